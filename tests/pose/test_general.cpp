// The general 6-DoF path: the exactly-180-degree case that OpenCV 4.6's
// SOLVEPNP_IPPE_SQUARE gets wrong, agreement with the closed form for level
// cameras, tilted cameras with lens distortion, ambiguity and covariance.
#include <codemark/landmark/primary.h>
#include <codemark/landmark/truth.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pose/general.h>
#include <codemark/pose/measurement.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <iostream>
#include <opencv2/calib3d.hpp>
#include <random>

#include "common.h"

#include "../common/numeric_diff.h"

using namespace codemark;
using namespace codemark::pose;
using codemark::test::cameraAt;
using codemark::test::levelCamera;
using codemark::test::projectCorners;
using mrpt::poses::CPose3D;

namespace
{
// Rotation angle between two poses [rad] and translation distance [m].
std::pair<double, double> poseError(const CPose3D& a, const CPose3D& b)
{
	const Eigen::Matrix3d dR =
		a.getRotationMatrix().asEigen().transpose() * b.getRotationMatrix().asEigen();
	const double ang = std::acos(std::clamp(0.5 * (dR.trace() - 1), -1.0, 1.0));
	return {ang, (a.translation() - b.translation()).norm()};
}

// (L, pose_in_landmark) of \a gp minus that of \a ref, angles wrapped.
Eigen::Matrix<double, 6, 1> errorOf(const GeneralPose& gp, const GeneralPose& ref)
{
	Eigen::Matrix<double, 6, 1> x;
	x << gp.L - ref.L, gp.pose_in_landmark - ref.pose_in_landmark;
	x[2] = wrapToPi(x[2]);
	x[5] = wrapToPi(x[5]);
	return x;
}

// The sample covariance of (L, pose_in_landmark) errors.
Eigen::Matrix<double, 6, 6> sampleCovariance(const std::vector<Eigen::Matrix<double, 6, 1>>& v)
{
	const double N = static_cast<double>(v.size());
	Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
	for (const auto& x : v) mean += x / N;
	Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
	for (const auto& x : v) C += (x - mean) * (x - mean).transpose() / (N - 1);
	return C;
}

CameraModel distortedCamera()
{
	mrpt::img::TCamera p;
	p.ncols = 1280;
	p.nrows = 960;
	p.setIntrinsicParamsFromValues(1000, 1000, 639.5, 479.5);
	p.distortion = mrpt::img::DistortionModel::plumb_bob;
	p.dist.fill(0);
	p.dist[0] = -0.25;
	p.dist[1] = 0.08;
	p.dist[2] = 0.001;
	p.dist[3] = -0.0015;
	p.dist[4] = -0.01;
	return CameraModel(p);
}
}  // namespace

