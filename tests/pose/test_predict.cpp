// Prediction before imaging: visibility flags on crafted cases, consistency
// with measure(), the posterior and the ranking.
#include <codemark/landmark/truth.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pose/predict.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "common.h"

using namespace codemark;
using namespace codemark::pose;
using mrpt::poses::CPose2D;
using mrpt::poses::CPose3D;

namespace
{
// A level forward camera 0.1 m ahead of the robot centre at 0.5 m height.
const CPose3D kRobotTCamera(0.1, 0.0, 0.5, -M_PI / 2, 0, -M_PI / 2);

// A wall landmark at the origin facing +x, centre at camera height.
MapLandmark wallLandmark(int id = 7, double x = 0, double y = 0, double yaw = 0, double scale = 1)
{
	MapLandmark lm;
	lm.id = id;
	lm.x_m = x;
	lm.y_m = y;
	lm.z_m = 0.5;
	lm.yaw_rad = yaw;
	lm.scale = scale;
	return lm;
}

// The robot pose whose camera sits at distance d on the landmark's normal
// rotated by view_angle, looking at the landmark centre turned by turn.
CPose2D robotFacing(const MapLandmark& lm, double d, double view_angle, double turn = 0)
{
	const double a = lm.yaw_rad + view_angle;
	const CPose2D world_T_camera(
		lm.x_m + d * std::cos(a), lm.y_m + d * std::sin(a), a + M_PI + turn);
	return world_T_camera + (CPose2D() - cameraPlanarPose(kRobotTCamera));
}

const Eigen::Matrix3d kPrior = Eigen::Vector3d(0.2 * 0.2, 0.2 * 0.2, 0.1 * 0.1).asDiagonal();
}  // namespace

TEST(Predict, VisibleInFrontAndConsistentWithMeasure)
{
	const CameraModel cam;
	const MapLandmark lm = wallLandmark();
	const Prediction p = predictSighting(robotFacing(lm, 1.5, 0.3), kPrior, kRobotTCamera, cam, lm);
	EXPECT_TRUE(p.visible());
	EXPECT_NEAR(p.view_angle_rad, 0.3, 1e-9);
	EXPECT_EQ(p.id, 7);
	// The predicted L is the geometric truth and measure() on the predicted
	// corners gives the same measurement.
	const CPose3D landmark_T_camera =
		worldTCamera(robotFacing(lm, 1.5, 0.3), kRobotTCamera) - lm.world_T_landmark();
	const SightingTruth t = sightingTruth(landmark_T_camera);
	EXPECT_LT((p.measurement.L - t.L).norm(), 1e-9);
	const Measurement m = measure(p.corners_px, cam, lm.geometry());
	EXPECT_LT((m.C_L - p.measurement.C_L).norm(), 1e-12 * m.C_L.norm());
	EXPECT_LT((m.C_R - p.measurement.C_R).norm(), 1e-12 * m.C_R.norm());
	// The fix shrinks the prior: posterior <= prior and <= the fix alone.
	const Eigen::Matrix3d post = p.posterior;
	EXPECT_GT(
		Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(kPrior - post).eigenvalues().minCoeff(),
		-1e-15);
	EXPECT_GT(
		Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(p.C_fix_world - post)
			.eigenvalues()
			.minCoeff(),
		-1e-15);
	EXPECT_NEAR(p.score, post(0, 0) + post(1, 1), 1e-18);
}

