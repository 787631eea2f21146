#include <codemark/detect/json.h>

#include <gtest/gtest.h>

using namespace codemark;
using namespace codemark::detect;

TEST(Json, ImageLineHasTheSpecFields)
{
	DetectedLandmark d;
	d.detection.id = 37;
	d.detection.corners = {
		Eigen::Vector2d(1.23456789, 2), Eigen::Vector2d(3, 4), Eigen::Vector2d(5, 6),
		Eigen::Vector2d(7, 8.00001)};
	d.P = Eigen::Vector4d(-10.5, 20, 30, 19.75);
	const std::string s =
		imageToJson("dir/a \"b\".png", 640, 480, 0.8, {d}, {{{"L", "[1, 2, 3]"}}});
	EXPECT_EQ(
		s,
		"{\"image\": \"dir/a \\\"b\\\".png\", \"width\": 640, \"height\": 480, \"time_ms\": 0.8, "
		"\"detections\": [{\"id\": 37, \"corners\": [[1.23456789, 2], [3, 4], [5, 6], [7, "
		"8.00001]], "
		"\"P\": [-10.5, 20, 30, 19.75], \"L\": [1, 2, 3]}]}");
	EXPECT_EQ(
		imageToJson("x.png", 1, 2, 0.5, {}),
		"{\"image\": \"x.png\", \"width\": 1, \"height\": 2, \"time_ms\": 0.5, \"detections\": "
		"[]}");
}

TEST(Json, ErrorLineAndEscapes)
{
	EXPECT_EQ(
		errorToJson("v.mp4#3", "cannot\nread"),
		"{\"image\": \"v.mp4#3\", \"error\": \"cannot\\nread\"}");
	EXPECT_EQ(jsonString(std::string("a\x01", 2)), "\"a\\u0001\"");
	EXPECT_EQ(jsonNumber(std::nan("")), "null");
	EXPECT_EQ(jsonNumber(123.45678912), "123.4567891");
}
