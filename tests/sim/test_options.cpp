#include <codemark/sim/render.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <string>

using namespace codemark::sim;

TEST(RenderOptions, IniRoundTrip)
{
	RenderOptions a;
	a.background = Background::Cluttered;
	a.background_grey = 90.5;
	a.distractors = 7;
	a.black_bgr = cv::Scalar(10, 20, 30);
	a.white_bgr = cv::Scalar(200, 210, 220);
	a.green_bgr = cv::Scalar(5, 240, 15);
	a.gain = 0.8;
	a.gradient = 0.4;
	a.gradient_angle_rad = 0.3;
	a.noise_sigma = 2.5;
	a.blur_sigma_px = 0.7;
	a.motion_blur_px = 3;
	a.motion_blur_angle_rad = 1.1;
	a.jpeg_quality = 85;
	a.occlusion = 0.25;
	a.supersampling = 6;
	mrpt::config::CConfigFileMemory cfg;
	a.saveToConfigFile(cfg, "RENDER");
	RenderOptions b;
	b.loadFromConfigFile(cfg, "RENDER");
	EXPECT_EQ(b.background, a.background);
	EXPECT_DOUBLE_EQ(b.background_grey, a.background_grey);
	EXPECT_EQ(b.distractors, a.distractors);
	for (int i = 0; i < 3; ++i)
	{
		EXPECT_DOUBLE_EQ(b.black_bgr[i], a.black_bgr[i]);
		EXPECT_DOUBLE_EQ(b.white_bgr[i], a.white_bgr[i]);
		EXPECT_DOUBLE_EQ(b.green_bgr[i], a.green_bgr[i]);
	}
	EXPECT_DOUBLE_EQ(b.gain, a.gain);
	EXPECT_DOUBLE_EQ(b.gradient, a.gradient);
	EXPECT_DOUBLE_EQ(b.gradient_angle_rad, a.gradient_angle_rad);
	EXPECT_DOUBLE_EQ(b.noise_sigma, a.noise_sigma);
	EXPECT_DOUBLE_EQ(b.blur_sigma_px, a.blur_sigma_px);
	EXPECT_DOUBLE_EQ(b.motion_blur_px, a.motion_blur_px);
	EXPECT_DOUBLE_EQ(b.motion_blur_angle_rad, a.motion_blur_angle_rad);
	EXPECT_EQ(b.jpeg_quality, a.jpeg_quality);
	EXPECT_DOUBLE_EQ(b.occlusion, a.occlusion);
	EXPECT_EQ(b.supersampling, a.supersampling);
}

TEST(RenderOptions, BackgroundByName)
{
	mrpt::config::CConfigFileMemory cfg("[R]\nbackground = textured\n");
	RenderOptions o;
	o.loadFromConfigFile(cfg, "R");
	EXPECT_EQ(o.background, Background::Textured);
	EXPECT_EQ(backgroundFromName("Cluttered"), Background::Cluttered);
	EXPECT_STREQ(backgroundName(Background::Flat), "Flat");
}

namespace
{
/** Loads a section with one bad line and returns the exception message. */
std::string loadError(const std::string& line)
{
	mrpt::config::CConfigFileMemory cfg("[R]\n" + line + "\n");
	RenderOptions o;
	try
	{
		o.loadFromConfigFile(cfg, "R");
	}
	catch (const std::invalid_argument& e)
	{
		return e.what();
	}
	return "";
}
}  // namespace

TEST(RenderOptions, BadValuesNameTheKey)
{
	const std::pair<const char*, const char*> cases[] = {
		{"noise_sigma = -1", "noise_sigma"},
		{"blur_sigma_px = -0.5", "blur_sigma_px"},
		{"motion_blur_px = -2", "motion_blur_px"},
		{"jpeg_quality = 101", "jpeg_quality"},
		{"jpeg_quality = -1", "jpeg_quality"},
		{"gain = 0", "gain"},
		{"gain = -1", "gain"},
		{"occlusion = 1.5", "occlusion"},
		{"background_grey = 300", "background_grey"},
		{"distractors = -3", "distractors"},
		{"background = Plaid", "background"},
		{"black_bgr = 1 2", "black_bgr"},
		{"green_bgr = 0 256 0", "green_bgr"},
		{"supersampling = 0", "supersampling"},
		{"gradient = 3", "gradient"},
	};
	for (const auto& [line, key] : cases)
	{
		const std::string msg = loadError(line);
		EXPECT_NE(msg.find(key), std::string::npos) << "line '" << line << "' gave '" << msg << "'";
	}
	EXPECT_EQ(loadError("noise_sigma = 0"), "");
	EXPECT_EQ(loadError("jpeg_quality = 100"), "");
}

TEST(RenderOptions, RenderRejectsInvalidOptions)
{
	Scene scene;
	RenderOptions o;
	o.noise_sigma = -1;
	EXPECT_THROW(render(scene, o, 1), std::invalid_argument);
}
