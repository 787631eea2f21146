// Calibration files: a written calibration reads back exactly, every shipped
// one loads, a [pose] section overrides its keys field by field, and each
// kind of bad file is refused with the file, the line and the key.
#include <codemark/pose/calibration.h>
#include <codemark/pose/uncertainty.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <Eigen/Dense>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "common.h"

using namespace codemark;
using namespace codemark::pose;

namespace
{
std::string tempPath(const std::string& name)
{
	return (std::filesystem::temp_directory_path() /
			("codemark-test-calibration-" + std::to_string(::getpid()) + "-" + name))
		.string();
}

/** A noise model with every key away from the library defaults. */
PoseOptions fullModel()
{
	PoseOptions o;
	o.sigma_px = 0.0238;
	o.sigma_y_px = 0.0163;
	o.growth_x_px = 0.02;
	o.growth_y_px = 1.0 / 3;  // not a short decimal: must still read back exactly
	o.size_exponent_x = 1.75;
	o.size_exponent_y = 1.25;
	o.size_reference_px = 31;
	o.corr_x12 = 0.05;
	o.corr_growth_x12 = -0.4;
	o.corr_y12 = 0.4;
	o.corr_growth_y12 = -0.15;
	o.sigma_x_table = {{11.6, 0.0794}, {54.4, 0.011}, {180, 0.00692}};
	o.sigma_y_table = {{28.7, 0.0339}, {181.3, 0.00468}};
	o.reference_noise_grey = 2.06;
	o.noise_sigma_x_table = {{13.9, 0.00419}, {91.3, 0.0181}};
	o.noise_sigma_y_table = {{24, 0.0125}, {117.9, 0.0168}};
	o.clipped_side_sigma_px = 0.03;
	o.clipped_side_correlation = 0.2;
	o.aligned_edge_ratio = 0.5;
	o.corner_midpoint_ratio = 0.91;
	o.corner_tilt_ratio = 0.34;
	o.corner_tilt_ratio_table = {{28.7, 0.31}, {150.2, 0.82}};
	o.corner_tilt_noise_ratio = 0.96;
	o.band_ratio_x = 4.5;
	o.band_ratio_y = 3.9;
	o.band_floor_x_table = {{14.2, 0.061}, {60.5, 0.0123}};
	o.band_floor_y_table = {{22.8, 0.0405}};
	return o;
}

/** The calibration text of fullModel() with line \a key's value replaced by
 * \a value (or the line dropped when \a value is "<drop>"), and \a extra
 * appended to [pose]. */
std::string variant(const std::string& key, const std::string& value, const std::string& extra = "")
{
	const std::string path = tempPath("base.ini");
	saveCalibration(path, fullModel(), {"test"});
	std::ifstream in(path);
	std::ostringstream out;
	for (std::string line; std::getline(in, line);)
	{
		if (!key.empty() && line.rfind(key + " =", 0) == 0)
		{
			if (value != "<drop>") out << key << " = " << value << "\n";
			continue;
		}
		out << line << "\n";
	}
	out << extra;
	std::filesystem::remove(path);
	return out.str();
}

/** The message loadCalibration() throws on \a text (empty if it loads). */
std::string refusal(const std::string& text)
{
	const std::string path = tempPath("bad.ini");
	std::ofstream(path) << text;
	std::string what;
	try
	{
		loadCalibration(path);
	}
	catch (const std::exception& e)
	{
		what = e.what();
	}
	std::filesystem::remove(path);
	return what;
}
}  // namespace

