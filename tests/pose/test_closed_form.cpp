// The paper's closed form against geometric truth, its Jacobians against
// central differences, and the composition to the robot's world pose.
#include <codemark/landmark/map.h>
#include <codemark/landmark/primary.h>
#include <codemark/landmark/truth.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pose/measurement.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <Eigen/Dense>
#include <random>
#include <utility>

#include "common.h"

#include "../common/numeric_diff.h"

using namespace codemark;
using namespace codemark::pose;
using codemark::test::cameraAt;
using codemark::test::projectCorners;
using mrpt::poses::CPose2D;
using mrpt::poses::CPose3D;

namespace
{
// Relative agreement of two matrices, element by element, against the
// largest entry of the row (a row mixes px-scale and rad-scale derivatives).
template <typename A, typename B>
void expectJacobianNear(const A& analytic, const B& numeric, double rel, const std::string& what)
{
	for (int r = 0; r < analytic.rows(); ++r)
	{
		const double scale = std::max(analytic.row(r).cwiseAbs().maxCoeff(), 1e-300);
		for (int c = 0; c < analytic.cols(); ++c)
			EXPECT_NEAR(analytic(r, c), numeric(r, c), rel * scale)
				<< what << " row " << r << " col " << c;
	}
}

struct Config
{
	double d, angle, z, phi1, scale;
};

// Random level-camera configurations whose reference square is in view.
std::vector<Config> randomConfigs(int n, uint32_t seed)
{
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> d(0.4, 6.0), a(-1.3, 1.3), z(-0.5, 0.5), p1(-0.3, 0.3),
		s(0.5, 2.0);
	std::vector<Config> out;
	for (int i = 0; i < n; ++i) out.push_back({d(rng), a(rng), z(rng), p1(rng), s(rng)});
	// Exactly frontal (y1 = y2) and strongly oblique cases.
	out.push_back({2.0, 0.0, 0.0, 0.0, 1.0});
	out.push_back({1.0, 0.0, 0.3, 0.2, 1.0});
	out.push_back({3.0, 1.4, 0.0, 0.0, 1.0});
	out.push_back({1.5, -1.4, -0.2, -0.1, 1.0});
	return out;
}
}  // namespace

TEST(ClosedForm, MatchesGeometricTruth)
{
	const CameraModel cam;
	for (const Config& c : randomConfigs(200, 1))
	{
		const LandmarkGeometry g = LandmarkGeometry::scaled(c.scale);
		const CPose3D landmark_T_camera = cameraAt(c.d, c.angle, c.z, c.phi1);
		const SightingTruth truth = sightingTruth(landmark_T_camera);
		double lambda = 0;
		const Eigen::Vector4d P =
			primaryMeasurement(projectCorners(landmark_T_camera, cam, g), cam, &lambda);
		const Eigen::Vector3d L = landmarkFromPrimary(P, lambda, g.innerHalf());
		EXPECT_NEAR(L[0], truth.L[0], 1e-9 * truth.L[0]) << "d " << c.d << " angle " << c.angle;
		EXPECT_NEAR(L[1], truth.L[1], 1e-9);
		EXPECT_NEAR(L[2], truth.L[2], 1e-9);
		const Eigen::Vector3d pose = poseFromLandmark(L);
		EXPECT_NEAR(pose[0], truth.pose_in_landmark[0], 1e-9 * c.d);
		EXPECT_NEAR(pose[1], truth.pose_in_landmark[1], 1e-9 * c.d);
		EXPECT_NEAR(wrapToPi(pose[2] - truth.pose_in_landmark[2]), 0.0, 1e-9);
	}
}

TEST(ClosedForm, SignsOnSimpleCases)
{
	// Landmark left of the image centre: x1, x2 < 0, phi1 > 0.
	const Eigen::Vector3d L = landmarkFromPrimary(Eigen::Vector4d(-100, 40, -60, 40), 800, 0.08);
	EXPECT_GT(L[1], 0);
	EXPECT_NEAR(L[2], 0, 1e-15);  // equal edges: seen squarely
	// Right edge longer (closer): the camera sits on the landmark's -Y side
	// (observer's left), its axis turned clockwise from the inward normal.
	const Eigen::Vector3d L2 = landmarkFromPrimary(Eigen::Vector4d(-20, 40, 20, 42), 800, 0.08);
	EXPECT_GT(L2[2], 0);
	EXPECT_THROW(
		landmarkFromPrimary(Eigen::Vector4d(0, 0, 10, 10), 800, 0.08), std::invalid_argument);
	EXPECT_THROW(
		landmarkFromPrimary(Eigen::Vector4d(0, 10, 10, -1), 800, 0.08), std::invalid_argument);
}

TEST(ClosedForm, JacobianOfPrimaryMatchesCentralDifferences)
{
	const CameraModel cam;
	for (const Config& c : randomConfigs(100, 2))
	{
		const LandmarkGeometry g = LandmarkGeometry::scaled(c.scale);
		double lambda = 0;
		const Eigen::Vector4d P = primaryMeasurement(
			projectCorners(cameraAt(c.d, c.angle, c.z, c.phi1), cam, g), cam, &lambda);
		Eigen::Matrix<double, 3, 4> J;
		landmarkFromPrimary(P, lambda, g.innerHalf(), &J);
		const Eigen::MatrixXd Jn = codemark::test::numericJacobian(
			[&](const Eigen::Vector4d& p) { return landmarkFromPrimary(p, lambda, g.innerHalf()); },
			P);
		expectJacobianNear(J, Jn, 1e-6, "J_P");
	}
}

