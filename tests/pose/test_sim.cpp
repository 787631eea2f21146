// The pose library on the project's renderer: the truth corners of noise-free
// renders (sim::render + sim::levelCameraLookingAt) give L and the pose; no
// detector involved.
#include <codemark/landmark/truth.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pose/measurement.h>
#include <codemark/sim/render.h>
#include <gtest/gtest.h>

using namespace codemark;
using namespace codemark::pose;

TEST(PoseOnRenders, TruthCornersGiveLAndPose)
{
	sim::Scene scene;
	MapLandmark lm;
	lm.id = 37;
	lm.x_m = 3.0;
	lm.y_m = 1.0;
	lm.z_m = 0.6;
	lm.yaw_rad = M_PI;	// facing -x
	scene.map.landmarks.push_back(lm);
	scene.camera = CameraModel();
	const sim::RenderOptions ro;
	int n = 0;
	for (const double d : {0.7, 1.5, 2.5, 4.0})
		for (const double deg : {-50.0, -20.0, 0.0, 30.0, 60.0})
			for (const double height : {0.0, 0.2})
			{
				const double bearing = 0.05;
				scene.world_T_camera =
					sim::levelCameraLookingAt(lm, d, deg * M_PI / 180, height, bearing);
				const sim::Render r = sim::render(scene, ro, 1);
				ASSERT_EQ(r.truth.size(), 1u);
				const sim::LandmarkTruth& t = r.truth[0];
				if (!t.fully_visible) continue;
				++n;
				// The renderer's conventions agree with the spec's L.
				EXPECT_NEAR(t.sighting.L[0], d, 1e-9);
				EXPECT_NEAR(t.sighting.L[1], bearing, 1e-9);
				EXPECT_NEAR(t.sighting.L[2], deg * M_PI / 180 - bearing, 1e-9);
				for (const PoseMethod method : {PoseMethod::ClosedForm, PoseMethod::General6Dof})
				{
					PoseOptions opt;
					opt.method = method;
					const Measurement m = measure(t.corners_px, scene.camera, lm.geometry(), opt);
					EXPECT_NEAR(m.L[0], t.sighting.L[0], 1e-6 * d) << toString(method);
					EXPECT_NEAR(m.L[1], t.sighting.L[1], 1e-6);
					EXPECT_NEAR(m.L[2], t.sighting.L[2], 1e-6);
					EXPECT_NEAR(m.pose_in_landmark[0], t.sighting.pose_in_landmark[0], 1e-6 * d);
					EXPECT_NEAR(m.pose_in_landmark[1], t.sighting.pose_in_landmark[1], 1e-6 * d);
					EXPECT_NEAR(
						wrapToPi(m.pose_in_landmark[2] - t.sighting.pose_in_landmark[2]), 0, 1e-6);
					EXPECT_LT((m.P - t.P).norm(), 1e-6);
					// And the robot (here: the camera) in the world.
					const auto w = robotPoseInWorld(
						m.pose_in_landmark, m.C_R, landmarkPlanarPose(lm.world_T_landmark()),
						mrpt::poses::CPose2D());
					const mrpt::poses::CPose2D truth_w = cameraPlanarPose(scene.world_T_camera);
					EXPECT_NEAR(w.x(), truth_w.x(), 1e-6 * d);
					EXPECT_NEAR(w.y(), truth_w.y(), 1e-6 * d);
					EXPECT_NEAR(wrapToPi(w.phi() - truth_w.phi()), 0, 1e-6);
				}
			}
	EXPECT_GE(n, 25);
}
