#include <codemark/detect/options.h>
#include <codemark/landmark/camera.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include <string>
#include <utility>
#include <vector>

using namespace codemark;
using namespace codemark::detect;

namespace
{
/** The message of the \a E that \a f throws; a test failure and "" when
 * it throws none. */
template <typename E, typename F>
std::string thrownMessage(F&& f)
{
	try
	{
		f();
	}
	catch (const E& e)
	{
		return e.what();
	}
	ADD_FAILURE() << "expected a throw";
	return "";
}
}  // namespace

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
	EXPECT_NE(
		thrownMessage<std::invalid_argument>([&] { o.loadFromConfigFile(cfg, "D"); })
			.find("segmentation.step_px"),
		std::string::npos);
	mrpt::config::CConfigFileMemory cfg2;
	cfg2.write("D", "segmentation.hue_max_deg", 200);
	EXPECT_THROW(o.loadFromConfigFile(cfg2, "D"), std::invalid_argument);
	EXPECT_THROW(DetectorOptions::load("/nonexistent/detector.ini"), std::runtime_error);
}

// A value not of its key's type is refused with the key and the text
// (MRPT's own readers take "maybe" for false and "3x" for 3).
TEST(Options, ValuesOfTheWrongTypeAreRefused)
{
	for (const auto& [key, text] : std::vector<std::pair<std::string, std::string>>{
			 {"segmentation.box_smoothing", "maybe"},
			 {"segmentation.step_px", "3x"},
			 {"segmentation.step_px", "2.5"},
			 {"subpixel.outlier_sigmas", "2.5 px"}})
	{
		mrpt::config::CConfigFileMemory cfg;
		cfg.write("D", key, text);
		DetectorOptions o;
		const std::string what =
			thrownMessage<std::invalid_argument>([&] { o.loadFromConfigFile(cfg, "D"); });
		EXPECT_NE(what.find(key + " = '" + text + "'"), std::string::npos) << what;
	}
	// Booleans in the spellings ini files use.
	for (const auto& [text, value] : std::vector<std::pair<std::string, bool>>{
			 {"true", true}, {"False", false}, {"1", true}, {"0", false}, {"yes", true}})
	{
		mrpt::config::CConfigFileMemory cfg;
		cfg.write("D", "segmentation.box_smoothing", text);
		DetectorOptions o;
		o.segmentation.box_smoothing = !value;
		o.loadFromConfigFile(cfg, "D");
		EXPECT_EQ(o.segmentation.box_smoothing, value) << text;
	}
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

// A key the detector does not read is refused with its name, the file and
// its line: a misspelt key would otherwise leave its default in force. A
// value of the wrong type or out of range names its line too.
TEST(Options, UnknownKeysAreRefusedWithFileAndLine)
{
	mrpt::config::CConfigFileMemory cfg;
	cfg.write("D", "segmentation.min_saturaton", 0.3);
	DetectorOptions o;
	std::string what =
		thrownMessage<std::invalid_argument>([&] { o.loadFromConfigFile(cfg, "D"); });
	EXPECT_NE(what.find("'segmentation.min_saturaton'"), std::string::npos) << what;
	// The sub-pixel stage's model switches are for tests and benchmarks
	// (SubpixelModels), not detector options: a file that sets one is told
	// so rather than left believing a model is off.
	for (const char* key :
		 {"subpixel.thin_frame_model", "subpixel.frame_midline", "subpixel.model_clipping",
		  "subpixel.step_model_peak", "subpixel.model_outer_edge",
		  "subpixel.correct_level_rounding"})
	{
		mrpt::config::CConfigFileMemory models;
		models.write("D", key, "false");
		what = thrownMessage<std::invalid_argument>([&] { o.loadFromConfigFile(models, "D"); });
		EXPECT_NE(what.find(std::string("'") + key + "'"), std::string::npos) << what;
	}
	const std::string path = testing::TempDir() + "codemark_unknown_key.ini";
	{
		std::ofstream f(path);
		f << "[OTHER]\nsubpixel.no_such_option = 1\n[DETECTOR]\n# comment\n"
			 "segmentation.step_px = 2\n  subpixel.no_such_option = true\n";
	}
	const auto load = [&] { (void)DetectorOptions::load(path); };
	what = thrownMessage<std::runtime_error>(load);
	EXPECT_NE(what.find(path + ":6:"), std::string::npos) << what;
	EXPECT_NE(what.find("subpixel.no_such_option"), std::string::npos) << what;
	// A value of the wrong type is located on its line too.
	{
		std::ofstream f(path);
		f << "[DETECTOR]\n\nsegmentation.step_px = 2x\n";
	}
	what = thrownMessage<std::runtime_error>(load);
	EXPECT_NE(what.find(path + ":3:"), std::string::npos) << what;
	// And a value out of its range.
	{
		std::ofstream f(path);
		f << "[DETECTOR]\nsegmentation.step_px = 2\ncomponents.frame_blur_px = -1\n";
	}
	what = thrownMessage<std::runtime_error>(load);
	EXPECT_NE(what.find(path + ":3:"), std::string::npos) << what;
	EXPECT_NE(what.find("components.frame_blur_px must be in [0, 10]"), std::string::npos) << what;
	std::remove(path.c_str());
}
