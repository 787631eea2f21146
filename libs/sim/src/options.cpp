#include <codemark/landmark/text.h>
#include <codemark/sim/render.h>
#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace codemark::sim
{
namespace
{
[[noreturn]] void bad(const std::string& key, const std::string& what)
{
	throw std::invalid_argument("render option '" + key + "' " + what);
}

void checkRange(const std::string& key, double v, double lo, double hi)
{
	if (!std::isfinite(v) || v < lo || v > hi)
	{
		std::ostringstream s;
		s << "must be in [" << lo << ", " << hi << "], got " << v;
		bad(key, s.str());
	}
}

void checkBgr(const std::string& key, const cv::Scalar& c)
{
	for (int i = 0; i < 3; ++i) checkRange(key, c[i], 0, 255);
}

cv::Scalar readBgr(
	const mrpt::config::CConfigFileBase& c, const std::string& s, const std::string& key,
	const cv::Scalar& def)
{
	const std::string text = c.read_string(s, key, "");
	if (text.empty()) return def;
	std::string t = text;
	std::replace_if(
		t.begin(), t.end(), [](char ch) { return ch == '[' || ch == ']' || ch == ','; }, ' ');
	std::istringstream in(t);
	double b, g, r;
	std::string rest;
	if (!(in >> b >> g >> r) || (in >> rest))
		bad(key, "must be three numbers \"B G R\", got '" + text + "'");
	return {b, g, r};
}

std::string bgrText(const cv::Scalar& c)
{
	std::ostringstream s;
	s << c[0] << " " << c[1] << " " << c[2];
	return s.str();
}
}  // namespace

const char* backgroundName(Background b)
{
	switch (b)
	{
		case Background::Flat:
			return "Flat";
		case Background::Textured:
			return "Textured";
		case Background::Cluttered:
			return "Cluttered";
	}
	return "Flat";
}

Background backgroundFromName(const std::string& name)
{
	std::string n = name;
	std::transform(
		n.begin(), n.end(), n.begin(), [](unsigned char ch) { return std::tolower(ch); });
	if (n == "flat") return Background::Flat;
	if (n == "textured") return Background::Textured;
	if (n == "cluttered") return Background::Cluttered;
	throw std::invalid_argument(
		"render option 'background' must be Flat, Textured or Cluttered, got '" + name + "'");
}

void RenderOptions::validate() const
{
	checkRange("background_grey", background_grey, 0, 255);
	if (distractors < 0 || distractors > 10000) bad("distractors", "must be in 0..10000");
	checkBgr("black_bgr", black_bgr);
	checkBgr("white_bgr", white_bgr);
	checkBgr("green_bgr", green_bgr);
	if (!std::isfinite(gain) || gain <= 0) bad("gain", "must be finite and > 0");
	// The gain factor 1 +- gradient/2 must stay positive.
	checkRange("gradient", gradient, -1.99, 1.99);
	checkRange("gradient_angle_rad", gradient_angle_rad, -1e3, 1e3);
	checkRange("noise_sigma", noise_sigma, 0, 1e4);
	checkRange("blur_sigma_px", blur_sigma_px, 0, 100);
	checkRange("motion_blur_px", motion_blur_px, 0, 500);
	checkRange("motion_blur_angle_rad", motion_blur_angle_rad, -1e3, 1e3);
	if (jpeg_quality < 0 || jpeg_quality > 100)
		bad("jpeg_quality", "must be in 0..100 (0 = no JPEG), got " + std::to_string(jpeg_quality));
	checkRange("occlusion", occlusion, 0, 1);
	if (supersampling < 1 || supersampling > 64)
		bad("supersampling", "must be in 1..64, got " + std::to_string(supersampling));
}

void RenderOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	// MRPT's readers take "abc" as 0 and "2px" as 2: check the numbers first.
	requireIniNumbers(
		c, s,
		{"background_grey", "gain", "gradient", "gradient_angle_rad", "noise_sigma",
		 "blur_sigma_px", "motion_blur_px", "motion_blur_angle_rad", "occlusion"});
	requireIniNumbers(c, s, {"distractors", "jpeg_quality", "supersampling"}, true);
	background = backgroundFromName(c.read_string(s, "background", backgroundName(background)));
	MRPT_LOAD_CONFIG_VAR(background_grey, double, c, s);
	MRPT_LOAD_CONFIG_VAR(distractors, int, c, s);
	black_bgr = readBgr(c, s, "black_bgr", black_bgr);
	white_bgr = readBgr(c, s, "white_bgr", white_bgr);
	green_bgr = readBgr(c, s, "green_bgr", green_bgr);
	MRPT_LOAD_CONFIG_VAR(gain, double, c, s);
	MRPT_LOAD_CONFIG_VAR(gradient, double, c, s);
	MRPT_LOAD_CONFIG_VAR(gradient_angle_rad, double, c, s);
	MRPT_LOAD_CONFIG_VAR(noise_sigma, double, c, s);
	MRPT_LOAD_CONFIG_VAR(blur_sigma_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(motion_blur_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(motion_blur_angle_rad, double, c, s);
	MRPT_LOAD_CONFIG_VAR(jpeg_quality, int, c, s);
	MRPT_LOAD_CONFIG_VAR(occlusion, double, c, s);
	MRPT_LOAD_CONFIG_VAR(supersampling, int, c, s);
	validate();
}

void RenderOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	c.write(
		s, "background", std::string(backgroundName(background)), -1, -1,
		"Flat, Textured or Cluttered");
	c.write(
		s, "background_grey", background_grey, -1, -1,
		"flat background level / texture mean [0..255]");
	c.write(s, "distractors", distractors, -1, -1, "number of distractor shapes (Cluttered only)");
	c.write(s, "black_bgr", bgrText(black_bgr), -1, -1, "printed black at gain 1, B G R [0..255]");
	c.write(s, "white_bgr", bgrText(white_bgr), -1, -1, "sheet white at gain 1, B G R [0..255]");
	c.write(
		s, "green_bgr", bgrText(green_bgr), -1, -1, "fluorescent green at gain 1, B G R [0..255]");
	c.write(s, "gain", gain, -1, -1, "illumination gain (> 0)");
	c.write(s, "gradient", gradient, -1, -1, "relative gain change across the image (0.5: +-25%)");
	c.write(
		s, "gradient_angle_rad", gradient_angle_rad, -1, -1,
		"direction of the gradient in the image [rad]");
	c.write(s, "noise_sigma", noise_sigma, -1, -1, "Gaussian pixel noise [grey levels]");
	c.write(s, "blur_sigma_px", blur_sigma_px, -1, -1, "Gaussian blur sigma [px]");
	c.write(s, "motion_blur_px", motion_blur_px, -1, -1, "linear motion blur length [px]");
	c.write(
		s, "motion_blur_angle_rad", motion_blur_angle_rad, -1, -1,
		"motion direction, counter-clockwise from +u [rad]");
	c.write(s, "jpeg_quality", jpeg_quality, -1, -1, "0 = no JPEG round trip, else 1..100");
	c.write(
		s, "occlusion", occlusion, -1, -1,
		"fraction of each reference square hidden by a grey bar [0..1]");
	c.write(
		s, "supersampling", supersampling, -1, -1, "samples per pixel side with lens distortion");
}

}  // namespace codemark::sim