TEST(General, SquarelyFacingLevelCamera180Degrees)
{
	// A level camera squarely facing the landmark: yaw exactly 180 deg in L.
	const CameraModel cam;
	const LandmarkGeometry g;
	const cv::Mat K =
		(cv::Mat_<double>(3, 3) << cam.fx(), 0, cam.cx(), 0, cam.fy(), cam.cy(), 0, 0, 1);
	for (const double d : {0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0})
	{
		for (const double z : {0.0, 0.25})
		{
			const CPose3D truth = levelCamera(d, 0, z, M_PI);
			const auto corners = projectCorners(truth, cam, g);
			const GeneralPose gp = solveGeneralPose(corners, cam, g, 0.07);
			const auto [ang, dt] = poseError(gp.solutions[0].landmark_T_camera, truth);
			EXPECT_LT(ang, 1e-6) << "d " << d << " z " << z;
			EXPECT_LT(dt, 1e-6 * d) << "d " << d << " z " << z;
			EXPECT_LT(gp.solutions[0].rms_px, 1e-6);
			EXPECT_NEAR(std::abs(gp.pose_in_landmark[2]), M_PI, 1e-6);

			// What OpenCV 4.6's SOLVEPNP_IPPE_SQUARE does here (documented, not
			// asserted: it is OpenCV's behaviour, not ours), and plain IPPE,
			// with IPPE_SQUARE's model: the square (-h, h, 0), (h, h, 0),
			// (h, -h, 0), (-h, -h, 0) in TL TR BR BL order, i.e. the frame
			// (Y_L, Z_L, X_L), in which this camera's rotation is exactly pi.
			const double h = g.innerHalf();
			const std::vector<cv::Point3d> obj{{-h, h, 0}, {h, h, 0}, {h, -h, 0}, {-h, -h, 0}};
			Eigen::Matrix3d R_L_M;
			R_L_M << 0, 0, 1, 1, 0, 0, 0, 1, 0;
			std::vector<cv::Point2d> img;
			for (const auto& c : corners) img.emplace_back(c.x(), c.y());
			for (const auto& [flag, name] :
				 {std::pair{cv::SOLVEPNP_IPPE_SQUARE, "IPPE_SQUARE"},
				  std::pair{cv::SOLVEPNP_IPPE, "IPPE"}})
			{
				std::vector<cv::Mat> rv, tv;
				const int n = cv::solvePnPGeneric(obj, img, K, cv::Mat(), rv, tv, false, flag);
				double best_ang = 1e9, best_dt = 1e9;
				for (int i = 0; i < n; ++i)
				{
					Eigen::Matrix<double, 6, 1> p;
					p << rv[i].at<double>(0), rv[i].at<double>(1), rv[i].at<double>(2),
						tv[i].at<double>(0), tv[i].at<double>(1), tv[i].at<double>(2);
					cv::Mat Rcv;
					cv::Rodrigues(rv[i], Rcv);
					Eigen::Matrix3d R;
					for (int r = 0; r < 3; ++r)
						for (int c = 0; c < 3; ++c) R(r, c) = Rcv.at<double>(r, c);
					Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
					T.topLeftCorner<3, 3>() = R_L_M * R.transpose();
					T.topRightCorner<3, 1>() = -R_L_M * R.transpose() * p.tail<3>();
					const auto [a, t] = poseError(CPose3D(mrpt::math::CMatrixDouble44(T)), truth);
					best_ang = std::min(best_ang, a);
					best_dt = std::min(best_dt, t);
				}
				std::cout << "[ " << name << " ] d=" << d << " z=" << z << ": " << n
						  << " solution(s), best rotation error " << best_ang * 180 / M_PI
						  << " deg, best position error " << best_dt << " m\n";
				RecordProperty(
					std::string(name) + "_d" + std::to_string(int(d * 10)) + "_z" +
						std::to_string(int(z * 100)) + "_rot_err_deg",
					std::to_string(best_ang * 180 / M_PI));
			}

			// Plain IPPE with codemark's model frame (Y_L, -Z_L, -X_L), where
			// this camera has the identity rotation: right before refinement.
			std::vector<cv::Point3d> obj2;
			for (const auto& m : modelPoints(g)) obj2.emplace_back(m.x(), m.y(), m.z());
			std::vector<cv::Mat> rv, tv;
			const int n =
				cv::solvePnPGeneric(obj2, img, K, cv::Mat(), rv, tv, false, cv::SOLVEPNP_IPPE);
			double best_ang = 1e9, best_dt = 1e9;
			for (int i = 0; i < n; ++i)
			{
				Eigen::Matrix<double, 6, 1> p;
				p << rv[i].at<double>(0), rv[i].at<double>(1), rv[i].at<double>(2),
					tv[i].at<double>(0), tv[i].at<double>(1), tv[i].at<double>(2);
				const auto [a, t] = poseError(landmarkTCameraFromRvecTvec(p), truth);
				best_ang = std::min(best_ang, a);
				best_dt = std::min(best_dt, t);
			}
			EXPECT_LT(best_ang, 1e-6) << "d " << d << " z " << z;
			EXPECT_LT(best_dt, 1e-6 * d) << "d " << d << " z " << z;
		}
	}
}

