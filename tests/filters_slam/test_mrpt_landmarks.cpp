// MRPT landmark ground-truth files (x y z type 0 0 id).
#include <codemark/filters/mrpt_landmarks.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>

using namespace codemark;
using namespace codemark::filters;

namespace
{
// The line number a parse of \a text fails at (0: no failure).
int failingLine(const std::string& text)
{
	std::istringstream in(text);
	try
	{
		parseMrptLandmarks(in, "x.txt");
	}
	catch (const MapFileError& e)
	{
		EXPECT_EQ(e.file(), "x.txt");
		EXPECT_NE(
			std::string(e.what()).find("x.txt:" + std::to_string(e.line())), std::string::npos);
		return e.line();
	}
	return 0;
}
}  // namespace

TEST(MrptLandmarks, ParsesRowsCommentsAndBlankLines)
{
	std::istringstream in(
		"% header\n"
		"  0.578229   7.694330   0.000000    5    0   0.000000 1 \n"
		"\n"
		"# another comment\n"
		" -7.0  0.5  1.25  5 0 0 42  % trailing\n");
	const LandmarkMap m = parseMrptLandmarks(in, "t");
	ASSERT_EQ(m.landmarks.size(), 2u);
	EXPECT_EQ(m.landmarks[0].id, 1);
	EXPECT_DOUBLE_EQ(m.landmarks[0].x_m, 0.578229);
	EXPECT_DOUBLE_EQ(m.landmarks[0].y_m, 7.694330);
	EXPECT_EQ(m.landmarks[1].id, 42);
	EXPECT_DOUBLE_EQ(m.landmarks[1].x_m, -7.0);
	EXPECT_DOUBLE_EQ(m.landmarks[1].z_m, 1.25);
	EXPECT_DOUBLE_EQ(m.landmarks[1].yaw_rad, 0.0);
	EXPECT_DOUBLE_EQ(m.landmarks[1].scale, 1.0);
}

TEST(MrptLandmarks, BadLinesAreNamed)
{
	EXPECT_EQ(failingLine("1 2 0 5 0 0 1\n1 2 0 5 0 1\n"), 2);	// 6 columns
	EXPECT_EQ(failingLine("1 2 0 5 0 0 1 7\n"), 1);	 // 8 columns
	EXPECT_EQ(failingLine("% c\n1 abc 0 5 0 0 1\n"), 2);  // not a number
	EXPECT_EQ(failingLine("1 2 0 5 0 0 1.5\n"), 1);	 // non-integer ID
	EXPECT_EQ(failingLine("1 2 0 5 0 0 -3\n"), 1);	// negative ID
	EXPECT_EQ(failingLine("1 2 0 5 0 0 3\n\n4 5 0 5 0 0 3\n"), 3);	// duplicate
	EXPECT_EQ(failingLine("1 nan 0 5 0 0 3\n"), 1);	 // not finite
	EXPECT_EQ(failingLine("1 2 0 5 0 0 3\n"), 0);
}

TEST(MrptLandmarks, FilesAndDetection)
{
	EXPECT_THROW(loadMrptLandmarksFile("/nonexistent/gt.txt"), std::runtime_error);
	EXPECT_FALSE(isMrptLandmarksFile("/nonexistent/gt.txt"));
	const std::string path = ::testing::TempDir() + "codemark_mrpt_lm.txt";
	{
		std::ofstream f(path);
		f << "% x y z type 0 0 id\n 1 2 0 5 0 0.0 7\n 3 4 0 5 0 0.0 8\n";
	}
	EXPECT_TRUE(isMrptLandmarksFile(path));
	const LandmarkMap m = loadMrptLandmarksFile(path);
	ASSERT_EQ(m.landmarks.size(), 2u);
	EXPECT_NE(m.find(8), nullptr);
	{
		std::ofstream f(path);
		f << "# id x y z yaw\n17 4.0 1.5 0.3 180\n";
	}
	EXPECT_FALSE(isMrptLandmarksFile(path));
	std::remove(path.c_str());
}

TEST(MrptLandmarks, KfSlamDemoGroundTruth)
{
	const std::string path = "/usr/share/mrpt/datasets/kf-slam_demo_ground_truth.txt";
	if (!std::ifstream(path)) GTEST_SKIP() << "mrpt-common datasets not installed";
	const LandmarkMap m = loadMrptLandmarksFile(path);
	EXPECT_EQ(m.landmarks.size(), 70u);
	ASSERT_NE(m.find(1), nullptr);
	EXPECT_NEAR(m.find(1)->x_m, 0.578229, 1e-9);
}