TEST(ClosedForm, PrimaryFromLandmarkInvertsTheClosedForm)
{
	const CameraModel cam;
	for (const Config& c : randomConfigs(200, 4))
	{
		const LandmarkGeometry g = LandmarkGeometry::scaled(c.scale);
		double lambda = 0;
		const Eigen::Vector4d P = primaryMeasurement(
			projectCorners(cameraAt(c.d, c.angle, c.z, c.phi1), cam, g), cam, &lambda);
		const Eigen::Vector3d L = landmarkFromPrimary(P, lambda, g.innerHalf());
		Eigen::Matrix<double, 4, 3> J;
		const Eigen::Vector4d back = primaryFromLandmark(L, lambda, g.innerHalf(), &J);
		EXPECT_LT((back - P).cwiseAbs().maxCoeff(), 1e-9 * P.cwiseAbs().maxCoeff())
			<< "d " << c.d << " angle " << c.angle;
		const Eigen::MatrixXd Jn = codemark::test::numericJacobian(
			[&](const Eigen::Vector3d& l) { return primaryFromLandmark(l, lambda, g.innerHalf()); },
			L);
		expectJacobianNear(J, Jn, 1e-6, "dP/dL");
	}
	EXPECT_THROW(
		primaryFromLandmark(Eigen::Vector3d(0.05, 0, 1.5), 800, 0.08), std::invalid_argument);
	// The overload on cosines and sines: the same P and Jacobian, and false
	// (P untouched) where the other throws.
	for (const Config& c : randomConfigs(50, 5))
	{
		const Eigen::Vector3d L(c.d, c.phi1, c.angle);
		Eigen::Matrix<double, 4, 3> J, Jcs;
		const Eigen::Vector4d P = primaryFromLandmark(L, 800, 0.08, &J);
		Eigen::Vector4d Pcs;
		ASSERT_TRUE(primaryFromLandmark(
			L[0], std::cos(L[1]), std::sin(L[1]), std::cos(L[2]), std::sin(L[2]), 800, 0.08, Pcs,
			&Jcs));
		EXPECT_LT((Pcs - P).cwiseAbs().maxCoeff(), 1e-12 * P.cwiseAbs().maxCoeff());
		EXPECT_LT((Jcs - J).cwiseAbs().maxCoeff(), 1e-12 * J.cwiseAbs().maxCoeff());
	}
	Eigen::Vector4d untouched = Eigen::Vector4d::Constant(7);
	EXPECT_FALSE(
		primaryFromLandmark(0.05, 1, 0, std::cos(1.5), std::sin(1.5), 800, 0.08, untouched));
	EXPECT_EQ(untouched, Eigen::Vector4d::Constant(7));
}

// The weighted least-squares L from P: the closed form's L where P is exact
// (its four numbers agree), and on noisy P (Monte Carlo, calibrated-size
// C_P at 4 m, 30 deg) an unbiased estimate whose covariance is the
// predicted (J^T C_P^-1 J)^-1 and whose phi2 is far better than the closed
// form's from the same samples.
TEST(ClosedForm, RefinementOnPrimaryIsTheWeightedLeastSquaresEstimate)
{
	const CameraModel cam;
	const LandmarkGeometry g;
	PoseOptions o;
	o.sigma_px = 0.04;
	o.corr_x12 = -0.5;
	o.corr_y12 = 0.8;
	for (const Config& c : randomConfigs(50, 5))
	{
		double lambda = 0;
		const Eigen::Vector4d P = primaryMeasurement(
			projectCorners(cameraAt(c.d, c.angle, c.z, c.phi1), cam, g), cam, &lambda);
		const Eigen::Vector3d L0 = landmarkFromPrimary(P, lambda, g.innerHalf());
		const Eigen::Vector3d L =
			refineLandmarkOnPrimary(P, o.primaryCovariance(P), lambda, g.innerHalf(), L0);
		EXPECT_LT((L - L0).cwiseAbs().maxCoeff(), 1e-9 * (1 + L0[0]));
	}
	const SightingTruth truth = sightingTruth(cameraAt(4.0, 30 * M_PI / 180));
	double lambda = 0;
	const Eigen::Vector4d P0 =
		primaryMeasurement(projectCorners(cameraAt(4.0, 30 * M_PI / 180), cam, g), cam, &lambda);
	const Eigen::Matrix4d C_P = o.primaryCovariance(P0);
	Eigen::Matrix3d C_pred;
	refineLandmarkOnPrimary(P0, C_P, lambda, g.innerHalf(), truth.L, &C_pred);
	const Eigen::Matrix4d A = C_P.llt().matrixL();
	std::mt19937 rng(6);
	std::normal_distribution<double> n01;
	const int N = 10000;
	Eigen::Vector3d mean = Eigen::Vector3d::Zero();
	Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
	double se_cf = 0, se_ml = 0;
	for (int i = 0; i < N; ++i)
	{
		const Eigen::Vector4d P = P0 + A * Eigen::Vector4d(n01(rng), n01(rng), n01(rng), n01(rng));
		const Eigen::Vector3d Lc = landmarkFromPrimary(P, lambda, g.innerHalf());
		const Eigen::Vector3d L = refineLandmarkOnPrimary(P, C_P, lambda, g.innerHalf(), Lc);
		const Eigen::Vector3d e = L - truth.L;
		mean += e / N;
		cov += e * e.transpose() / N;
		se_cf += std::pow(Lc[2] - truth.L[2], 2) / N;
		se_ml += std::pow(e[2], 2) / N;
	}
	cov -= mean * mean.transpose();
	for (int k = 0; k < 3; ++k)
		EXPECT_LT(
			std::abs(mean[k]), 3 * std::sqrt(C_pred(k, k) / N) + 1e-3 * std::sqrt(C_pred(k, k)))
			<< "component " << k;
	EXPECT_LT((cov - C_pred).norm() / C_pred.norm(), 0.1);
	EXPECT_LT(se_ml, 0.25 * se_cf)
		<< "phi2 RMS: refined " << std::sqrt(se_ml) << ", closed form " << std::sqrt(se_cf);
}