TEST(Calibration, WrittenFileReadsBackExactly)
{
	const std::string path = tempPath("round.ini");
	const PoseOptions a = fullModel();
	saveCalibration(path, a, {"made by: test", "date: now"});
	PoseOptions base;
	base.fold_ambiguity = false;  // not a calibration key: kept
	const PoseOptions b = loadCalibration(path, base);
	std::filesystem::remove(path);
	EXPECT_FALSE(b.fold_ambiguity);
	EXPECT_EQ(a.sigma_px, b.sigma_px);
	EXPECT_EQ(a.growth_y_px, b.growth_y_px);
	EXPECT_EQ(a.size_reference_px, b.size_reference_px);
	EXPECT_EQ(a.corr_growth_x12, b.corr_growth_x12);
	EXPECT_EQ(a.clipped_side_correlation, b.clipped_side_correlation);
	EXPECT_EQ(a.sigma_x_table, b.sigma_x_table);
	EXPECT_EQ(a.noise_sigma_y_table, b.noise_sigma_y_table);
	EXPECT_EQ(a.corner_tilt_ratio_table, b.corner_tilt_ratio_table);
	EXPECT_EQ(a.corner_tilt_noise_ratio, b.corner_tilt_noise_ratio);
	EXPECT_EQ(a.band_ratio_y, b.band_ratio_y);
	EXPECT_EQ(a.band_floor_x_table, b.band_floor_x_table);
	// The same C_P everywhere, clipped sides, noise scaling and the bands'
	// scatter included.
	const Eigen::Vector4d P(-40, 30, 45, 33);
	EXPECT_EQ(a.primaryCovariance(P, 5.0), b.primaryCovariance(P, 5.0));
	EXPECT_EQ(a.primaryCovariance(P, 5.0, 0.02), b.primaryCovariance(P, 5.0, 0.02));
	EXPECT_EQ(
		a.clippedSidesCovariance({true, false, true, true}),
		b.clippedSidesCovariance({true, false, true, true}));
}

TEST(Calibration, ProvenanceIsWrittenAsComments)
{
	const std::string path = tempPath("prov.ini");
	saveCalibration(path, fullModel(), {"made by: tool --x 1", "data: two\nlines"});
	std::ifstream in(path);
	std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
	std::filesystem::remove(path);
	EXPECT_EQ(text.rfind("# made by: tool --x 1\n# data: two\n# lines\n", 0), 0u) << text;
	for (const auto& k : calibrationKeys())
		EXPECT_NE(text.find("\n" + k + " ="), std::string::npos) << k;
}

TEST(Calibration, EveryShippedCalibrationLoads)
{
	const auto names = shippedCalibrationNames();
	ASSERT_GE(names.size(), 2u);
	for (const auto& n : names)
	{
		SCOPED_TRACE(n);
		const PoseOptions o = loadCalibration(shippedCalibrationPath(n));
		// A 40 px landmark's C_P is positive definite and of sub-pixel size.
		const Eigen::Matrix4d C = o.primaryCovariance(Eigen::Vector4d(-20, 20, 20, 20));
		const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(C);
		EXPECT_GT(es.eigenvalues().minCoeff(), 0);
		EXPECT_LT(std::sqrt(es.eigenvalues().maxCoeff()), 1.0);
	}
	EXPECT_EQ(resolveCalibration(names[0]), shippedCalibrationPath(names[0]));
}

TEST(Calibration, MissingShippedCalibrationNamesWhereItLooked)
{
	try
	{
		shippedCalibrationPath("no-such-calibration");
		FAIL() << "no exception";
	}
	catch (const std::runtime_error& e)
	{
		const std::string what = e.what();
		EXPECT_NE(what.find("calibration/no-such-calibration.ini"), std::string::npos) << what;
		for (const auto& d : shareSearchDirs()) EXPECT_NE(what.find(d), std::string::npos) << what;
	}
}

TEST(Calibration, PoseSectionOverridesItsKeys)
{
	const std::string path = tempPath("override.ini");
	saveCalibration(path, fullModel(), {"test"});
	PoseOptions o = loadCalibration(path);
	std::filesystem::remove(path);
	mrpt::config::CConfigFileMemory ini;
	ini.setContent("[pose]\nsigma_px = 0.5\nsigma_x_table =\n");
	o.loadFromConfigFile(ini, "pose");
	EXPECT_EQ(o.sigma_px, 0.5);
	EXPECT_EQ(o.sigma_y_px, fullModel().sigma_y_px);
	EXPECT_EQ(o.noise_sigma_x_table, fullModel().noise_sigma_x_table);
}