TEST(General, AgreesWithClosedFormForLevelCameras)
{
	const CameraModel cam;
	std::mt19937 rng(11);
	std::uniform_real_distribution<double> d(0.5, 5.0), a(-1.2, 1.2), z(-0.4, 0.4), p1(-0.3, 0.3);
	PoseOptions cf, gen;
	gen.method = PoseMethod::General6Dof;
	for (int i = 0; i < 100; ++i)
	{
		const CPose3D truth = cameraAt(d(rng), a(rng), z(rng), p1(rng));
		const LandmarkGeometry g;
		const auto corners = projectCorners(truth, cam, g);
		const Measurement mc = measure(corners, cam, g, cf);
		const Measurement mg = measure(corners, cam, g, gen);
		EXPECT_EQ(mg.method, PoseMethod::General6Dof);
		EXPECT_NEAR(mg.L[0], mc.L[0], 1e-6 * mc.L[0]);
		EXPECT_NEAR(mg.L[1], mc.L[1], 1e-6);
		EXPECT_NEAR(mg.L[2], mc.L[2], 1e-6);
		EXPECT_LT(
			(mg.pose_in_landmark.head<2>() - mc.pose_in_landmark.head<2>()).norm(), 1e-6 * mc.L[0]);
		EXPECT_NEAR(wrapToPi(mg.pose_in_landmark[2] - mc.pose_in_landmark[2]), 0, 1e-6);
		const auto [ang, dt] = poseError(mg.landmark_T_camera, truth);
		EXPECT_LT(ang, 1e-6);
		EXPECT_LT(dt, 1e-6 * mc.L[0]);
		// The general path also knows the height, which the closed form cannot.
		EXPECT_NEAR(mg.landmark_T_camera.z(), truth.z(), 1e-6);
		EXPECT_GT(mg.ambiguity_ratio, 1.0);
	}
}

TEST(General, TiltedCameraWithLensDistortion)
{
	const CameraModel cam = distortedCamera();
	ASSERT_TRUE(cam.hasDistortion());
	std::mt19937 rng(12);
	std::uniform_real_distribution<double> d(0.6, 4.0), a(-1.0, 1.0), z(-0.6, 0.6), yaw(-0.4, 0.4),
		roll(-0.1, 0.1);
	const LandmarkGeometry g = LandmarkGeometry::scaled(1.5);
	int tested = 0;
	for (int i = 0; i < 200 && tested < 60; ++i)
	{
		const double dd = d(rng), aa = a(rng), zz = z(rng);
		// Heading towards the landmark plus an offset, pitched 10 deg down
		// (MRPT pitch is about the robot's y: positive = nose down), rolled a little.
		const CPose3D truth = CPose3D(
								  dd * std::cos(aa), dd * std::sin(aa), zz, aa + M_PI + yaw(rng),
								  10 * M_PI / 180, roll(rng)) +
							  CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
		std::array<Eigen::Vector2d, 4> corners;
		try
		{
			corners = projectCorners(truth, cam, g);
		}
		catch (const std::runtime_error&)
		{
			continue;
		}
		bool inside = true;
		for (const auto& c : corners)
			inside = inside && c.x() > 0 && c.y() > 0 && c.x() < cam.width() - 1 &&
					 c.y() < cam.height() - 1;
		if (!inside) continue;
		++tested;
		PoseOptions gen;
		gen.method = PoseMethod::General6Dof;
		const Measurement m = measure(corners, cam, g, gen);
		const auto [ang, dt] = poseError(m.landmark_T_camera, truth);
		EXPECT_LT(ang, 1e-6) << "i " << i;
		EXPECT_LT(dt, 1e-6 * dd) << "i " << i;
		const SightingTruth st = sightingTruth(truth);
		EXPECT_NEAR(m.L[0], st.L[0], 1e-6 * st.L[0]);
		EXPECT_NEAR(m.L[1], st.L[1], 1e-6);
		EXPECT_NEAR(m.L[2], st.L[2], 1e-6);
		EXPECT_NEAR(wrapToPi(m.pose_in_landmark[2] - st.pose_in_landmark[2]), 0, 1e-6);
		// The planar pose is poseFromLandmark(L) on this path too, and its
		// first-order C_R is J_L C_L J_L^T: what lets measure() take C_R to
		// second order in C_L here as on the closed form.
		Eigen::Matrix3d J_L;
		const Eigen::Vector3d from_L = poseFromLandmark(m.L, &J_L);
		EXPECT_LT((from_L.head<2>() - m.pose_in_landmark.head<2>()).norm(), 1e-9 * dd);
		EXPECT_NEAR(wrapToPi(from_L[2] - m.pose_in_landmark[2]), 0, 1e-9);
		const Eigen::Matrix3d first = J_L * m.C_L * J_L.transpose();
		EXPECT_LT((first - m.C_R).norm(), 1e-5 * m.C_R.norm()) << "i " << i;
		PoseOptions gen2 = gen;
		gen2.second_order_pose_covariance = true;
		const Measurement m2 = measure(corners, cam, g, gen2);
		EXPECT_LT((m2.C_R - poseCovarianceSecondOrder(m.L, m.C_L)).norm(), 1e-12 * m.C_R.norm());
		EXPECT_GE(
			Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m2.C_R - m.C_R).eigenvalues().minCoeff(),
			-1e-9 * m.C_R.norm());
		// The closed form, which assumes a level camera, is biased here.
		PoseOptions cf;
		const Measurement mc = measure(corners, cam, g, cf);
		EXPECT_GT(std::abs(mc.L[0] - st.L[0]), 1e-4 * st.L[0]) << "i " << i;
	}
	EXPECT_GE(tested, 30);
}