TEST(ClosedForm, JacobianOfPoseMatchesCentralDifferences)
{
	for (const Config& c : randomConfigs(100, 3))
	{
		const Eigen::Vector3d L = sightingTruth(cameraAt(c.d, c.angle, c.z, c.phi1)).L;
		Eigen::Matrix3d J;
		poseFromLandmark(L, &J);
		Eigen::Matrix3d Jn;
		for (int k = 0; k < 3; ++k)
		{
			const double h = 1e-6;
			Eigen::Vector3d a = L, b = L;
			a[k] += h;
			b[k] -= h;
			Eigen::Vector3d d = poseFromLandmark(a) - poseFromLandmark(b);
			d[2] = wrapToPi(d[2]);
			Jn.col(k) = d / (2 * h);
		}
		expectJacobianNear(J, Jn, 1e-6, "J_L");
	}
}

TEST(ClosedForm, CovariancePropagation)
{
	const Eigen::Matrix4d C_P = primaryCovariance(0.1, 0.2);
	EXPECT_DOUBLE_EQ(C_P(0, 0), 0.01);
	EXPECT_DOUBLE_EQ(C_P(1, 1), 0.04);
	EXPECT_DOUBLE_EQ(C_P(3, 3), 0.04);
	EXPECT_DOUBLE_EQ(C_P(0, 1), 0.0);
	// measure() with the paper's formulas alone uses C_L = J_P C_P J_P^T and
	// C_R = J_L C_L J_L^T (the spec's); refined on P, C_L = (J^T C_P^-1 J)^-1
	// with J = dP/dL, never larger.
	const CameraModel cam;
	const LandmarkGeometry g;
	PoseOptions opt;
	opt.sigma_px = 0.3;
	opt.refine_on_primary = false;
	// The local covariance; at 0.3 px the mirror image would be folded in
	// (test_ambiguity.cpp).
	opt.fold_ambiguity = false;
	const auto corners = projectCorners(cameraAt(2.0, 0.5, 0.1, 0.1), cam, g);
	const Measurement m = measure(corners, cam, g, opt);
	Eigen::Matrix<double, 3, 4> J_P;
	Eigen::Matrix3d J_L;
	landmarkFromPrimary(m.P, cam.fx(), g.innerHalf(), &J_P);
	poseFromLandmark(m.L, &J_L);
	const Eigen::Matrix3d C_L = J_P * primaryCovariance(0.3, 0.3) * J_P.transpose();
	EXPECT_LT((m.C_L - C_L).norm(), 1e-12 * C_L.norm());
	EXPECT_LT((m.C_R - J_L * C_L * J_L.transpose()).norm(), 1e-12 * m.C_R.norm());
	opt.refine_on_primary = true;
	const Measurement mr = measure(corners, cam, g, opt);
	Eigen::Matrix<double, 4, 3> J;
	primaryFromLandmark(mr.L, cam.fx(), g.innerHalf(), &J);
	const Eigen::Matrix3d C_Lr =
		(J.transpose() * primaryCovariance(0.3, 0.3).inverse() * J).inverse();
	EXPECT_LT((mr.C_L - C_Lr).norm(), 1e-9 * C_Lr.norm());
	EXPECT_LT((mr.L - m.L).norm(), 1e-9 * m.L.norm());	// exact P: the same L
	EXPECT_LE(mr.C_L(2, 2), m.C_L(2, 2));
	// phi2 is the weak direction: larger than phi1's variance by orders.
	EXPECT_GT(m.C_L(2, 2), 100 * m.C_L(1, 1));
}