TEST(Predict, VisibilityFlagsOnCraftedCases)
{
	const CameraModel cam;
	const MapLandmark lm = wallLandmark();
	// Behind the camera: the robot looks away from the landmark.
	Prediction p = predictSighting(robotFacing(lm, 2.0, 0.0, M_PI), kPrior, kRobotTCamera, cam, lm);
	EXPECT_FALSE(p.in_front);
	EXPECT_FALSE(p.visible());
	// Out of the field of view: turned 30 deg (the half FOV is 21.8 deg).
	p = predictSighting(robotFacing(lm, 2.0, 0.0, 0.52), kPrior, kRobotTCamera, cam, lm);
	EXPECT_TRUE(p.in_front);
	EXPECT_FALSE(p.in_fov);
	EXPECT_FALSE(p.visible());
	// Partly out: turned so the landmark sits at the image border.
	p = predictSighting(robotFacing(lm, 2.0, 0.0, 0.37), kPrior, kRobotTCamera, cam, lm);
	EXPECT_FALSE(p.in_fov);
	// Too small: 6 m away the 160 mm square is 21 px tall (< 30 px).
	VisibilityOptions vis;
	vis.max_range_m = 10;
	p = predictSighting(
		robotFacing(lm, 6.0, 0.0), kPrior, kRobotTCamera, cam, lm, PoseOptions(), vis);
	EXPECT_TRUE(p.in_fov);
	EXPECT_TRUE(p.in_range);
	EXPECT_FALSE(p.big_enough);
	EXPECT_NEAR(p.size_px, 800 * 0.16 / 6.0, 0.1);
	EXPECT_FALSE(p.visible());
	// ... but a scale-2 landmark at the same place is big enough.
	const MapLandmark big = wallLandmark(8, 0, 0, 0, 2.0);
	p = predictSighting(
		robotFacing(big, 6.0, 0.0), kPrior, kRobotTCamera, cam, big, PoseOptions(), vis);
	EXPECT_TRUE(p.visible());
	// Out of range with the default 6 m limit.
	p = predictSighting(robotFacing(big, 6.5, 0.0), kPrior, kRobotTCamera, cam, big);
	EXPECT_FALSE(p.in_range);
	EXPECT_FALSE(p.visible());
	// The back side: the camera behind the wall looking at the landmark's back.
	p = predictSighting(robotFacing(lm, 2.0, M_PI), kPrior, kRobotTCamera, cam, lm);
	EXPECT_TRUE(p.in_front);
	EXPECT_FALSE(p.facing);
	EXPECT_FALSE(p.visible());
	// Beyond the angle limit: 75 deg from the normal.
	p = predictSighting(robotFacing(lm, 1.5, 75 * M_PI / 180), kPrior, kRobotTCamera, cam, lm);
	EXPECT_TRUE(p.facing);
	EXPECT_FALSE(p.angle_ok);
	EXPECT_FALSE(p.visible());
	p = predictSighting(robotFacing(lm, 1.5, -65 * M_PI / 180), kPrior, kRobotTCamera, cam, lm);
	EXPECT_TRUE(p.angle_ok);
}

TEST(Predict, RankingPrefersTheInformativeLandmark)
{
	const CameraModel cam;
	// Robot at the origin looking along +x; landmarks on a wall at x = 2..4
	// facing -x, and one behind the robot.
	LandmarkMap map;
	map.landmarks.push_back(wallLandmark(1, 4.0, 0.10, M_PI));	// far
	map.landmarks.push_back(wallLandmark(2, 1.6, -0.15, M_PI));	 // near: best
	map.landmarks.push_back(wallLandmark(3, 2.5, 0.20, M_PI));	// middle
	map.landmarks.push_back(wallLandmark(4, -2.0, 0.0, 0.0));  // behind the robot
	map.landmarks.push_back(wallLandmark(5, 2.0, 0.0, 0.0));  // back side towards the robot
	const CPose2D robot(0, 0, 0);
	const auto ranked = rankLandmarks(robot, kPrior, kRobotTCamera, cam, map);
	ASSERT_EQ(ranked.size(), 3u);
	EXPECT_EQ(ranked[0].id, 2);
	EXPECT_EQ(ranked[1].id, 3);
	EXPECT_EQ(ranked[2].id, 1);
	EXPECT_LT(ranked[0].score, ranked[1].score);
	EXPECT_LT(ranked[1].score, ranked[2].score);
	for (const auto& p : ranked) EXPECT_TRUE(p.visible());
}

TEST(Predict, FuseCovarianceIsTheKalmanUpdate)
{
	const Eigen::Matrix3d prior = kPrior;
	Eigen::Matrix3d fix;
	fix << 0.01, 0.002, 0.001, 0.002, 0.02, 0.0, 0.001, 0.0, 0.005;
	const Eigen::Matrix3d post = fuseCovariance(prior, fix);
	// Information form: post^-1 = prior^-1 + fix^-1.
	const Eigen::Matrix3d info = prior.inverse() + fix.inverse();
	EXPECT_LT((post - info.inverse()).norm(), 1e-12);
	EXPECT_LT((post - post.transpose()).norm(), 1e-18);
}
