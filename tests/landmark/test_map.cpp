#include <codemark/landmark/map.h>
#include <gtest/gtest.h>

#include <sstream>

using namespace codemark;

namespace
{
LandmarkMap parseText(const std::string& text)
{
	std::istringstream in(text);
	return LandmarkMap::parse(in, "test.txt");
}

// The error for \a text must be a MapFileError on \a line whose message
// names the file, the line and contains \a fragment.
void expectError(const std::string& text, int line, const std::string& fragment)
{
	try
	{
		parseText(text);
		FAIL() << "no error for:\n" << text;
	}
	catch (const MapFileError& e)
	{
		EXPECT_EQ(e.line(), line) << e.what();
		const std::string msg = e.what();
		EXPECT_NE(msg.find("test.txt:" + std::to_string(line) + ":"), std::string::npos) << msg;
		EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
	}
}
}  // namespace

TEST(Map, ParsesSpecExample)
{
	const auto m = parseText(
		"# id  x[m]  y[m]  z[m]  yaw[deg]  [scale]\n"
		"17    4.00  1.50  0.30  180\n"
		"\n"
		"18    0.00  2.00  0.60  0         1.5   # a comment\n");
	ASSERT_EQ(m.landmarks.size(), 2u);
	EXPECT_EQ(m.landmarks[0].id, 17);
	EXPECT_DOUBLE_EQ(m.landmarks[0].yaw_rad, M_PI);
	EXPECT_DOUBLE_EQ(m.landmarks[0].scale, 1.0);
	EXPECT_DOUBLE_EQ(m.landmarks[1].scale, 1.5);
	EXPECT_DOUBLE_EQ(m.landmarks[1].geometry().inner_size_m, 0.24);
	ASSERT_NE(m.find(18), nullptr);
	EXPECT_EQ(m.find(19), nullptr);
}

TEST(Map, BadLinesNameTheLine)
{
	expectError("1 0 0 0 0\n2 0 0 0\n", 2, "expected 5 or 6 fields");
	expectError("1 0 0 0 0 1 7\n", 1, "expected 5 or 6 fields");
	expectError("# c\n1 0 abc 0 0\n", 2, "field 'y' is not a number");
	expectError("1 0 0 0 1.5x\n", 1, "field 'yaw' is not a number");
	expectError("1 0 nan 0 0\n", 1, "not finite");
	expectError("1 inf 0 0 0\n", 1, "not finite");
	expectError("1 0 0 0 0\n\n1 1 0 0 0\n", 3, "duplicate ID 1");
	expectError("256 0 0 0 0\n", 1, "0..255");
	expectError("-1 0 0 0 0\n", 1, "0..255");
	expectError("2.5 0 0 0 0\n", 1, "0..255");
	expectError("3 0 0 0 0 0\n", 1, "scale must be > 0");
}

TEST(Map, SaveLoadRoundTrip)
{
	LandmarkMap m;
	m.landmarks.push_back({5, 1.25, -2.5, 0.4, 0.3, 1.0});
	m.landmarks.push_back({200, 0.0, 3.0, 1.1, -2.0, 2.25});
	std::stringstream ss;
	m.write(ss);
	const auto back = LandmarkMap::parse(ss, "mem");
	ASSERT_EQ(back.landmarks.size(), 2u);
	for (std::size_t i = 0; i < 2; ++i)
	{
		EXPECT_EQ(back.landmarks[i].id, m.landmarks[i].id);
		EXPECT_NEAR(back.landmarks[i].x_m, m.landmarks[i].x_m, 1e-9);
		EXPECT_NEAR(back.landmarks[i].yaw_rad, m.landmarks[i].yaw_rad, 1e-9);
		EXPECT_NEAR(back.landmarks[i].scale, m.landmarks[i].scale, 1e-9);
	}
}

TEST(Map, PoseOfLandmarkFrame)
{
	MapLandmark l{7, 1, 2, 0.5, M_PI / 2, 1};
	const auto T = l.world_T_landmark();
	// X_L (outward normal) points along world +y for yaw 90 deg; Z_L is up.
	const auto R = T.getRotationMatrix();
	EXPECT_NEAR(R(1, 0), 1.0, 1e-12);
	EXPECT_NEAR(R(2, 2), 1.0, 1e-12);
}

TEST(Map, MissingFileThrows)
{
	EXPECT_THROW(LandmarkMap::load("/nonexistent/map.txt"), std::runtime_error);
}

TEST(Map, ShippedExampleLoads)
{
	const auto m = LandmarkMap::load(std::string(CODEMARK_SOURCE_SHARE_DIR) + "/example-map.txt");
	EXPECT_GE(m.landmarks.size(), 4u);
}