TEST(General, CovarianceMatchesMonteCarlo)
{
	// Perturb the corners with independent noise: the empirical covariance of
	// (L, pose) against the predicted one (first order holds at 1.5 m).
	const CameraModel cam;
	const LandmarkGeometry g;
	const double sigma_c = 0.1;
	const CPose3D truth = cameraAt(1.5, 0.5, 0.2, 0.1);
	const auto corners = projectCorners(truth, cam, g);
	const GeneralPose ref = solveGeneralPose(corners, cam, g, sigma_c);
	std::mt19937 rng(13);
	std::normal_distribution<double> n(0, sigma_c);
	const int N = 2000;
	std::vector<Eigen::Matrix<double, 6, 1>> v;
	for (int i = 0; i < N; ++i)
	{
		auto c = corners;
		for (auto& p : c) p += Eigen::Vector2d(n(rng), n(rng));
		const GeneralPose gp = solveGeneralPose(c, cam, g, sigma_c);
		v.push_back(errorOf(gp, ref));
	}
	const Eigen::Matrix<double, 6, 6> C = sampleCovariance(v);
	const Eigen::Matrix3d CL = C.topLeftCorner<3, 3>(), CR = C.bottomRightCorner<3, 3>();
	EXPECT_LT((CL - ref.C_L).norm() / ref.C_L.norm(), 0.15);
	EXPECT_LT((CR - ref.C_R).norm() / ref.C_R.norm(), 0.15);
}

namespace
{
/** dP/dcorners by central differences of primaryMeasurement (raw pixels). */
Eigen::Matrix<double, 4, 8> primaryJacobian(
	const std::array<Eigen::Vector2d, 4>& corners, const CameraModel& cam)
{
	Eigen::Matrix<double, 8, 1> x;
	for (int k = 0; k < 8; ++k) x[k] = corners[k / 2][k % 2];
	const auto f = [&](const Eigen::Matrix<double, 8, 1>& v)
	{
		std::array<Eigen::Vector2d, 4> c;
		for (int k = 0; k < 4; ++k) c[k] = Eigen::Vector2d(v[2 * k], v[2 * k + 1]);
		return primaryMeasurement(c, cam);
	};
	// Steps of 1e-7 of the coordinates (a few hundredths of a micro-pixel
	// per pixel of coordinate).
	return codemark::test::numericJacobian(f, x, 1e-7);
}
}  // namespace