TEST(Composition, RobotWorldPoseRecoveredExactly)
{
	const CameraModel cam;
	std::mt19937 rng(4);
	std::uniform_real_distribution<double> u(-1, 1);
	for (int i = 0; i < 50; ++i)
	{
		// A landmark on a wall somewhere, scaled.
		MapLandmark lm;
		lm.x_m = 3 * u(rng);
		lm.y_m = 3 * u(rng);
		lm.z_m = 0.8 + 0.3 * u(rng);
		lm.yaw_rad = M_PI * u(rng);
		lm.scale = 1.0 + 0.5 * u(rng);
		// A camera mounted with offset, height and yaw (optical axis level).
		const double mount_yaw = 0.8 * u(rng);
		const CPose3D robot_T_camera =
			CPose3D(0.2 * u(rng), 0.1 * u(rng), 0.6 + 0.3 * u(rng), mount_yaw, 0, 0) +
			CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
		// The robot placed so that the camera sees the landmark from the front.
		const CPose3D landmark_T_camera = cameraAt(
			1 + 2 * std::abs(u(rng)), 0.8 * u(rng), robot_T_camera.z() - lm.z_m, 0.2 * u(rng));
		const CPose3D world_T_camera = lm.world_T_landmark() + landmark_T_camera;
		const CPose3D world_T_robot3 = world_T_camera + (-robot_T_camera);
		ASSERT_NEAR(world_T_robot3.z(), 0, 1e-9);
		ASSERT_NEAR(world_T_robot3.pitch(), 0, 1e-9);
		ASSERT_NEAR(world_T_robot3.roll(), 0, 1e-9);

		const Measurement m =
			measure(projectCorners(landmark_T_camera, cam, lm.geometry()), cam, lm.geometry());
		Eigen::Matrix3d C_world, J;
		const CPose2D robot = robotPoseInWorld(
			m.pose_in_landmark, m.C_R, landmarkPlanarPose(lm.world_T_landmark()),
			cameraPlanarPose(robot_T_camera), &C_world, &J);
		EXPECT_NEAR(robot.x(), world_T_robot3.x(), 1e-8);
		EXPECT_NEAR(robot.y(), world_T_robot3.y(), 1e-8);
		EXPECT_NEAR(wrapToPi(robot.phi() - world_T_robot3.yaw()), 0, 1e-9);
		// The inverse mapping gives back the camera's pose in L.
		const Eigen::Vector3d c = cameraInLandmark(
			robot, landmarkPlanarPose(lm.world_T_landmark()), cameraPlanarPose(robot_T_camera));
		EXPECT_LT((c.head<2>() - m.pose_in_landmark.head<2>()).norm(), 1e-8);
		EXPECT_NEAR(wrapToPi(c[2] - m.pose_in_landmark[2]), 0, 1e-9);

		// The composition's Jacobian against central differences.
		Eigen::Matrix3d Jn;
		for (int k = 0; k < 3; ++k)
		{
			const double h = 1e-6;
			Eigen::Vector3d a = m.pose_in_landmark, b = a;
			a[k] += h;
			b[k] -= h;
			const CPose2D ra = robotPoseInWorld(
				a, m.C_R, landmarkPlanarPose(lm.world_T_landmark()),
				cameraPlanarPose(robot_T_camera));
			const CPose2D rb = robotPoseInWorld(
				b, m.C_R, landmarkPlanarPose(lm.world_T_landmark()),
				cameraPlanarPose(robot_T_camera));
			Jn.col(k) << (ra.x() - rb.x()) / (2 * h), (ra.y() - rb.y()) / (2 * h),
				wrapToPi(ra.phi() - rb.phi()) / (2 * h);
		}
		EXPECT_LT((J - Jn).norm(), 1e-6 * J.norm());
		EXPECT_LT((C_world - J * m.C_R * J.transpose()).norm(), 1e-12 * C_world.norm());
		// A rigid change of frame keeps the determinant of the covariance.
		EXPECT_NEAR(
			C_world.determinant(), m.C_R.determinant(), 1e-6 * std::abs(m.C_R.determinant()));
	}
}

TEST(Composition, CameraPlanarPoseOfMountedCamera)
{
	const CPose3D level_fwd(0.3, -0.1, 0.5, -M_PI / 2, 0, -M_PI / 2);
	const CPose2D p = cameraPlanarPose(level_fwd);
	EXPECT_NEAR(p.x(), 0.3, 1e-12);
	EXPECT_NEAR(p.y(), -0.1, 1e-12);
	EXPECT_NEAR(p.phi(), 0.0, 1e-12);
	const CPose3D left =
		CPose3D(0, 0, 0.5, M_PI / 2, 0, 0) + CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
	EXPECT_NEAR(cameraPlanarPose(left).phi(), M_PI / 2, 1e-12);
}

