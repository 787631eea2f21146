#include <codemark/landmark/truth.h>
#include <codemark/pose/closed_form.h>

#include <Eigen/Dense>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace codemark::pose
{
Eigen::Vector3d landmarkFromPrimary(
	const Eigen::Vector4d& P, double lambda, double h, Eigen::Matrix<double, 3, 4>* J_P)
{
	const double x1 = P[0], y1 = P[1], x2 = P[2], y2 = P[3];
	if (!(y1 > 0) || !(y2 > 0) || !(lambda > 0))
	{
		std::ostringstream s;
		s << "landmarkFromPrimary: need y1, y2, lambda > 0, got y1=" << y1 << " y2=" << y2
		  << " lambda=" << lambda;
		throw std::invalid_argument(s.str());
	}
	// Paper eq. 1-3 (spec signs). Z_i = lambda h / y_i and X_i = x_i h / y_i
	// locate each vertical edge's centre; the landmark centre is their
	// midpoint, at lateral/depth ratio xm / lambda.
	const double s = y1 + y2;
	const double xm = (x1 * y2 + x2 * y1) / s;
	const double r2 = lambda * lambda + xm * xm;
	const double r = std::sqrt(r2);
	const double k = 0.5 * h * (1.0 / y1 + 1.0 / y2);  // = h (y1 + y2) / (2 y1 y2)
	const double N = lambda * (y2 - y1);
	const double D = x2 * y1 - x1 * y2;
	Eigen::Vector3d L(k * r, -std::atan2(xm, lambda), std::atan2(N, D));

	if (J_P)
	{
		// Derivatives of the intermediate quantities w.r.t. (x1, y1, x2, y2).
		const Eigen::RowVector4d dxm(
			y2 / s, y2 * (x2 - x1) / (s * s), y1 / s, y1 * (x1 - x2) / (s * s));
		const Eigen::RowVector4d dk(0, -0.5 * h / (y1 * y1), 0, -0.5 * h / (y2 * y2));
		const Eigen::RowVector4d dN(0, -lambda, 0, lambda);
		const Eigen::RowVector4d dD(-y2, x2, y1, -x1);
		// l2 = k r, r = sqrt(lambda^2 + xm^2)
		J_P->row(0) = dk * r + (k * xm / r) * dxm;
		// phi1 = -atan2(xm, lambda)
		J_P->row(1) = (-lambda / r2) * dxm;
		// phi2 = atan2(N, D)
		J_P->row(2) = (D * dN - N * dD) / (N * N + D * D);
	}
	return L;
}

Eigen::Vector3d poseFromLandmark(const Eigen::Vector3d& L, Eigen::Matrix3d* J_L)
{
	// Paper eq. 12-14 in the spec's convention (docs/spec.md section 4).
	const double l2 = L[0], a = L[1] + L[2];
	const double c = std::cos(a), sn = std::sin(a);
	if (J_L)
	{
		*J_L << c, -l2 * sn, -l2 * sn,	//
			sn, l2 * c, l2 * c,	 //
			0, 0, 1;
	}
	return {l2 * c, l2 * sn, wrapToPi(M_PI + L[2])};
}

Eigen::Matrix3d poseCovarianceSecondOrder(const Eigen::Vector3d& L, const Eigen::Matrix3d& C_L)
{
	Eigen::Matrix3d J_L;
	poseFromLandmark(L, &J_L);
	const double l2 = L[0], a = L[1] + L[2];
	const double c = std::cos(a), sn = std::sin(a);
	// Hessians of x = l2 cos(a) and y = l2 sin(a), a = phi1 + phi2, w.r.t.
	// (l2, phi1, phi2); theta = pi + phi2 is linear.
	Eigen::Matrix3d H[2];
	H[0] << 0, -sn, -sn,  //
		-sn, -l2 * c, -l2 * c,	//
		-sn, -l2 * c, -l2 * c;
	H[1] << 0, c, c,  //
		c, -l2 * sn, -l2 * sn,	//
		c, -l2 * sn, -l2 * sn;
	Eigen::Matrix3d C = J_L * C_L * J_L.transpose();
	for (int i = 0; i < 2; ++i)
		for (int j = 0; j < 2; ++j) C(i, j) += 0.5 * (H[i] * C_L * H[j] * C_L).trace();
	return C;
}

bool primaryFromLandmark(
	double l2, double c1, double s1, double c2, double s2, double lambda, double h,
	Eigen::Vector4d& P, Eigen::Matrix<double, 4, 3>* J_L)
{
	// Forward and left coordinates of the left (1) and right (2) edge centres.
	const double f[2] = {l2 * c1 + h * s2, l2 * c1 - h * s2};
	const double g[2] = {l2 * s1 + h * c2, l2 * s1 - h * c2};
	if (!(f[0] > 0) || !(f[1] > 0) || !(lambda > 0)) return false;
	for (int i = 0; i < 2; ++i)
	{
		P[2 * i] = -lambda * g[i] / f[i];
		P[2 * i + 1] = lambda * h / f[i];
	}
	if (J_L)
	{
		const double sgn[2] = {1, -1};
		for (int i = 0; i < 2; ++i)
		{
			// d(f, g)/d(l2, phi1, phi2)
			const double df[3] = {c1, -l2 * s1, sgn[i] * h * c2};
			const double dg[3] = {s1, l2 * c1, -sgn[i] * h * s2};
			for (int k = 0; k < 3; ++k)
			{
				(*J_L)(2 * i, k) = -lambda * (dg[k] * f[i] - g[i] * df[k]) / (f[i] * f[i]);
				(*J_L)(2 * i + 1, k) = -lambda * h * df[k] / (f[i] * f[i]);
			}
		}
	}
	return true;
}

Eigen::Vector4d primaryFromLandmark(
	const Eigen::Vector3d& L, double lambda, double h, Eigen::Matrix<double, 4, 3>* J_L)
{
	Eigen::Vector4d P;
	if (!primaryFromLandmark(
			L[0], std::cos(L[1]), std::sin(L[1]), std::cos(L[2]), std::sin(L[2]), lambda, h, P,
			J_L))
		throw std::invalid_argument("primaryFromLandmark: an edge is not in front of the camera");
	return P;
}

Eigen::Vector3d refineLandmarkOnPrimary(
	const Eigen::Vector4d& P, const Eigen::Matrix4d& C_P, double lambda, double h,
	const Eigen::Vector3d& L0, Eigen::Matrix3d* C_L)
{
	const Eigen::LLT<Eigen::Matrix4d> llt(C_P);
	if (llt.info() != Eigen::Success)
		throw std::invalid_argument("refineLandmarkOnPrimary: C_P is not positive definite");
	const Eigen::Matrix4d W = llt.solve(Eigen::Matrix4d::Identity());
	const auto cost = [&](const Eigen::Vector3d& L)
	{
		const Eigen::Vector4d r = P - primaryFromLandmark(L, lambda, h);
		return r.dot(W * r);
	};
	Eigen::Vector3d L = L0;
	Eigen::Matrix<double, 4, 3> J;
	double c = cost(L);
	for (int it = 0; it < 20; ++it)
	{
		const Eigen::Vector4d r = P - primaryFromLandmark(L, lambda, h, &J);
		const Eigen::Vector3d step = (J.transpose() * W * J).ldlt().solve(J.transpose() * W * r);
		// Halve the step while it does not lower the cost (or leaves the
		// region where both edges are in front of the camera).
		double applied = 0;
		for (double t = 1; t > 1e-3 && applied == 0; t *= 0.5)
		{
			try
			{
				const double ct = cost(L + t * step);
				if (ct <= c)
				{
					L += t * step;
					c = ct;
					applied = t * step.norm();
				}
			}
			catch (const std::invalid_argument&)
			{
			}
		}
		if (applied < 1e-12 * (1 + L.norm())) break;
	}
	if (C_L)
	{
		primaryFromLandmark(L, lambda, h, &J);
		*C_L = (J.transpose() * W * J).inverse();
	}
	return L;
}

Eigen::Matrix4d primaryCovariance(double sx, double sy)
{
	return Eigen::Vector4d(sx * sx, sy * sy, sx * sx, sy * sy).asDiagonal();
}

mrpt::poses::CPose2D cameraPlanarPose(const mrpt::poses::CPose3D& robot_T_camera)
{
	const auto R = robot_T_camera.getRotationMatrix();
	// Optical axis (camera z) in the robot frame, projected on the floor.
	return mrpt::poses::CPose2D(
		robot_T_camera.x(), robot_T_camera.y(), std::atan2(R(1, 2), R(0, 2)));
}

mrpt::poses::CPose2D landmarkPlanarPose(const mrpt::poses::CPose3D& world_T_landmark)
{
	return mrpt::poses::CPose2D(world_T_landmark.x(), world_T_landmark.y(), world_T_landmark.yaw());
}

mrpt::poses::CPose2D robotPoseInWorld(
	const Eigen::Vector3d& c, const Eigen::Matrix3d& C_R,
	const mrpt::poses::CPose2D& world_T_landmark, const mrpt::poses::CPose2D& robot_T_camera,
	Eigen::Matrix3d* C_world, Eigen::Matrix3d* J_out)
{
	using mrpt::poses::CPose2D;
	const CPose2D world_T_camera = world_T_landmark + CPose2D(c[0], c[1], c[2]);
	const CPose2D camera_T_robot = CPose2D() - robot_T_camera;	// inverse
	CPose2D world_T_robot = world_T_camera + camera_T_robot;
	if (C_world || J_out)
	{
		// d(a (+) b)/db = rot(a.phi) (+ 1 for the angle);
		// d(q (+) d)/dq = [1 0 -dx sin - dy cos; 0 1 dx cos - dy sin; 0 0 1].
		const double ca = std::cos(world_T_landmark.phi()), sa = std::sin(world_T_landmark.phi());
		Eigen::Matrix3d J1;
		J1 << ca, -sa, 0, sa, ca, 0, 0, 0, 1;
		const double q = world_T_camera.phi(), cq = std::cos(q), sq = std::sin(q);
		const double dx = camera_T_robot.x(), dy = camera_T_robot.y();
		Eigen::Matrix3d J2;
		J2 << 1, 0, -dx * sq - dy * cq, 0, 1, dx * cq - dy * sq, 0, 0, 1;
		const Eigen::Matrix3d J = J2 * J1;
		if (J_out) *J_out = J;
		if (C_world) *C_world = J * C_R * J.transpose();
	}
	return world_T_robot;
}

Eigen::Vector3d cameraInLandmark(
	const mrpt::poses::CPose2D& world_T_robot, const mrpt::poses::CPose2D& world_T_landmark,
	const mrpt::poses::CPose2D& robot_T_camera)
{
	const mrpt::poses::CPose2D c = (world_T_robot + robot_T_camera) - world_T_landmark;
	return {c.x(), c.y(), wrapToPi(c.phi())};
}

}  // namespace codemark::pose
