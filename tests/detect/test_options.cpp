#include <codemark/detect/options.h>
#include <codemark/landmark/camera.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <gtest/gtest.h>

using namespace codemark;
using namespace codemark::detect;

TEST(Options, DefaultsAreValid) { EXPECT_NO_THROW(DetectorOptions().validate()); }

TEST(Options, SaveLoadRoundTrip)
{
	DetectorOptions o;
	o.segmentation.step_px = 3;
	o.segmentation.box_smoothing = true;
	o.segmentation.hue_min_deg = 90;
	o.components.max_candidates = 7;
	o.subpixel.outlier_sigmas = 2.5;
	o.code.min_margin = 0.2;
	mrpt::config::CConfigFileMemory cfg;
	o.saveToConfigFile(cfg, "DETECTOR");
	DetectorOptions back;
	back.loadFromConfigFile(cfg, "DETECTOR");
	EXPECT_EQ(back.segmentation.step_px, 3);
	EXPECT_TRUE(back.segmentation.box_smoothing);
	EXPECT_DOUBLE_EQ(back.segmentation.hue_min_deg, 90);
	EXPECT_EQ(back.components.max_candidates, 7);
	EXPECT_DOUBLE_EQ(back.subpixel.outlier_sigmas, 2.5);
	EXPECT_DOUBLE_EQ(back.code.min_margin, 0.2);
}

TEST(Options, InvalidValuesAreRejectedByName)
{
	mrpt::config::CConfigFileMemory cfg;
	cfg.write("D", "segmentation.step_px", 9);
	DetectorOptions o;
	try
	{
		o.loadFromConfigFile(cfg, "D");
		FAIL() << "expected a throw";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("segmentation.step_px"), std::string::npos);
	}
	mrpt::config::CConfigFileMemory cfg2;
	cfg2.write("D", "segmentation.hue_max_deg", 200);
	EXPECT_THROW(o.loadFromConfigFile(cfg2, "D"), std::invalid_argument);
	EXPECT_THROW(DetectorOptions::load("/nonexistent/detector.ini"), std::runtime_error);
}

TEST(Options, ShippedIniHoldsTheDefaults)
{
	const std::string path = findShareFile("detector.ini");
	ASSERT_FALSE(path.empty());
	const DetectorOptions o = DetectorOptions::load(path);
	// Every key of the shipped file equals the compiled default.
	mrpt::config::CConfigFileMemory a, b;
	o.saveToConfigFile(a, "DETECTOR");
	DetectorOptions().saveToConfigFile(b, "DETECTOR");
	EXPECT_EQ(a.getContent(), b.getContent());
	// And the file names every key.
	std::vector<std::string> keys_file, keys_all;
	mrpt::config::CConfigFile f(path);
	f.getAllKeys("DETECTOR", keys_file);
	b.getAllKeys("DETECTOR", keys_all);
	EXPECT_EQ(keys_file.size(), keys_all.size());
}