TEST(Options, LoadSaveAndMethodNames)
{
	EXPECT_EQ(poseMethodFromString("general6dof"), PoseMethod::General6Dof);
	EXPECT_EQ(poseMethodFromString("ClosedForm"), PoseMethod::ClosedForm);
	EXPECT_THROW(poseMethodFromString("pnp"), std::invalid_argument);
	PoseOptions o;
	EXPECT_DOUBLE_EQ(o.sigma_px, kDefaultSigmaPx);
	o.method = PoseMethod::General6Dof;
	o.sigma_px = 0.2;
	o.fold_ambiguity = false;  // not the default
	o.reference_noise_grey = 2;
	o.corner_tilt_noise_ratio = 1.4;
	o.corner_tilt_ratio_table = sigmaTableFromString("30:0.3 90:0.9");
	o.noise_sigma_x_table = sigmaTableFromString("20:0.01 80:0.004");
	o.noise_sigma_y_table = sigmaTableFromString("30:0.012");
	mrpt::config::CConfigFileMemory cfg;
	o.saveToConfigFile(cfg, "POSE");
	PoseOptions r;
	r.loadFromConfigFile(cfg, "POSE");
	EXPECT_EQ(r.method, PoseMethod::General6Dof);
	EXPECT_DOUBLE_EQ(r.sigma_px, 0.2);
	EXPECT_FALSE(r.fold_ambiguity);
	EXPECT_DOUBLE_EQ(r.reference_noise_grey, 2);
	EXPECT_EQ(r.corner_tilt_ratio_table, o.corner_tilt_ratio_table);
	EXPECT_DOUBLE_EQ(r.corner_tilt_noise_ratio, 1.4);
	EXPECT_EQ(r.noise_sigma_x_table, o.noise_sigma_x_table);
	EXPECT_EQ(r.noise_sigma_y_table, o.noise_sigma_y_table);
	cfg.write("POSE", "sigma_px", -1.0);
	EXPECT_THROW(r.loadFromConfigFile(cfg, "POSE"), std::invalid_argument);
	// Not numbers at all (MRPT would read 0.03 and 0), not booleans (MRPT's
	// read_bool would take them as false): named, not taken.
	const std::pair<const char*, const char*> bad_values[] = {
		{"clipped_side_sigma_px", "0.03px"},
		{"lm_max_iterations", "0.03px"},
		{"fold_ambiguity", "maybe"},
		{"reference_noise_grey", "2 grey"},
		{"corner_tilt_noise_ratio", "1.4x"},
		{"noise_sigma_x_table", "20:0.01 10:0.02"},
		{"refine_on_primary", "maybe"},
		{"second_order_pose_covariance", "true ; note"},
		{"corner_tilt_ratio_table", "30:0.3 20:0.4"}};
	for (const auto& [key, value] : bad_values)
	{
		mrpt::config::CConfigFileMemory bad;
		o.saveToConfigFile(bad, "POSE");
		bad.write("POSE", key, std::string(value));
		try
		{
			r.loadFromConfigFile(bad, "POSE");
			ADD_FAILURE() << key << " = " << value << " was accepted";
		}
		catch (const std::exception& e)
		{
			EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
		}
	}
	EXPECT_EQ(sigmaSourceFromString("detector"), SigmaSource::Detector);
	EXPECT_THROW(sigmaSourceFromString("auto"), std::invalid_argument);
}

TEST(Options, SigmaFromTheDetector)
{
	const CameraModel cam;
	const LandmarkGeometry g;
	Detection d;
	d.id = 3;
	d.corners = projectCorners(cameraAt(2.0, 0.3), cam, g);
	d.quality.corner_sigma_px = 0.2;
	PoseOptions o;
	o.sigma_px = 0.05;
	o.fold_ambiguity = false;  // the local covariances scale with sigma^2
	const Measurement fixed = measure(d, cam, g, o);
	o.sigma_source = SigmaSource::Detector;
	const Measurement det = measure(d, cam, g, o);
	// Covariances scale with sigma^2: (0.2 / sqrt 2 / 0.05)^2 = 8.
	EXPECT_NEAR(det.C_R(2, 2) / fixed.C_R(2, 2), 8.0, 1e-9);
	EXPECT_NEAR(det.C_P(0, 0), 0.02, 1e-15);
	// The floor, and the fallback when the detector gives no estimate.
	d.quality.corner_sigma_px = 1e-4;
	EXPECT_NEAR(measure(d, cam, g, o).C_P(1, 1), o.min_sigma_px * o.min_sigma_px, 1e-18);
	d.quality.corner_sigma_px = 0;
	EXPECT_NEAR(measure(d, cam, g, o).C_P(1, 1), 0.05 * 0.05, 1e-18);
	// The detector's sigma replaces a tabulated model too.
	d.quality.corner_sigma_px = 0.2;
	o.sigma_x_table = sigmaTableFromString("10:0.5 100:0.4");
	o.sigma_y_table = sigmaTableFromString("10:0.5");
	EXPECT_NEAR(measure(d, cam, g, o).C_P(0, 0), 0.02, 1e-15);
	EXPECT_NEAR(measure(d, cam, g, o).C_P(3, 3), 0.02, 1e-15);
}