TEST(Calibration, BadFilesAreRefusedWithFileLineAndKey)
{
	ASSERT_EQ(refusal(variant("", "")), "");  // the unmodified text loads
	struct Case
	{
		std::string text, expected;	 // expected: a regex of the message
	};
	const Case cases[] = {
		{variant("", "", "sigma_pixels = 0.1\n"), ":[0-9]+: unknown key 'sigma_pixels'"},
		{variant("corr_y12", "<drop>"), "misses key 'corr_y12'"},
		{variant("sigma_y_px", "nan"), ":[0-9]+: sigma_y_px = 'nan': not a finite number"},
		{variant("growth_x_px", "0.2x"), ":[0-9]+: growth_x_px = '0.2x': not a finite number"},
		{variant("growth_y_px", "-0.01"), ":[0-9]+: growth_y_px = '-0.01': must be >= 0"},
		{variant("sigma_px", "0"), ":[0-9]+: sigma_px = '0': must be > 0"},
		{variant("corr_growth_x12", "1.5"), ":[0-9]+: corr_growth_x12 = '1.5': a correlation"},
		{variant("corr_x12", "-1"), ":[0-9]+: corr_x12 = '-1': a correlation"},
		{variant("clipped_side_correlation", "-0.2"), ":[0-9]+: clipped_side_correlation"},
		{variant("sigma_x_table", "10:0.1 5:0.2"),
		 ":[0-9]+: sigma_x_table = .*sizes must increase"},
		{variant("noise_sigma_y_table", "10:-1"), ":[0-9]+: noise_sigma_y_table = .*bad entry"},
		{variant("band_ratio_x", "-2"), ":[0-9]+: band_ratio_x = '-2': must be >= 0"},
		{variant("band_floor_y_table", "20:0 30:0.1"), ":[0-9]+: band_floor_y_table = .*bad entry"},
		{variant("", "", "sigma_px = 0.1\n"), ":[0-9]+: key 'sigma_px' set twice"},
		{"[other]\nsigma_px = 1\n", "no \\[pose\\] section"},
	};
	for (const Case& c : cases)
	{
		const std::string what = refusal(c.text);
		EXPECT_TRUE(std::regex_search(what, std::regex(c.expected))) << what;
		EXPECT_NE(what.find("codemark-test-calibration-"), std::string::npos) << what;
	}
	EXPECT_THROW(loadCalibration("/nonexistent/calibration.ini"), std::runtime_error);
}

// The scatter model's keys came later than the format: a file without them
// (every calibration written before) loads, with the model off.
TEST(Calibration, FileWithoutTheScatterModelLoadsWithItOff)
{
	std::string text = variant("band_ratio_x", "<drop>");
	for (const char* key : {"band_ratio_y", "band_floor_x_table", "band_floor_y_table"})
	{
		const auto at = text.find(std::string(key) + " =");
		ASSERT_NE(at, std::string::npos) << key;
		text.erase(at, text.find('\n', at) - at + 1);
	}
	ASSERT_EQ(refusal(text), "");
	const std::string path = tempPath("old.ini");
	std::ofstream(path) << text;
	PoseOptions base;
	base.band_ratio_x = 7;	// not the file's: the file's model is off
	const PoseOptions o = loadCalibration(path, base);
	std::filesystem::remove(path);
	EXPECT_EQ(o.band_ratio_x, 0);
	EXPECT_EQ(o.band_ratio_y, 0);
	EXPECT_TRUE(o.band_floor_x_table.empty());
	// Its C_P is the tables' whatever the detector measured.
	const Eigen::Vector4d P(-40, 30, 45, 33);
	EXPECT_EQ(o.primaryCovariance(P, 0, 0.05), o.primaryCovariance(P));
}

TEST(Calibration, LineNumberIsTheKeysLine)
{
	const std::string bad = variant("corr_x12", "2");
	int line = 1;
	for (size_t k = 0; k < bad.find("corr_x12 ="); ++k) line += bad[k] == '\n';
	const std::string what = refusal(bad);
	EXPECT_NE(what.find(":" + std::to_string(line) + ": corr_x12"), std::string::npos) << what;
}

TEST(Calibration, PredictionWithACalibrationUsesItsSizeDependentNoise)
{
	const CameraModel cam;
	const LandmarkGeometry g;
	PoseOptions o = constantNoise(0.05);
	o.growth_x_px = o.growth_y_px = 0.5;  // a far landmark's C_P grows
	const auto near_c = predictUncertainty(cam, g, constantNoise(0.05), 1.0, 0.3);
	const auto near_g = predictUncertainty(cam, g, o, 1.0, 0.3);
	const auto far_c = predictUncertainty(cam, g, constantNoise(0.05), 4.0, 0.3);
	const auto far_g = predictUncertainty(cam, g, o, 4.0, 0.3);
	ASSERT_TRUE(near_c.in_image && far_c.in_image);
	// The growth term matters more where the landmark is small.
	EXPECT_GT(far_g.sigma_l2_m / far_c.sigma_l2_m, near_g.sigma_l2_m / near_c.sigma_l2_m);
	EXPECT_GT(near_g.sigma_l2_m, near_c.sigma_l2_m);
}