TEST(General, CornerCovarianceFromPrimaryReproducesCP)
{
	// dP/dcorners (central differences of primaryMeasurement, raw pixels,
	// with lens distortion and fx != fy) maps the lifted corner covariance
	// back onto C_P exactly; the lifted covariance is positive definite.
	CameraModel cam = distortedCamera();
	const LandmarkGeometry g;
	for (const auto& [d, a, phi1] :
		 {std::array<double, 3>{1.2, 0.3, 0.1}, {3.5, -0.9, -0.05}, {0.8, 0.0, 0.0}})
	{
		const auto corners = projectCorners(cameraAt(d, a, 0.15, phi1), cam, g);
		Eigen::Matrix4d C_P;
		C_P << 4, 0, -1.5, 0, 0, 2, 0, 0.6, -1.5, 0, 4, 0, 0, 0.6, 0, 2;
		C_P *= 1e-4;
		const CornerCovariance C = cornerCovarianceFromPrimary(corners, cam, C_P);
		const Eigen::Matrix<double, 4, 8> J = primaryJacobian(corners, cam);
		const Eigen::Matrix4d back = J * C * J.transpose();
		EXPECT_LT((back - C_P).norm(), 1e-6 * C_P.norm()) << "d " << d;
		EXPECT_LT((C - C.transpose()).norm(), 1e-12 * C.norm());
		EXPECT_GT(Eigen::SelfAdjointEigenSolver<CornerCovariance>(C).eigenvalues().minCoeff(), 0);
	}
}

// corner_tilt_noise_ratio: the extra tilt variance lands on the tilts alone
// (P's covariance and the midpoints' unchanged), and measure() adds it only
// for an image noisier than the reference.
TEST(General, TiltTakesItsOwnShareOfTheNoise)
{
	const CameraModel cam;	// no distortion: the tilts are the corners' x
	const LandmarkGeometry g;
	const auto corners = projectCorners(cameraAt(1.5, 0.4, 0.1, 0.05), cam, g);
	Eigen::Matrix4d C_P;
	C_P << 4, 0, -1.5, 0, 0, 2, 0, 0.6, -1.5, 0, 4, 0, 0, 0.6, 0, 2;
	C_P *= 1e-4;
	const Eigen::Vector2d extra(3e-4, 5e-4);
	const CornerCovariance C0 = cornerCovarianceFromPrimary(corners, cam, C_P, 0.9, 0.5);
	const CornerCovariance C1 = cornerCovarianceFromPrimary(corners, cam, C_P, 0.9, 0.5, extra);
	// Corner order TL, TR, BR, BL; edge 0 = TL-BL, edge 1 = TR-BR; tilt =
	// (x_top - x_bottom) / 2.
	for (int e = 0; e < 2; ++e)
	{
		const int top = e == 0 ? 0 : 1, bottom = e == 0 ? 3 : 2;
		Eigen::Matrix<double, 8, 1> t = Eigen::Matrix<double, 8, 1>::Zero();
		t[2 * top] = 0.5;
		t[2 * bottom] = -0.5;
		EXPECT_NEAR(t.dot(C0 * t), 0.25 * C_P(2 * e, 2 * e), 1e-12) << e;
		EXPECT_NEAR(t.dot(C1 * t) - t.dot(C0 * t), extra[e], 1e-12) << e;
	}
	const Eigen::Matrix<double, 4, 8> J = primaryJacobian(corners, cam);
	EXPECT_LT((J * C1 * J.transpose() - C_P).norm(), 1e-6 * C_P.norm());

	// measure(): on only above the reference noise; a ratio equal to
	// corner_tilt_ratio changes nothing, a larger one widens the general
	// path's C_L.
	PoseOptions o;
	o.method = PoseMethod::General6Dof;
	o.sigma_px = 0.03;
	o.corner_tilt_ratio = 0.5;
	o.reference_noise_grey = 2;
	o.noise_sigma_x_table = sigmaTableFromString("20:0.02 200:0.02");
	o.noise_sigma_y_table = sigmaTableFromString("20:0.02 200:0.02");
	Detection d;
	d.corners = corners;
	const auto cl = [&](double noise, double k)
	{
		o.corner_tilt_noise_ratio = k;
		d.quality.image_noise_grey = noise;
		return measure(d, cam, g, o).C_L;
	};
	EXPECT_LT((cl(2, 1.7) - cl(2, 0)).norm(), 1e-15);
	EXPECT_LT((cl(5, 0.5) - cl(5, 0)).norm(), 1e-9 * cl(5, 0).norm());
	// Wider in every direction (the difference positive semi-definite), the
	// range's variance by over 10% here (the tilts carry the pitch, which
	// trades off against the range).
	const Eigen::Matrix3d base = cl(5, 0), wider = cl(5, 1.7) - base;
	EXPECT_GT(
		Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(wider).eigenvalues().minCoeff(),
		-1e-9 * base.norm());
	EXPECT_GT(wider(0, 0), 0.1 * base(0, 0));
	o.corner_tilt_noise_ratio = -1;
	EXPECT_THROW(o.validate(), std::invalid_argument);
}