// The size-dependent, correlated C_P of PoseOptions::primaryCovariance().
TEST(PrimaryCovariance, SizeDependentModel)
{
	PoseOptions o;
	o.sigma_px = 0.03;
	o.sigma_y_px = 0.05;
	const Eigen::Vector4d P(-30, 20, 30, 21);  // width 60 px, height 41 px
	// No growth, no correlation: the spec's diagonal.
	EXPECT_LT((o.primaryCovariance(P) - primaryCovariance(0.03, 0.05)).norm(), 1e-15);
	o.growth_x_px = 0.1;
	o.growth_y_px = 0.2;
	o.size_exponent_x = 2;
	o.size_exponent_y = 1;
	o.size_reference_px = 60;
	o.corr_x12 = -0.5;
	o.corr_growth_x12 = -0.9;
	o.corr_y12 = 0.6;
	o.corr_growth_y12 = 0.1;
	const Eigen::Matrix4d C = o.primaryCovariance(P);
	// At the reference width the growth term is growth_x_px.
	EXPECT_NEAR(C(0, 0), 0.03 * 0.03 + 0.1 * 0.1, 1e-15);
	EXPECT_NEAR(C(2, 2), C(0, 0), 1e-15);
	EXPECT_NEAR(C(0, 2), -0.5 * 0.03 * 0.03 - 0.9 * 0.1 * 0.1, 1e-15);
	const double gy = 0.2 * 60.0 / 41.0;
	EXPECT_NEAR(C(1, 1), 0.05 * 0.05 + gy * gy, 1e-15);
	EXPECT_NEAR(C(1, 3), 0.6 * 0.05 * 0.05 + 0.1 * gy * gy, 1e-15);
	EXPECT_EQ(C(0, 1), 0);
	EXPECT_LT((C - C.transpose()).norm(), 1e-18);
	EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(C).eigenvalues().minCoeff(), 0);
	// Smaller landmarks are noisier.
	EXPECT_GT(o.primaryCovariance(P / 2)(0, 0), C(0, 0));
	o.corr_y12 = 1.0;
	EXPECT_THROW(o.validate(), std::invalid_argument);
}

// C_P at the image's noise: the noise-driven part of each variance scales
// with the noise squared, the rest (the detector's bias) stays.
TEST(PrimaryCovariance, FollowsTheImageNoise)
{
	PoseOptions o;
	o.sigma_x_table = sigmaTableFromString("20:0.05 80:0.01");
	o.sigma_y_table = sigmaTableFromString("40:0.04 160:0.008");
	o.corr_growth_x12 = -0.2;
	o.corr_growth_y12 = 0.3;
	const Eigen::Vector4d P(-40, 40, 40, 41);  // width 80 px, height 81 px
	const Eigen::Matrix4d C_ref = o.primaryCovariance(P);
	// Off (no reference) or no measured noise: unchanged.
	EXPECT_EQ(o.primaryCovariance(P, 6.0), C_ref);
	o.reference_noise_grey = 2;
	o.noise_sigma_x_table = sigmaTableFromString("20:0.03 80:0.006");
	o.noise_sigma_y_table = sigmaTableFromString("40:0.02 160:0.004");
	EXPECT_EQ(o.primaryCovariance(P, 0.0), C_ref);
	EXPECT_LT((o.primaryCovariance(P, 2.0) - C_ref).norm(), 1e-18);
	const double nx = 0.006 * 0.006, vx = C_ref(0, 0);
	const double sy = interpolateSigma(o.noise_sigma_y_table, 81), vy = C_ref(1, 1);
	// A quieter image than the reference keeps its C_P.
	EXPECT_LT((o.primaryCovariance(P, 1.0) - C_ref).norm(), 1e-18);
	for (const double n : {3.0, 4.0, 6.0})
	{
		const double q = (n / 2) * (n / 2) - 1;
		const Eigen::Matrix4d C = o.primaryCovariance(P, n);
		EXPECT_NEAR(C(0, 0), vx + q * nx, 1e-15) << n;
		EXPECT_NEAR(C(2, 2), vx + q * nx, 1e-15) << n;
		EXPECT_NEAR(C(1, 1), vy + q * sy * sy, 1e-15) << n;
		// Each axis's correlation is kept, x and y stay uncorrelated.
		EXPECT_NEAR(C(0, 2) / C(0, 0), C_ref(0, 2) / C_ref(0, 0), 1e-12) << n;
		EXPECT_NEAR(C(1, 3) / C(1, 1), C_ref(1, 3) / C_ref(1, 1), 1e-12) << n;
		EXPECT_EQ(C(0, 1), 0);
		EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(C).eigenvalues().minCoeff(), 0);
		// More noise, more variance.
		EXPECT_GT(o.primaryCovariance(P, n * 1.5)(0, 0), C(0, 0));
	}
	// A noise part as large as the whole variance: all of it scales.
	o.noise_sigma_x_table = sigmaTableFromString("20:1 80:1");
	EXPECT_NEAR(o.primaryCovariance(P, 4.0)(0, 0), 4 * vx, 1e-15);
	// measure() of a detection takes the detector's noise.
	const CameraModel cam;
	const LandmarkGeometry g;
	Detection d;
	d.corners = {{{280, 200}, {360, 200}, {360, 281}, {280, 281}}};
	o.noise_sigma_x_table = sigmaTableFromString("20:0.03 80:0.006");
	d.quality.image_noise_grey = 2;
	const double c2 = measure(d, cam, g, o).C_P(0, 0);
	d.quality.image_noise_grey = 6;
	EXPECT_GT(measure(d, cam, g, o).C_P(0, 0), c2);
	o.reference_noise_grey = -1;
	EXPECT_THROW(o.validate(), std::invalid_argument);
}

