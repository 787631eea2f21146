// The paper's Fig. 3 as a file: written, with drawn ellipses.
#include <codemark/eval/uncertainty_figure.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

using namespace codemark;
using namespace codemark::eval;

TEST(UncertaintyFigure, WrittenWithEllipses)
{
	const CameraModel cam;
	const std::string path =
		(std::filesystem::temp_directory_path() / "codemark_test_fig3.png").string();
	FigureOptions fo;
	const FigureScales sc = drawUncertaintyFigure(path, cam, fo);
	EXPECT_GT(sc.ellipse, 0);
	EXPECT_GE(sc.heading, 1);
	const cv::Mat img = cv::imread(path);
	ASSERT_FALSE(img.empty());
	EXPECT_GE(img.cols, 640);
	// Some red (ellipse) pixels were drawn.
	int red = 0;
	for (int r = 0; r < img.rows; ++r)
		for (int c = 0; c < img.cols; ++c)
		{
			const auto p = img.at<cv::Vec3b>(r, c);
			red += p[2] > 180 && p[1] < 100 && p[0] < 100;
		}
	EXPECT_GT(red, 100);
	std::remove(path.c_str());
	EXPECT_THROW(drawUncertaintyFigure("/nonexistent-dir/x.png", cam, fo), std::exception);
}

// The text reports: the table marks what the detector can use, the size
// advice names the scale and the printed sizes it found.
TEST(UncertaintyReports, TableAndSizeAdvice)
{
	const CameraModel cam;
	const std::string t = accuracyTable(cam, 1.0, 0.05, 0.0, {0.5, 1.0, 4.5});
	EXPECT_NE(t.find("yes"), std::string::npos);
	EXPECT_NE(t.find("too small"), std::string::npos);	// 4.5 m: 28 px
	const pose::SizeAdvice a = pose::sizeFor(cam, 0.05, 0.02, M_PI / 180, 2.0, 0.0, 2.0, 30);
	ASSERT_TRUE(a.found);
	const std::string d = describeSizeAdvice(a, 2.0);
	EXPECT_NE(d.find("reference square"), std::string::npos);
	EXPECT_NE(d.find("2.0 sigma"), std::string::npos);
	EXPECT_NE(
		describeSizeAdvice(pose::sizeFor(cam, 1.0, 0.001, 0.001, 4.0, 0.0), 2.0)
			.find("no landmark size"),
		std::string::npos);
}