// corner_tilt_ratio_table: the tilt ratio at the sighting's apparent
// height y1 + y2, interpolated as the sigma tables (clamped at the ends,
// log-linear between), in place of corner_tilt_ratio.
TEST(General, TiltRatioFollowsTheApparentHeight)
{
	PoseOptions o;
	o.corner_tilt_ratio = 0.6;
	EXPECT_DOUBLE_EQ(o.cornerTiltRatio(50), 0.6);
	o.corner_tilt_ratio_table = sigmaTableFromString("30:0.3 120:0.9");
	EXPECT_DOUBLE_EQ(o.cornerTiltRatio(10), 0.3);
	EXPECT_DOUBLE_EQ(o.cornerTiltRatio(500), 0.9);
	EXPECT_NEAR(o.cornerTiltRatio(60), std::sqrt(0.3 * 0.9), 1e-12);  // the geometric midpoint

	// measure(): a table whose value at this sighting's height is the scalar
	// ratio gives the scalar's C_L; a larger value there widens it.
	const CameraModel cam;
	const LandmarkGeometry g;
	const auto corners = projectCorners(cameraAt(1.5, 0.4, 0.1, 0.05), cam, g);
	PoseOptions s;
	s.method = PoseMethod::General6Dof;
	s.sigma_px = 0.03;
	s.corner_tilt_ratio = 0.5;
	const Measurement scalar = measure(corners, cam, g, s);
	const double height = scalar.P[1] + scalar.P[3];
	PoseOptions t = s;
	t.corner_tilt_ratio = 7;  // unused with the table
	t.corner_tilt_ratio_table = {{0.5 * height, 0.5}, {2 * height, 0.5}};
	EXPECT_LT((measure(corners, cam, g, t).C_L - scalar.C_L).norm(), 1e-12 * scalar.C_L.norm());
	t.corner_tilt_ratio_table = {{0.5 * height, 0.1}, {height, 1.5}, {2 * height, 0.1}};
	const Eigen::Matrix3d wider = measure(corners, cam, g, t).C_L - scalar.C_L;
	EXPECT_GT(
		Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(wider).eigenvalues().minCoeff(),
		-1e-9 * scalar.C_L.norm());
	EXPECT_GT(wider.trace(), 0.05 * scalar.C_L.trace());
	// The closed form does not use it.
	t.method = s.method = PoseMethod::ClosedForm;
	EXPECT_LT(
		(measure(corners, cam, g, t).C_L - measure(corners, cam, g, s).C_L).norm(),
		1e-15 * scalar.C_L.norm());
	t.corner_tilt_ratio_table = {{50, 0.5}, {40, 0.6}};	 // sizes must increase
	EXPECT_THROW(t.validate(), std::invalid_argument);
	t.corner_tilt_ratio_table = {{50, 0.5}, {60, 0}};  // ratios must be > 0
	EXPECT_THROW(t.validate(), std::invalid_argument);
}

