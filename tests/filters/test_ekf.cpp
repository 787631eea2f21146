// EKF localization ("ekf" and "ekf-pose") on tiny problems with known answers.
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include "common.h"

#include "../common/numeric_diff.h"

using namespace codemark;
using namespace codemark::filters;
using namespace codemark::filters::test;
using mrpt::poses::CPose2D;

namespace
{
const Eigen::Vector3d kSigma(0.01, 0.002, 0.01);  // l2 [m], phi1, phi2 [rad]

PoseEstimate guess(const CPose2D& p, double sxy, double syaw)
{
	PoseEstimate e;
	e.initialized = true;
	e.mean = p;
	e.cov = Eigen::Vector3d(sxy * sxy, sxy * sxy, syaw * syaw).asDiagonal();
	return e;
}

bool isSpd(const Eigen::Matrix3d& P)
{
	if (!P.allFinite() ||
		(P - P.transpose()).cwiseAbs().maxCoeff() > 1e-12 * std::max(1.0, P.norm()))
		return false;
	return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(P).eigenvalues()[0] > 0;
}

class BothVariants : public ::testing::TestWithParam<EkfMeasurement>
{
};
}  // namespace

TEST(EkfModel, ObservationJacobianMatchesNumeric)
{
	std::mt19937 rng(7);
	std::uniform_real_distribution<double> u(-1.0, 1.0);
	for (int k = 0; k < 200; ++k)
	{
		// Headings across the whole circle, including near +-pi.
		const Eigen::Vector3d x(2 + u(rng), 2 + u(rng), M_PI * u(rng));
		const CPose2D cam(0.1 + 0.1 * u(rng), 0.05 * u(rng), 0.5 * u(rng));
		const CPose2D lm(6 + u(rng), 2 + u(rng), M_PI + 0.5 * u(rng));
		Eigen::Matrix3d H;
		const Eigen::Vector3d h0 = predictLandmarkMeasurement(x, cam, lm, &H);
		const Eigen::Matrix3d Hn = codemark::test::numericJacobian(
			[&](const Eigen::Vector3d& v) { return predictLandmarkMeasurement(v, cam, lm); }, x,
			1e-6, {1, 2});
		EXPECT_LT((H - Hn).cwiseAbs().maxCoeff(), 1e-6) << "x " << x.transpose() << "\nH\n"
														<< H << "\nHn\n"
														<< Hn;
		EXPECT_GT(h0[0], 0);
	}
}

