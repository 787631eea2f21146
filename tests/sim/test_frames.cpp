#include <codemark/sim/frames.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

using namespace codemark;
using namespace codemark::sim;

namespace
{
LandmarkMap exampleMap()
{
	LandmarkMap m;
	const double rows[][5] = {{17, 6, 1.5, 0.6, 180}, {37, 3, 4, 0.6, -90}, {41, 0, 2, 0.3, 0}};
	for (const auto& r : rows)
	{
		MapLandmark lm;
		lm.id = int(r[0]);
		lm.x_m = r[1];
		lm.y_m = r[2];
		lm.z_m = r[3];
		lm.yaw_rad = r[4] * M_PI / 180;
		m.landmarks.push_back(lm);
	}
	return m;
}

std::string writeTemp(const std::string& name, const std::string& text)
{
	const std::string path = ::testing::TempDir() + name;
	std::ofstream(path) << text;
	return path;
}
}  // namespace

TEST(Frames, ViewpointsLookAtTheLandmarksWithinTheRanges)
{
	const LandmarkMap map = exampleMap();
	ViewpointOptions vp;
	const auto poses = viewpointsAroundLandmarks(map, 30, 5, vp);
	ASSERT_EQ(poses.size(), 30u);
	Scene scene;
	scene.map = map;
	for (size_t i = 0; i < poses.size(); ++i)
	{
		scene.world_T_camera = poses[i];
		EXPECT_NEAR(poses[i].z(), vp.camera_height_m, 1e-12);
		const auto truth = groundTruth(scene);
		const LandmarkTruth& t = truth[i % map.landmarks.size()];
		EXPECT_GE(t.sighting.L[0], vp.min_distance_m - 1e-9);
		EXPECT_LE(t.sighting.L[0], vp.max_distance_m + 1e-9);
		EXPECT_LE(std::abs(t.sighting.L[1]), vp.max_bearing_rad + 1e-9);
		EXPECT_LE(std::abs(t.sighting.L[1] + t.sighting.L[2]), vp.max_view_angle_rad + 1e-9);
		EXPECT_TRUE(isInView(t, scene.camera)) << "frame " << i;
	}
	// Deterministic for the seed, different for another.
	EXPECT_EQ(viewpointsAroundLandmarks(map, 3, 5, vp)[2], poses[2]);
	EXPECT_NE(viewpointsAroundLandmarks(map, 3, 6, vp)[2], poses[2]);
	EXPECT_THROW(viewpointsAroundLandmarks(LandmarkMap(), 3, 5, vp), std::invalid_argument);
}

TEST(Frames, BodyAndOpticalFrames)
{
	const mrpt::poses::CPose3D body(1, 2, 0.5, 0.3, 0.1, -0.2);
	const auto optical = opticalFromBody(body);
	// The optical axis (z) is the body's forward axis (x).
	const auto Rb = body.getRotationMatrix(), Ro = optical.getRotationMatrix();
	for (int r = 0; r < 3; ++r) EXPECT_NEAR(Ro(r, 2), Rb(r, 0), 1e-12);
	const auto back = bodyFromOptical(optical);
	EXPECT_NEAR((back.asVectorVal() - body.asVectorVal()).norm(), 0.0, 1e-12);
}

TEST(Frames, CameraPosesFile)
{
	const auto poses = loadCameraPoses(writeTemp(
		"poses_ok.txt", "# x y z yaw pitch roll\n1 2 0.6 90 0 0\n\n3 4 0.5 -45 0 0 # c\n"));
	ASSERT_EQ(poses.size(), 2u);
	const auto body = bodyFromOptical(poses[0]);
	EXPECT_NEAR(body.x(), 1, 1e-12);
	EXPECT_NEAR(body.yaw(), M_PI / 2, 1e-12);
	const std::pair<const char*, const char*> bad[] = {
		{"1 2 3 4 5\n", ":1:"},
		{"1 2 3 4 5 6\n1 2 x 4 5 6\n", ":2:"},
		{"1 2 3 nan 5 6\n", ":1:"},
		{"# empty\n", "no camera poses"}};
	for (const auto& [text, expect] : bad)
	{
		try
		{
			loadCameraPoses(writeTemp("poses_bad.txt", text));
			ADD_FAILURE() << "no error for '" << text << "'";
		}
		catch (const std::runtime_error& e)
		{
			EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
		}
	}
	EXPECT_THROW(loadCameraPoses("/nonexistent/poses.txt"), std::runtime_error);
}

TEST(Frames, TruthJsonListsTheLandmarksInView)
{
	const LandmarkMap map = exampleMap();
	Scene scene;
	scene.map = map;
	scene.world_T_camera = levelCameraLookingAt(map.landmarks[0], 2.0, 0.2);
	const auto truth = groundTruth(scene);
	const std::string j = frameTruthJson("a \"b\".png", scene.world_T_camera, truth, scene.camera);
	EXPECT_EQ(j.find("{\"image\": \"a \\\"b\\\".png\""), 0u) << j;
	EXPECT_NE(j.find("\"id\": 17"), std::string::npos);
	EXPECT_EQ(j.find("\"id\": 37"), std::string::npos);	 // behind the camera
	int in_view = 0;
	for (const auto& t : truth) in_view += isInView(t, scene.camera);
	size_t n = 0;
	for (size_t p = j.find("\"corners\""); p != std::string::npos; p = j.find("\"corners\"", p + 1))
		++n;
	EXPECT_EQ(int(n), in_view);
	EXPECT_EQ(std::count(j.begin(), j.end(), '{'), std::count(j.begin(), j.end(), '}'));
	EXPECT_EQ(std::count(j.begin(), j.end(), '['), std::count(j.begin(), j.end(), ']'));
}