TEST(General, CorrelatedCornerCovarianceMatchesMonteCarlo)
{
	// Corners drawn from a correlated covariance (x1, x2 anti-correlated as
	// the detector's edges are): the sandwich covariance of the unweighted
	// LM against the samples.
	const CameraModel cam;
	const LandmarkGeometry g;
	const CPose3D truth = cameraAt(2.0, 0.6, 0.1, 0.0);
	const auto corners = projectCorners(truth, cam, g);
	Eigen::Matrix4d C_P;
	C_P << 1, 0, -0.6, 0, 0, 1.5, 0, 0.3, -0.6, 0, 1, 0, 0, 0.3, 0, 1.5;
	C_P *= 0.05 * 0.05;
	const CornerCovariance Cc = cornerCovarianceFromPrimary(corners, cam, C_P);
	const GeneralPose ref = solveGeneralPose(corners, cam, g, Cc);
	const CornerCovariance Lc = Cc.llt().matrixL();
	std::mt19937 rng(17);
	std::normal_distribution<double> n(0, 1);
	const int N = 3000;
	std::vector<Eigen::Matrix<double, 6, 1>> v;
	for (int i = 0; i < N; ++i)
	{
		Eigen::Matrix<double, 8, 1> z;
		for (int k = 0; k < 8; ++k) z[k] = n(rng);
		const Eigen::Matrix<double, 8, 1> e = Lc * z;
		auto c = corners;
		for (int k = 0; k < 4; ++k) c[k] += e.segment<2>(2 * k);
		const GeneralPose gp = solveGeneralPose(c, cam, g, Cc);
		v.push_back(errorOf(gp, ref));
	}
	const Eigen::Matrix<double, 6, 6> C = sampleCovariance(v);
	const Eigen::Matrix3d CL = C.topLeftCorner<3, 3>(), CR = C.bottomRightCorner<3, 3>();
	EXPECT_LT((CL - ref.C_L).norm() / ref.C_L.norm(), 0.1);
	EXPECT_LT((CR - ref.C_R).norm() / ref.C_R.norm(), 0.1);
	// The isotropic sigma of the same determinant predicts another C_R.
	const double s_iso = std::sqrt(2 * std::pow(C_P.determinant(), 0.25));
	const GeneralPose iso = solveGeneralPose(corners, cam, g, s_iso);
	EXPECT_GT((iso.C_R - ref.C_R).norm() / ref.C_R.norm(), 0.2);
}

TEST(General, AmbiguityAndBothSolutions)
{
	// A small, distant, oblique landmark: the two IPPE solutions are both
	// kept and the noise-free one wins clearly.
	const CameraModel cam;
	const LandmarkGeometry g;
	const CPose3D truth = cameraAt(4.0, 0.6, 0.0, 0.0);
	const GeneralPose gp = solveGeneralPose(projectCorners(truth, cam, g), cam, g, 0.07);
	ASSERT_EQ(gp.solutions.size(), 2u);
	EXPECT_LE(gp.solutions[0].rms_px, gp.solutions[1].rms_px);
	EXPECT_GT(gp.ambiguity_ratio, 10.0);
	const auto [ang, dt] = poseError(gp.solutions[0].landmark_T_camera, truth);
	EXPECT_LT(ang, 1e-6);
	EXPECT_LT(dt, 1e-5);
	// The other solution mirrors the landmark's tilt: a different pose.
	const auto [ang2, dt2] = poseError(gp.solutions[1].landmark_T_camera, truth);
	EXPECT_GT(ang2 + dt2, 1e-3);
	// The covariance is symmetric positive definite.
	const Eigen::Matrix<double, 6, 6> C = gp.solutions[0].cov;
	EXPECT_LT((C - C.transpose()).norm(), 1e-12 * C.norm());
	using Mat6 = Eigen::Matrix<double, 6, 6>;
	EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat6>(C).eigenvalues().minCoeff(), 0);
}
