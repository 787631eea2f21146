#include <codemark/landmark/truth.h>
#include <codemark/pose/general.h>
#include <mrpt/math/CMatrixFixed.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <stdexcept>

namespace codemark::pose
{
namespace
{
using Vec6 = Eigen::Matrix<double, 6, 1>;

cv::Mat cameraMatrix(const CameraModel& cam)
{
	return (cv::Mat_<double>(3, 3) << cam.fx(), 0, cam.cx(), 0, cam.fy(), cam.cy(), 0, 0, 1);
}

cv::Mat distCoeffs(const CameraModel& cam)
{
	if (!cam.hasDistortion()) return cv::Mat();
	// CameraModel's plumb_bob is OpenCV's rational model k1 k2 p1 p2 k3 k4 k5 k6.
	cv::Mat d(1, 8, CV_64F);
	for (int i = 0; i < 8; ++i) d.at<double>(i) = cam.params().dist[i];
	return d;
}

// Model frame M: x = Y_L (right), y = -Z_L (down), z = -X_L (into the wall),
// so that a level camera squarely facing the landmark has R = identity.
// With the model "y up, z out" (OpenCV's IPPE_SQUARE layout) that camera has
// a rotation of exactly pi, where OpenCV 4.6's IPPE solutions come out wrong
// (the rotation-matrix -> Rodrigues conversion is ill-posed at pi; see
// tests/pose/test_general.cpp, General.SquarelyFacingLevelCamera180Degrees).
Eigen::Matrix3d landmarkRModel()
{
	Eigen::Matrix3d R;
	R << 0, 0, -1, 1, 0, 0, 0, -1, 0;
	return R;
}

struct Projection
{
	double rms = 0;
	Eigen::Matrix<double, 8, 1> r;	//!< projections minus the corners [px]
	Eigen::Matrix<double, 8, 6> J;
};

Projection project(
	const std::vector<cv::Point3d>& obj, const std::vector<cv::Point2d>& img, const Vec6& p,
	const cv::Mat& K, const cv::Mat& dist)
{
	cv::Mat rvec = (cv::Mat_<double>(3, 1) << p[0], p[1], p[2]);
	cv::Mat tvec = (cv::Mat_<double>(3, 1) << p[3], p[4], p[5]);
	std::vector<cv::Point2d> proj;
	cv::Mat jac;
	cv::projectPoints(obj, rvec, tvec, K, dist, proj, jac);
	Projection out;
	double ss = 0;
	for (size_t i = 0; i < proj.size(); ++i)
	{
		const cv::Point2d d = proj[i] - img[i];
		out.r[2 * i] = d.x;
		out.r[2 * i + 1] = d.y;
		ss += d.x * d.x + d.y * d.y;
	}
	out.rms = std::sqrt(ss / (2.0 * proj.size()));
	// Columns 0..2: d/drvec, 3..5: d/dtvec.
	for (int r = 0; r < 8; ++r)
		for (int c = 0; c < 6; ++c) out.J(r, c) = jac.at<double>(r, c);
	return out;
}

// L and the pose in L (as sightingTruth) as one 6-vector.
Vec6 reduce(const Vec6& p)
{
	const SightingTruth t = sightingTruth(landmarkTCameraFromRvecTvec(p));
	Vec6 v;
	v << t.L, t.pose_in_landmark;
	return v;
}

bool samePose(const Vec6& a, const Vec6& b)
{
	const auto A = landmarkTCameraFromRvecTvec(a), B = landmarkTCameraFromRvecTvec(b);
	const Eigen::Matrix3d dR =
		A.getRotationMatrix().asEigen().transpose() * B.getRotationMatrix().asEigen();
	const double angle = std::acos(std::clamp(0.5 * (dR.trace() - 1), -1.0, 1.0));
	const double dt = (A.translation() - B.translation()).norm();
	return angle < 1e-6 && dt < 1e-6 * std::max(1.0, A.translation().norm());
}
}  // namespace

std::array<Eigen::Vector3d, 4> modelPoints(const LandmarkGeometry& g)
{
	const double h = g.innerHalf();
	return {
		Eigen::Vector3d(-h, -h, 0), Eigen::Vector3d(h, -h, 0), Eigen::Vector3d(h, h, 0),
		Eigen::Vector3d(-h, h, 0)};
}

mrpt::poses::CPose3D landmarkTCameraFromRvecTvec(const Eigen::Matrix<double, 6, 1>& p)
{
	cv::Mat rvec = (cv::Mat_<double>(3, 1) << p[0], p[1], p[2]);
	cv::Mat Rcv;
	cv::Rodrigues(rvec, Rcv);
	Eigen::Matrix3d R_cam_model;
	cv::cv2eigen(Rcv, R_cam_model);
	// p_cam = R p_M + t  =>  p_L = R_LM R^T (p_cam - t).
	const Eigen::Matrix3d R_L_cam = landmarkRModel() * R_cam_model.transpose();
	Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
	T.topLeftCorner<3, 3>() = R_L_cam;
	T.topRightCorner<3, 1>() = -R_L_cam * p.tail<3>();
	return mrpt::poses::CPose3D(mrpt::math::CMatrixDouble44(T));
}

void reducePnPSolution(PnPSolution& s)
{
	// Jacobian of the reduction by central differences; angle differences
	// wrapped.
	const Vec6& p0 = s.rvec_tvec;
	const Vec6 v0 = reduce(p0);
	Eigen::Matrix<double, 6, 6> Jr;
	for (int k = 0; k < 6; ++k)
	{
		const double step = k < 3 ? 1e-6 : 1e-6 * std::max(1e-3, p0.tail<3>().norm());
		Vec6 a = p0, b = p0;
		a[k] += step;
		b[k] -= step;
		Vec6 d = reduce(a) - reduce(b);
		for (const int ang : {1, 2, 5}) d[ang] = wrapToPi(d[ang]);
		Jr.col(k) = d / (2 * step);
	}
	const Eigen::Matrix<double, 6, 6> C = Jr * s.cov * Jr.transpose();
	s.L = v0.head<3>();
	s.pose_in_landmark = v0.tail<3>();
	s.C_L = C.topLeftCorner<3, 3>();
	s.C_R = C.bottomRightCorner<3, 3>();
}

GeneralPose solveGeneralPose(
	const std::array<Eigen::Vector2d, 4>& corners, const CameraModel& camera,
	const LandmarkGeometry& geometry, double corner_sigma_px, int lm_max_iterations)
{
	return solveGeneralPose(
		corners, camera, geometry,
		CornerCovariance(corner_sigma_px * corner_sigma_px * CornerCovariance::Identity()),
		lm_max_iterations);
}

CornerCovariance cornerCovarianceFromPrimary(
	const std::array<Eigen::Vector2d, 4>& raw, const CameraModel& cam, const Eigen::Matrix4d& C_P,
	double midpoint_ratio, double tilt_ratio, const Eigen::Vector2d& tilt_extra_var)
{
	// T: ideal corners -> [x1 y1 x2 y2 m1 m2 t1 t2]; its first four rows are
	// dP/dcorners of primaryMeasurementFromIdeal() (x1, x2 the means of the
	// edges' x, y1, y2 their half-lengths in fx units).
	std::array<Eigen::Vector2d, 4> ideal;
	for (int k = 0; k < 4; ++k) ideal[k] = cam.undistortPixel(raw[k]);
	const double sy = cam.fx() / cam.fy();
	CornerCovariance T = CornerCovariance::Zero();
	for (const auto& [top, bottom, e] : {std::array<int, 3>{0, 3, 0}, {1, 2, 1}})
	{
		const int top_u = 2 * top, bottom_u = 2 * bottom;
		T(2 * e, top_u) = T(2 * e, bottom_u) = 0.5;	 // x_e
		const Eigen::Vector2d d(
			ideal[top].x() - ideal[bottom].x(), (ideal[top].y() - ideal[bottom].y()) * sy);
		const double n = std::max(1e-9, d.norm());
		const Eigen::Vector2d g(0.5 * d.x() / n, 0.5 * d.y() / n * sy);
		T.block<1, 2>(2 * e + 1, top_u) = g.transpose();  // y_e
		T.block<1, 2>(2 * e + 1, bottom_u) = -g.transpose();
		T(4 + e, top_u + 1) = T(4 + e, bottom_u + 1) = 0.5 * sy;  // m_e
		T(6 + e, top_u) = 0.5;	// t_e
		T(6 + e, bottom_u) = -0.5;
	}
	CornerCovariance Cc = CornerCovariance::Zero();
	Cc.topLeftCorner<4, 4>() = C_P;
	for (int e = 0; e < 2; ++e)
	{
		Cc(4 + e, 4 + e) = midpoint_ratio * midpoint_ratio * C_P(2 * e + 1, 2 * e + 1);
		Cc(6 + e, 6 + e) =
			std::max(0.0, tilt_ratio * tilt_ratio * C_P(2 * e, 2 * e) + tilt_extra_var[e]);
	}
	const CornerCovariance Ti = T.inverse();
	const CornerCovariance C = Ti * Cc * Ti.transpose();
	// Ideal -> raw pixels: the distortion's Jacobian per corner, by central
	// differences of CameraModel::distortNormalized (identity without
	// distortion).
	CornerCovariance D = CornerCovariance::Zero();
	for (int k = 0; k < 4; ++k)
		for (int a = 0; a < 2; ++a)
		{
			const double h = 1e-4;
			Eigen::Vector2d xp = ideal[k], xm = ideal[k];
			xp[a] += h;
			xm[a] -= h;
			const auto toRaw = [&](const Eigen::Vector2d& x) {
				return cam.distortNormalized(
					{(x.x() - cam.cx()) / cam.fx(), (x.y() - cam.cy()) / cam.fy()});
			};
			D.block<2, 1>(2 * k, 2 * k + a) = (toRaw(xp) - toRaw(xm)) / (2 * h);
		}
	return D * C * D.transpose();
}

GeneralPose solveGeneralPose(
	const std::array<Eigen::Vector2d, 4>& corners, const CameraModel& camera,
	const LandmarkGeometry& geometry, const CornerCovariance& corner_cov, int lm_max_iterations)
{
	const cv::Mat K = cameraMatrix(camera), dist = distCoeffs(camera);
	std::vector<cv::Point3d> obj;
	for (const auto& m : modelPoints(geometry)) obj.emplace_back(m.x(), m.y(), m.z());
	std::vector<cv::Point2d> img;
	for (const auto& c : corners)
	{
		if (!c.allFinite()) throw std::invalid_argument("solveGeneralPose: non-finite corner");
		img.emplace_back(c.x(), c.y());
	}

	// Candidates: both IPPE solutions, and SQPNP's (IPPE_SQUARE is avoided:
	// see general.h).
	std::vector<Vec6> candidates;
	for (const int flag : {cv::SOLVEPNP_IPPE, cv::SOLVEPNP_SQPNP})
	{
		std::vector<cv::Mat> rvecs, tvecs;
		try
		{
			cv::solvePnPGeneric(obj, img, K, dist, rvecs, tvecs, false, cv::SolvePnPMethod(flag));
		}
		catch (const cv::Exception&)
		{
			continue;  // a degenerate input for this solver; the other may cope
		}
		for (size_t i = 0; i < rvecs.size(); ++i)
		{
			cv::Mat r = rvecs[i].clone(), t = tvecs[i].clone();
			r.convertTo(r, CV_64F);
			t.convertTo(t, CV_64F);
			cv::solvePnPRefineLM(
				obj, img, K, dist, r, t,
				cv::TermCriteria(
					cv::TermCriteria::COUNT + cv::TermCriteria::EPS, lm_max_iterations, 1e-12));
			Vec6 p;
			p << r.at<double>(0), r.at<double>(1), r.at<double>(2), t.at<double>(0),
				t.at<double>(1), t.at<double>(2);
			// The landmark must be in front of the camera.
			if (p.allFinite() && p[5] > 0) candidates.push_back(p);
		}
	}

	// A singular corner covariance (exact corners) leaves the solutions
	// unweighed (chi2 and log_det_cov 0).
	const Eigen::LLT<CornerCovariance> Cc_llt(corner_cov);
	const bool weighable = Cc_llt.info() == Eigen::Success;
	std::vector<PnPSolution> sols;
	for (const Vec6& p : candidates)
	{
		if (std::any_of(
				sols.begin(), sols.end(),
				[&](const PnPSolution& s) { return samePose(s.rvec_tvec, p); }))
			continue;
		const Projection pr = project(obj, img, p, K, dist);
		PnPSolution s;
		s.rvec_tvec = p;
		s.landmark_T_camera = landmarkTCameraFromRvecTvec(p);
		s.rms_px = pr.rms;
		// The LM refinement is unweighted: its covariance is the sandwich
		// (J^T J)^-1 J^T C_c J (J^T J)^-1.
		const Eigen::Matrix<double, 6, 6> JtJi = (pr.J.transpose() * pr.J).inverse();
		s.cov = JtJi * pr.J.transpose() * corner_cov * pr.J * JtJi;
		// The corners' Mahalanobis residual and the width of the weighted
		// optimum (Laplace), which weigh this solution against the other
		// (foldModes()).
		if (weighable)
		{
			s.chi2 = pr.r.dot(Cc_llt.solve(pr.r));
			s.log_det_cov = -std::log((pr.J.transpose() * Cc_llt.solve(pr.J)).determinant());
		}
		// Only the landmark's front side is printed: a camera behind it is no solution.
		if (s.landmark_T_camera.x() > 0) sols.push_back(s);
	}
	if (sols.empty())
		throw std::runtime_error("solveGeneralPose: no PnP solution in front of the landmark");
	std::sort(
		sols.begin(), sols.end(),
		[](const PnPSolution& a, const PnPSolution& b) { return a.rms_px < b.rms_px; });
	if (sols.size() > 2) sols.resize(2);

	GeneralPose out;
	out.solutions = sols;
	out.ambiguity_ratio = (sols.size() < 2 || sols[0].rms_px <= 0)
							  ? std::numeric_limits<double>::infinity()
							  : sols[1].rms_px / sols[0].rms_px;

	// The best solution reduced; the other only where a caller weighs it
	// (pose::measure() with fold_ambiguity): the reduction's 12 evaluations
	// are most of this path's cost after the PnP.
	reducePnPSolution(out.solutions[0]);
	out.L = out.solutions[0].L;
	out.pose_in_landmark = out.solutions[0].pose_in_landmark;
	out.C_L = out.solutions[0].C_L;
	out.C_R = out.solutions[0].C_R;
	return out;
}

}  // namespace codemark::pose