TEST(EkfModel, MeasurementAgreesWithThePoseLibrary)
{
	// h(x) inverts pose::robotPoseInWorld: the fix from the predicted L is x.
	const CPose2D robot(2.0, 1.5, 0.3);
	const auto cam3 = cameraOnRobot(0.2);
	const MapLandmark l = roomMap().landmarks[0];
	const auto s = sighting(robot, cam3, l, kSigma);
	const CPose2D fix = pose::robotPoseInWorld(
		s.pose_in_landmark, s.C_R, pose::landmarkPlanarPose(l.world_T_landmark()),
		pose::cameraPlanarPose(cam3));
	EXPECT_NEAR(fix.x(), robot.x(), 1e-12);
	EXPECT_NEAR(fix.y(), robot.y(), 1e-12);
	EXPECT_NEAR(mrpt::math::wrapToPi(fix.phi() - robot.phi()), 0.0, 1e-12);
	// And agrees with the pose library's own inverse.
	const Eigen::Vector3d c = pose::cameraInLandmark(
		robot, pose::landmarkPlanarPose(l.world_T_landmark()), pose::cameraPlanarPose(cam3));
	EXPECT_LT((c - s.pose_in_landmark).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(EkfModel, MotionJacobiansMatchNumeric)
{
	const Eigen::Vector3d x(1, 2, 3.1), u(0.2, -0.05, 0.1);
	Eigen::Matrix3d F, G;
	composeMotion(x, u, &F, &G);
	const Eigen::MatrixXd Fn = codemark::test::numericJacobian(
		[&](const Eigen::Vector3d& v) { return composeMotion(v, u); }, x, 1e-6, {2});
	const Eigen::MatrixXd Gn = codemark::test::numericJacobian(
		[&](const Eigen::Vector3d& v) { return composeMotion(x, v); }, u, 1e-6, {2});
	EXPECT_LT((F - Fn).cwiseAbs().maxCoeff(), 1e-6);
	EXPECT_LT((G - Gn).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(EkfModel, CovarianceCheckSymmetrisesAndRejects)
{
	Eigen::Matrix3d P;
	P << 1, 0.1, 0, 0.1 + 1e-9, 2, 0, 0, 0, 3;
	symmetriseAndCheckCovariance(P, 1e-9, 1e-12, "t");
	EXPECT_EQ(P(0, 1), P(1, 0));
	Eigen::Matrix3d bad = Eigen::Vector3d(1, -0.1, 1).asDiagonal();
	EXPECT_THROW(symmetriseAndCheckCovariance(bad, 1e-9, 1e-12, "t"), std::runtime_error);
	Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
	nan(1, 1) = std::nan("");
	EXPECT_THROW(symmetriseAndCheckCovariance(nan, 1e-9, 1e-12, "t"), std::runtime_error);
}

TEST_P(BothVariants, PerfectMeasurementsConvergeToTheTruePose)
{
	const LandmarkMap map = roomMap();
	const CPose2D truth(4.5, 2.0, 0.1);
	auto f =
		makeEkfLocalizer(GetParam(), EkfOptions(), map, guess(CPose2D(4.3, 2.2, 0.05), 0.3, 0.2));
	const auto cam = cameraOnRobot();
	for (int k = 0; k < 20; ++k)
	{
		const auto st = f->step(
			nullptr, frameOf(
						 {sighting(truth, cam, map.landmarks[0], kSigma),
						  sighting(truth, cam, map.landmarks[1], kSigma)}));
		EXPECT_EQ(st.used, 2);
		EXPECT_EQ(st.rejected, 0);
	}
	const auto e = f->estimate();
	EXPECT_NEAR(e.mean.x(), truth.x(), 1e-3);
	EXPECT_NEAR(e.mean.y(), truth.y(), 1e-3);
	EXPECT_NEAR(e.mean.phi(), truth.phi(), 1e-3);
	EXPECT_TRUE(isSpd(e.cov));
	EXPECT_LT(e.cov.trace(), 1e-3);
}

TEST_P(BothVariants, GlobalInitialisationFromOneLandmark)
{
	const LandmarkMap map = roomMap();
	const CPose2D truth(1.5, 3.1, -2.9);
	auto f = makeEkfLocalizer(GetParam(), EkfOptions(), map);
	EXPECT_FALSE(f->estimate().initialized);
	// Odometry before any sighting is ignored; an unknown ID does not initialise.
	const auto odo = odometry(CPose2D(0.1, 0, 0), 0.01, 0.01);
	const auto cam = cameraOnRobot();
	auto st = f->step(&odo, frameOf({sighting(truth, cam, map.landmarks[2], kSigma, nullptr, 99)}));
	EXPECT_EQ(st.unknown_id, 1);
	EXPECT_FALSE(f->estimate().initialized);
	st = f->step(&odo, frameOf({sighting(truth, cam, map.landmarks[2], kSigma)}));
	EXPECT_TRUE(st.reinitialized);
	EXPECT_EQ(st.used, 1);
	const auto e = f->estimate();
	ASSERT_TRUE(e.initialized);
	EXPECT_NEAR(e.mean.x(), truth.x(), 1e-9);
	EXPECT_NEAR(e.mean.y(), truth.y(), 1e-9);
	EXPECT_NEAR(mrpt::math::wrapToPi(e.mean.phi() - truth.phi()), 0, 1e-9);
	// The covariance is the fix's: C_R propagated into the world.
	const auto s = sighting(truth, cam, map.landmarks[2], kSigma);
	Eigen::Matrix3d C;
	pose::robotPoseInWorld(
		s.pose_in_landmark, s.C_R, pose::landmarkPlanarPose(map.landmarks[2].world_T_landmark()),
		pose::cameraPlanarPose(cam), &C);
	EXPECT_LT((e.cov - C).cwiseAbs().maxCoeff(), 1e-12);
}

// The first fix waits for a tight estimate: a far landmark's single pose fix
// is wide along its arc, so the filter runs from it while estimate() reports
// no fix until the position and yaw standard deviations are under
// converged_std_*; the fix then stays, however the covariance grows.
TEST_P(BothVariants, FirstFixWaitsForATightEstimate)
{
	const LandmarkMap map = roomMap();
	const CPose2D truth(1.5, 3.1, 0.05);  // 4.5 m from landmark 2
	const auto cam = cameraOnRobot();
	const Eigen::Vector3d wide(0.01, 0.002, 0.1);
	const auto std_xy = [](const PoseEstimate& e)
	{
		return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(e.cov.topLeftCorner<2, 2>())
							 .eigenvalues()
							 .maxCoeff());
	};
	EkfOptions o;
	auto f = makeEkfLocalizer(GetParam(), o, map);
	std::mt19937 rng(3);
	auto st = f->step(nullptr, frameOf({sighting(truth, cam, map.landmarks[1], wide, &rng)}));
	EXPECT_TRUE(st.reinitialized);
	ASSERT_FALSE(f->estimate().initialized);
	ASSERT_GT(std_xy(f->estimate()), o.converged_std_xy_m) << "the test needs a wide first fix";
	int fixed_at = -1;
	for (int k = 1; k < 40 && fixed_at < 0; ++k)
	{
		f->step(nullptr, frameOf({sighting(truth, cam, map.landmarks[1], wide, &rng)}));
		const auto e = f->estimate();
		const bool tight = std_xy(e) < o.converged_std_xy_m &&
						   std::sqrt(e.cov(2, 2)) < o.converged_std_yaw_deg * M_PI / 180;
		EXPECT_EQ(e.initialized, tight) << "step " << k;
		if (e.initialized) fixed_at = k;
	}
	ASSERT_GT(fixed_at, 1);
	// Sticky: odometry without sightings widens the covariance past the
	// thresholds; the estimate stays a fix.
	const auto odo = odometry(CPose2D(0.1, 0, 0), 0.2, 0.2);
	for (int k = 0; k < 5; ++k) f->step(&odo, mrpt::obs::CSensoryFrame());
	EXPECT_GT(std_xy(f->estimate()), o.converged_std_xy_m);
	EXPECT_TRUE(f->estimate().initialized);

	// Wide thresholds: the first sighting is the fix.
	o.converged_std_xy_m = 10;
	o.converged_std_yaw_deg = 180;
	auto g = makeEkfLocalizer(GetParam(), o, map);
	g->step(nullptr, frameOf({sighting(truth, cam, map.landmarks[1], wide)}));
	EXPECT_TRUE(g->estimate().initialized);
	// A known initial pose is a fix from the start.
	auto h = makeEkfLocalizer(GetParam(), EkfOptions(), map, guess(truth, 0.5, 0.5));
	EXPECT_TRUE(h->estimate().initialized);
	o.converged_std_xy_m = 0;
	EXPECT_THROW(o.validate(), std::invalid_argument);
}

TEST_P(BothVariants, AngleWrapAcrossPi)
{
	// Robot heading pi - 0.01, facing landmark 3 on the wall x = 0.
	const LandmarkMap map = roomMap();
	const CPose2D truth(3.0, 1.0, M_PI - 0.01);
	// Prior on the other side of the cut: -pi + 0.01 (0.02 rad away).
	auto f = makeEkfLocalizer(
		GetParam(), EkfOptions(), map, guess(CPose2D(3.0, 1.0, -M_PI + 0.01), 0.05, 0.05));
	const auto cam = cameraOnRobot();
	for (int k = 0; k < 5; ++k)
	{
		const auto st = f->step(nullptr, frameOf({sighting(truth, cam, map.landmarks[2], kSigma)}));
		EXPECT_EQ(st.used, 1) << "step " << k;
		const double err = mrpt::math::wrapToPi(f->estimate().mean.phi() - truth.phi());
		EXPECT_LT(std::abs(err), 0.021) << "step " << k;
	}
	EXPECT_NEAR(mrpt::math::wrapToPi(f->estimate().mean.phi() - truth.phi()), 0, 1e-3);
	EXPECT_LE(std::abs(f->estimate().mean.phi()), M_PI);
}

TEST_P(BothVariants, GateRejectsAPlantedWrongIdSighting)
{
	const LandmarkMap map = roomMap();
	const CPose2D truth(4.5, 2.0, 0.0);
	auto f = makeEkfLocalizer(GetParam(), EkfOptions(), map, guess(truth, 0.02, 0.01));
	const auto cam = cameraOnRobot();
	// Landmark 1 seen, but reported with landmark 2's ID (2 m away).
	const auto st = f->step(
		nullptr, frameOf(
					 {sighting(truth, cam, map.landmarks[0], kSigma),
					  sighting(truth, cam, map.landmarks[0], kSigma, nullptr, 2)}));
	EXPECT_EQ(st.used, 1);
	EXPECT_EQ(st.rejected, 1);
	EXPECT_FALSE(st.reinitialized);
	EXPECT_NEAR(f->estimate().mean.x(), truth.x(), 1e-3);
	EXPECT_NEAR(f->estimate().mean.y(), truth.y(), 1e-3);
}

TEST_P(BothVariants, KidnappedRobotRecovers)
{
	const LandmarkMap map = roomMap();
	EkfOptions o;
	o.kidnap_rejections = 3;
	const CPose2D a(4.5, 2.0, 0.0), b(1.5, 2.0, M_PI);
	auto f = makeEkfLocalizer(GetParam(), o, map, guess(a, 0.02, 0.01));
	const auto cam = cameraOnRobot();
	std::mt19937 rng(3);
	const auto still = odometry(CPose2D(0, 0, 0), 0.002, 0.002);
	for (int k = 0; k < 5; ++k)
		f->step(&still, frameOf({sighting(a, cam, map.landmarks[0], kSigma, &rng)}));
	EXPECT_NEAR(f->estimate().mean.x(), a.x(), 0.01);
	// Teleported to b (facing landmarks 3 and 4): rejected until K, then re-initialised.
	int rejected = 0;
	bool reinit = false;
	for (int k = 0; k < 10 && !reinit; ++k)
	{
		const auto st =
			f->step(&still, frameOf({sighting(b, cam, map.landmarks[2], kSigma, &rng)}));
		rejected += st.rejected;
		reinit = st.reinitialized;
	}
	EXPECT_TRUE(reinit);
	EXPECT_EQ(rejected, o.kidnap_rejections);
	for (int k = 0; k < 10; ++k)
	{
		const auto st = f->step(
			&still, frameOf(
						{sighting(b, cam, map.landmarks[2], kSigma, &rng),
						 sighting(b, cam, map.landmarks[3], kSigma, &rng)}));
		EXPECT_EQ(st.rejected, 0);
	}
	EXPECT_NEAR(f->estimate().mean.x(), b.x(), 0.01);
	EXPECT_NEAR(f->estimate().mean.y(), b.y(), 0.01);
	EXPECT_NEAR(mrpt::math::wrapToPi(f->estimate().mean.phi() - b.phi()), 0, 0.01);
}

TEST_P(BothVariants, CovarianceStaysSymmetricPositiveDefiniteOver10kRandomSteps)
{
	const LandmarkMap map = roomMap();
	auto f = makeEkfLocalizer(GetParam(), EkfOptions(), map, guess(CPose2D(3, 2, 0), 0.1, 0.1));
	std::mt19937 rng(11);
	std::uniform_real_distribution<double> u(-1.0, 1.0);
	std::uniform_int_distribution<int> pick(0, static_cast<int>(map.landmarks.size()) - 1);
	const auto cam = cameraOnRobot();
	int used = 0;
	for (int k = 0; k < 10000; ++k)
	{
		// Random motion with a random (sometimes tiny, sometimes huge) noise,
		// sightings from a random nearby pose with a random noise level.
		const auto odo = odometry(
			CPose2D(0.1 * u(rng), 0.05 * u(rng), 0.3 * u(rng)),
			std::pow(10.0, -4 + 3 * (u(rng) + 1) / 2), std::pow(10.0, -4 + 3 * (u(rng) + 1) / 2));
		const CPose2D where(3 + 2 * u(rng), 2 + 1.5 * u(rng), M_PI * u(rng));
		const Eigen::Vector3d sigma = kSigma * std::pow(10.0, 2 * u(rng));
		std::vector<CObservationCodedLandmarks::TSighting> s;
		const int n = static_cast<int>((u(rng) + 1) * 1.5);
		for (int i = 0; i < n; ++i)
			s.push_back(sighting(where, cam, map.landmarks[pick(rng)], sigma, &rng));
		StepStats st;
		ASSERT_NO_THROW(st = f->step(&odo, frameOf(s))) << "step " << k;
		used += st.used;
		const auto e = f->estimate();
		ASSERT_TRUE(isSpd(e.cov)) << "step " << k << "\n" << e.cov;
		ASSERT_LE(std::abs(e.mean.phi()), M_PI + 1e-12);
	}
	EXPECT_GT(used, 100);  // the updates did run
}

INSTANTIATE_TEST_SUITE_P(
	Ekf, BothVariants, ::testing::Values(EkfMeasurement::Landmark, EkfMeasurement::PoseFix),
	[](const auto& info) { return info.param == EkfMeasurement::Landmark ? "ekf" : "ekf_pose"; });

TEST(EkfFactory, MakeLocalizerSelectsTheVariant)
{
	mrpt::config::CConfigFileMemory cfg;
	EXPECT_EQ(makeLocalizer("ekf", cfg, roomMap())->method(), "ekf");
	EXPECT_EQ(makeLocalizer("ekf-pose", cfg, roomMap())->method(), "ekf-pose");
	EXPECT_THROW(makeLocalizer("nope", cfg, roomMap()), std::invalid_argument);
	cfg.write("ekf", "gate_probability", 1.5, -1, -1);
	EXPECT_THROW(makeLocalizer("ekf", cfg, roomMap()), std::invalid_argument);
}

// A wide prior (10 cm, 3 deg) and one precise sighting (phi1 good to 1e-4
// rad, as the detector gives): the second-order terms of h over the update
// exceed phi1's sigma, so one linearisation is overconfident. The iterated
// update must be consistent: Monte Carlo mean NEES of the posterior about 3.
TEST(Ekf, IteratedUpdateIsConsistentFromAWidePrior)
{
	const LandmarkMap map = roomMap();
	const auto cam = cameraOnRobot();
	const Eigen::Vector3d sigma(0.01, 1e-4, 0.05);
	std::mt19937 rng(21);
	std::normal_distribution<double> n(0.0, 1.0);
	std::vector<double> mean_nees;
	for (const int iterations : {1, 10})
	{
		EkfOptions o;
		o.iterations = iterations;
		double sum = 0;
		const int runs = 300;
		for (int run = 0; run < runs; ++run)
		{
			const CPose2D truth(3.0, 1.0, 0.0);	 // landmark 1 (6, 1) straight ahead, 2.9 m
			// The prior's mean is drawn from the prior around the truth.
			const CPose2D prior(
				truth.x() + 0.1 * n(rng), truth.y() + 0.1 * n(rng), truth.phi() + 0.05 * n(rng));
			auto f = makeEkfLocalizer(EkfMeasurement::Landmark, o, map, guess(prior, 0.1, 0.05));
			const auto st =
				f->step(nullptr, frameOf({sighting(truth, cam, map.landmarks[0], sigma, &rng)}));
			ASSERT_EQ(st.used, 1);
			const auto e = f->estimate();
			const Eigen::Vector3d err(
				e.mean.x() - truth.x(), e.mean.y() - truth.y(),
				mrpt::math::wrapToPi(e.mean.phi() - truth.phi()));
			sum += err.dot(e.cov.ldlt().solve(err));
		}
		mean_nees.push_back(sum / runs);
	}
	std::cout << "mean NEES: plain EKF " << mean_nees[0] << ", iterated " << mean_nees[1] << "\n";
	// 900 DoF: a consistent filter's mean is in [2.6, 3.4] with 99.9%
	// probability; the posterior is still a little non-Gaussian (its
	// covariance is the linearisation at the MAP), measured 3.7: allow 4.
	// The plain EKF measured about 100.
	EXPECT_GT(mean_nees[1], 2.6);
	EXPECT_LT(mean_nees[1], 4.0);
	EXPECT_GT(mean_nees[0], 5 * mean_nees[1])
		<< "the plain EKF should be clearly overconfident here";
}

// A map with no landmarks cannot localise anything: a clear error at
// construction rather than a run that silently never fixes.
TEST(EkfFactory, EmptyMapIsAnError)
{
	for (const auto kind : {EkfMeasurement::Landmark, EkfMeasurement::PoseFix})
	{
		try
		{
			makeEkfLocalizer(kind, EkfOptions(), LandmarkMap{});
			FAIL() << "an empty map must throw";
		}
		catch (const std::invalid_argument& e)
		{
			EXPECT_NE(std::string(e.what()).find("map is empty"), std::string::npos) << e.what();
		}
	}
}