// The scatter model: a detection whose bands the detector measured gets
// (band_ratio se)^2 + floor(size)^2 per axis, with the tables' correlations
// and no noise scaling; one without bands, and a prediction, keep the
// tables.
TEST(PrimaryCovariance, FollowsTheBandsScatter)
{
	PoseOptions o;
	o.sigma_x_table = sigmaTableFromString("20:0.05 80:0.01");
	o.sigma_y_table = sigmaTableFromString("40:0.04 160:0.008");
	o.corr_growth_x12 = -0.2;
	o.corr_growth_y12 = 0.3;
	o.reference_noise_grey = 2;
	o.noise_sigma_x_table = sigmaTableFromString("20:0.03 80:0.006");
	const Eigen::Vector4d P(-40, 40, 40, 41);  // width 80 px, height 81 px
	const Eigen::Matrix4d C_tables = o.primaryCovariance(P, 4.0);
	// Off: the bands' scatter changes nothing.
	EXPECT_EQ(o.primaryCovariance(P, 4.0, 0.03), C_tables);
	o.band_ratio_x = 5;
	o.band_ratio_y = 4;
	o.band_floor_x_table = sigmaTableFromString("20:0.1 80:0.02");
	// Not measured (0): the tables, noise scaling included.
	EXPECT_EQ(o.primaryCovariance(P, 4.0, 0.0), C_tables);
	for (const double se : {0.005, 0.02, 0.08})
	{
		const Eigen::Matrix4d C = o.primaryCovariance(P, 4.0, se);
		const double vx = 25 * se * se + 0.02 * 0.02, vy = 16 * se * se;
		EXPECT_NEAR(C(0, 0), vx, 1e-15) << se;
		EXPECT_NEAR(C(2, 2), vx, 1e-15) << se;
		EXPECT_NEAR(C(0, 2), -0.2 * vx, 1e-15) << se;
		EXPECT_NEAR(C(1, 1), vy, 1e-15) << se;	// no floor table: none
		EXPECT_NEAR(C(1, 3), 0.3 * vy, 1e-15) << se;
		EXPECT_EQ(C(0, 1), 0);
		// The image's noise is in the scatter already.
		EXPECT_EQ(o.primaryCovariance(P, 8.0, se), C) << se;
	}
	// measure() of a detection takes the detector's scatter.
	const CameraModel cam;
	const LandmarkGeometry g;
	Detection d;
	d.corners = {{{280, 200}, {360, 200}, {360, 281}, {280, 281}}};
	d.quality.edge_bend_se_px = 0.01;
	const double c1 = measure(d, cam, g, o).C_P(0, 0);
	d.quality.edge_bend_se_px = 0.04;
	EXPECT_GT(measure(d, cam, g, o).C_P(0, 0), 4 * c1);
	o.band_ratio_y = -1;
	EXPECT_THROW(o.validate(), std::invalid_argument);
}

