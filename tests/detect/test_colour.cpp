// The colour report (codemark-detect --colour-report) on renders of prints
// of known colour.
#include <codemark/detect/colour.h>

#include "common.h"

#include <gtest/gtest.h>

using namespace codemark;
using namespace codemark::detect;
using namespace codemark::detect::test;

TEST(Colour, HsiOfPrimariesAndGreys)
{
	const auto green = hsiOf(0, 255, 0);
	EXPECT_DOUBLE_EQ(green.hue_deg, 120);
	EXPECT_DOUBLE_EQ(green.saturation, 1);
	EXPECT_DOUBLE_EQ(green.intensity, 85);
	EXPECT_DOUBLE_EQ(hsiOf(255, 0, 0).hue_deg, 0);
	EXPECT_DOUBLE_EQ(hsiOf(0, 0, 255).hue_deg, 240);
	// An office inkjet's green, sRGB (40, 170, 80): 120 + 60 * 40 / 130.
	const auto ink = hsiOf(40, 170, 80);
	EXPECT_NEAR(ink.hue_deg, 120 + 60.0 * 40 / 130, 1e-12);
	EXPECT_NEAR(ink.saturation, 1 - 40 / (290.0 / 3), 1e-12);
	const auto grey = hsiOf(90, 90, 90);
	EXPECT_DOUBLE_EQ(grey.saturation, 0);
	EXPECT_DOUBLE_EQ(grey.hue_deg, 0);
}

// A noise-free, sharp render of a print in a known green and black: the
// report reads those colours back, and each margin is the distance to its
// threshold.
TEST(Colour, ReportReadsTheColoursOfAKnownPrint)
{
	for (const cv::Scalar& green_bgr : {cv::Scalar(80, 170, 40), cv::Scalar(0, 255, 0)})
		for (const double dist : {1.0, 3.0})
		{
			sim::RenderOptions o;
			o.background = sim::Background::Flat;
			o.green_bgr = green_bgr;
			o.black_bgr = cv::Scalar(30, 35, 40);
			const Shot s = shoot(77, dist, 20 * kDeg, o, 5);
			DetectorOptions opt;
			const auto res = detect::detect(s.render.image, CameraModel(), LandmarkGeometry(), opt);
			ASSERT_EQ(res.landmarks.size(), 1u) << "distance " << dist;
			const ColourReport c = colourReport(
				s.render.image, res.landmarks[0].detection, CameraModel(), LandmarkGeometry(), opt);
			SCOPED_TRACE("green " + std::to_string(green_bgr[1]) + " at " + std::to_string(dist));
			EXPECT_NEAR(c.fill.b, green_bgr[0], 1.0);
			EXPECT_NEAR(c.fill.g, green_bgr[1], 1.0);
			EXPECT_NEAR(c.fill.r, green_bgr[2], 1.0);
			EXPECT_NEAR(c.frame.b, 30, 1.0);
			EXPECT_NEAR(c.frame.g, 35, 1.0);
			EXPECT_NEAR(c.frame.r, 40, 1.0);
			EXPECT_GT(c.fill.samples, 50);
			EXPECT_GT(c.frame.samples, 20);
			const auto expect = hsiOf(green_bgr[2], green_bgr[1], green_bgr[0]);
			EXPECT_NEAR(c.fill.hue_deg, expect.hue_deg, 1.0);
			EXPECT_NEAR(c.fill.saturation, expect.saturation, 0.01);
			EXPECT_NEAR(
				c.margin_saturation, c.fill.saturation - opt.segmentation.min_saturation, 1e-12);
			EXPECT_NEAR(c.margin_hue_min_deg, c.fill.hue_deg - opt.segmentation.hue_min_deg, 1e-12);
			EXPECT_NEAR(c.margin_hue_max_deg, opt.segmentation.hue_max_deg - c.fill.hue_deg, 1e-12);
			EXPECT_NEAR(
				c.margin_intensity, c.fill.intensity - opt.segmentation.min_intensity, 1e-12);
			// The ratio compares the frame's ink: the level read less the
			// share of fill and sheet a 1.5 px blur would spread over it. At
			// 1 m the frame spans 15 px and has no share; at 3 m (5 px) this
			// sharp render's ink reads darker than its level.
			const double as_read = opt.code.max_black_ratio - 35 / green_bgr[1];
			if (dist < 2)
			{
				EXPECT_NEAR(c.margin_black_ratio, as_read, 0.01);
			}
			else
			{
				EXPECT_GT(c.margin_black_ratio, as_read + 0.01);
				EXPECT_LT(c.margin_black_ratio, as_read + 0.2);
			}
			EXPECT_NEAR(c.margin_contrast, green_bgr[1] - 35 - opt.code.min_contrast, 1.0);
			// The JSON object carries every field.
			const std::string json = colourReportJson(c);
			for (const char* key :
				 {"\"fill\"", "\"frame\"", "\"rgb\"", "\"hue_deg\"", "\"saturation\"",
				  "\"intensity\"", "\"margins\"", "\"black_ratio\"", "\"contrast\"",
				  "\"hue_min_deg\"", "\"hue_max_deg\""})
				EXPECT_NE(json.find(key), std::string::npos) << key;
		}
}