// The tabulated sigma, the clipped sides' and the aligned edges' terms.
TEST(PrimaryCovariance, TablesClippedSidesAndAlignedEdges)
{
	const SigmaTable t = sigmaTableFromString("20:0.08 40:0.02 80:0.005");
	ASSERT_EQ(t.size(), 3u);
	EXPECT_DOUBLE_EQ(interpolateSigma(t, 10), 0.08);  // the ends beyond the table
	EXPECT_DOUBLE_EQ(interpolateSigma(t, 200), 0.005);
	EXPECT_NEAR(interpolateSigma(t, 40), 0.02, 1e-15);
	EXPECT_NEAR(interpolateSigma(t, std::sqrt(20.0 * 40)), 0.04, 1e-12);  // log-log midpoint
	EXPECT_EQ(sigmaTableFromString(toString(t)), t);
	EXPECT_TRUE(sigmaTableFromString("").empty());
	for (const char* bad : {"20:0.08 20:0.01", "20;0.08", "20:", "x:0.1", "20:-1", "20:0.1abc"})
		EXPECT_THROW(sigmaTableFromString(bad), std::invalid_argument) << bad;

	PoseOptions o;
	o.sigma_x_table = t;
	o.sigma_y_table = sigmaTableFromString("40:0.03");
	o.corr_growth_x12 = -0.5;
	o.corr_growth_y12 = 0.25;
	const Eigen::Vector4d P(-20, 20, 20, 20);  // width 40 px, height 40 px
	const Eigen::Matrix4d C = o.primaryCovariance(P);
	EXPECT_NEAR(C(0, 0), 0.02 * 0.02, 1e-15);
	EXPECT_NEAR(C(0, 2), -0.5 * 0.02 * 0.02, 1e-15);
	EXPECT_NEAR(C(3, 3), 0.03 * 0.03, 1e-15);
	EXPECT_NEAR(C(1, 3), 0.25 * 0.03 * 0.03, 1e-15);
	mrpt::config::CConfigFileMemory cfg;
	o.clipped_side_sigma_px = 0.04;
	o.clipped_side_correlation = 0.5;
	o.aligned_edge_ratio = 2;
	o.saveToConfigFile(cfg, "POSE");
	PoseOptions r;
	r.loadFromConfigFile(cfg, "POSE");
	EXPECT_EQ(r.sigma_x_table, o.sigma_x_table);
	EXPECT_EQ(r.sigma_y_table, o.sigma_y_table);
	EXPECT_DOUBLE_EQ(r.clipped_side_correlation, 0.5);

	// Clipped sides: a left side moves x1 alone, a top both half-lengths by
	// half its shift; two clipped sides' shifts correlate.
	const double v = 0.04 * 0.04;
	Eigen::Matrix4d K = o.clippedSidesCovariance({{false, false, false, true}});
	EXPECT_NEAR(K(0, 0), v, 1e-18);
	EXPECT_NEAR(K.norm(), v, 1e-18);
	K = o.clippedSidesCovariance({{true, false, false, false}});
	EXPECT_NEAR(K(1, 1), v / 4, 1e-18);
	EXPECT_NEAR(K(1, 3), v / 4, 1e-18);
	K = o.clippedSidesCovariance({{false, true, false, true}});	 // right and left
	EXPECT_NEAR(K(0, 2), -0.5 * v, 1e-18);	// outward shifts: x1 down, x2 up
	// The same by sampling the sides' shifts.
	std::mt19937 rng(5);
	std::normal_distribution<double> n(0, 1);
	Eigen::Matrix4d S = Eigen::Matrix4d::Zero();
	const int N = 100000;
	for (int i = 0; i < N; ++i)
	{
		const double common = n(rng), a = n(rng), b = n(rng);
		const double dr = 0.04 * (std::sqrt(0.5) * common + std::sqrt(0.5) * a);
		const double dl = 0.04 * (std::sqrt(0.5) * common + std::sqrt(0.5) * b);
		const Eigen::Vector4d e(-dl, 0, dr, 0);
		S += e * e.transpose() / N;
	}
	EXPECT_LT((S - K).norm(), 0.02 * K.norm());

	// measure() of a detection adds them: its flags, its corners' rows.
	const CameraModel cam;
	const LandmarkGeometry g;
	Detection d;
	d.corners = projectCorners(cameraAt(2.0, 0.3), cam, g);
	PoseOptions m;
	m.clipped_side_sigma_px = 0.04;
	const Eigen::Matrix4d before = measure(d, cam, g, m).C_P;
	d.quality.fill_clipped = {{false, false, false, true}};
	EXPECT_NEAR(measure(d, cam, g, m).C_P(0, 0) - before(0, 0), v, 1e-15);
	EXPECT_NEAR(measure(d.corners, cam, g, m).C_P(0, 0), before(0, 0), 1e-15);

	// Aligned edges: full weight on a row, none a row or more apart.
	PoseOptions a;
	a.sigma_y_px = 0.02;
	a.aligned_edge_ratio = 2;
	const Eigen::Matrix4d A0 = a.alignedEdgesCovariance(P, 0, 0);
	EXPECT_NEAR(A0(1, 1), 2 * 0.25 * 4 * 0.02 * 0.02, 1e-18);
	EXPECT_NEAR(A0(1, 3), A0(1, 1), 1e-18);
	EXPECT_NEAR(a.alignedEdgesCovariance(P, 0.5, -1.5)(1, 1), A0(1, 1) / 4, 1e-18);
	EXPECT_EQ(a.alignedEdgesCovariance(P, 1.0, 2.0).norm(), 0);
}

// The second-order C_R against the sample covariance of the exact pose of
// Gaussian L samples, where phi2 is uncertain enough for first order to miss.
TEST(PoseCovariance, SecondOrderMatchesSamples)
{
	const Eigen::Vector3d L(3.5, 0.05, 0.3);
	Eigen::Matrix3d C_L;
	C_L << 4e-6, 0, 1e-5,  //
		0, 1e-8, -2e-6,	 //
		1e-5, -2e-6, 9e-4;	// sigma(phi2) = 1.7 deg, phi1 far better known
	const Eigen::LLT<Eigen::Matrix3d> llt(C_L);
	std::mt19937 rng(3);
	std::normal_distribution<double> n01;
	const int N = 200000;
	std::vector<Eigen::Vector3d> poses(N);
	Eigen::Vector3d mean = Eigen::Vector3d::Zero();
	const Eigen::Vector3d p0 = poseFromLandmark(L);
	for (int i = 0; i < N; ++i)
	{
		const Eigen::Vector3d l = L + llt.matrixL() * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
		poses[i] = poseFromLandmark(l);
		poses[i][2] = p0[2] + wrapToPi(poses[i][2] - p0[2]);
		mean += poses[i] / N;
	}
	Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
	for (const auto& p : poses) S += (p - mean) * (p - mean).transpose() / (N - 1);
	Eigen::Matrix3d J_L;
	poseFromLandmark(L, &J_L);
	const Eigen::Matrix3d first = J_L * C_L * J_L.transpose();
	const Eigen::Matrix3d second = poseCovarianceSecondOrder(L, C_L);
	// Compare in the metric of the sample covariance (whitened), where the
	// near-singular direction counts as much as the others.
	const Eigen::Matrix3d W = S.llt().matrixL().solve(Eigen::Matrix3d::Identity());
	const double err2 = (W * second * W.transpose() - Eigen::Matrix3d::Identity()).norm();
	const double err1 = (W * first * W.transpose() - Eigen::Matrix3d::Identity()).norm();
	// Third and higher orders of cos and sin remain; the second-order term
	// must take at least half of the first order's misfit away.
	EXPECT_LT(err2, 0.3) << "first order: " << err1;
	EXPECT_GT(err1, 2 * err2);
}
