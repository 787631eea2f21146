#include <codemark/landmark/text.h>
#include <codemark/sim/render.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "background.h"

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

/** A numeric key that may be drawn per frame ("lo hi"): its field (double
 * or int), its physically meaningful range and its meaning. */
struct DrawableKey
{
	const char* key;
	double RenderOptions::*real;
	int RenderOptions::*whole;
	double lo, hi;
	const char* doc;
	double get(const RenderOptions& o) const { return real ? o.*real : o.*whole; }
	void set(RenderOptions& o, double v) const
	{
		if (real)
			o.*real = v;
		else
			o.*whole = static_cast<int>(std::lround(v));
	}
};

using O = RenderOptions;
const DrawableKey kDrawable[] = {
	{"blur_sigma_px", &O::blur_sigma_px, nullptr, 0, 100, "Gaussian optical blur sigma [px]"},
	{"defocus_radius_px", &O::defocus_radius_px, nullptr, 0, 20, "defocus disc radius [px]"},
	{"ca_red_px", &O::ca_red_px, nullptr, -5, 5,
	 "lateral CA: R's radial shift against G at the farthest corner [px]"},
	{"ca_blue_px", &O::ca_blue_px, nullptr, -5, 5,
	 "lateral CA: B's radial shift against G at the farthest corner [px]"},
	{"vignetting", &O::vignetting, nullptr, 0, 0.9, "loss of light at the farthest corner"},
	{"exposure", &O::exposure, nullptr, 0.05, 20, "exposure gain of the sensor signal"},
	{"wb_red", &O::wb_red, nullptr, 0.25, 4, "white-balance gain of R against G"},
	{"wb_blue", &O::wb_blue, nullptr, 0.25, 4, "white-balance gain of B against G"},
	{"noise_sigma", &O::noise_sigma, nullptr, 0, 1e4, "Gaussian pixel noise [grey levels]"},
	{"full_well_e", &O::full_well_e, nullptr, 0, 1e7,
	 "electrons at full scale; 0 = no shot and read noise"},
	{"read_noise_e", &O::read_noise_e, nullptr, 0, 1e4, "read noise RMS [e-]"},
	{"gamma", &O::gamma, nullptr, 1, 4, "exponent of transfer = gamma"},
	{"filmic_strength", &O::filmic_strength, nullptr, 0, 0.9,
	 "strength of transfer = filmic's S-curve"},
	{"unsharp_sigma_px", &O::unsharp_sigma_px, nullptr, 0.3, 20, "unsharp mask sigma [px]"},
	{"unsharp_amount", &O::unsharp_amount, nullptr, 0, 5, "unsharp mask amount; 0 = none"},
	{"jpeg_quality", nullptr, &O::jpeg_quality, 0, 100, "0 = no JPEG round trip, else 1..100"},
};

const DrawableKey* drawableKey(const std::string& key)
{
	for (const auto& k : kDrawable)
		if (key == k.key) return &k;
	return nullptr;
}

/** The choice keys, the names one of them draws from with "any", and how
 * each sets and names its member of RenderOptions. */
struct ChoiceKey
{
	const char* key;
	std::vector<std::string> any;
	void (*set)(RenderOptions&, const std::string& key, const std::string& name);
	std::string (*name)(const RenderOptions&);
};
const ChoiceKey kChoices[] = {
	{"bayer",
	 {"RGGB", "BGGR", "GRBG", "GBRG"},
	 [](RenderOptions& o, const std::string& k, const std::string& n)
	 { o.bayer = bayerFromName(n, k); },
	 [](const RenderOptions& o) -> std::string { return bayerName(o.bayer); }},
	{"demosaic",
	 {"bilinear", "vng", "edge-aware"},
	 [](RenderOptions& o, const std::string& k, const std::string& n)
	 { o.demosaic = demosaicFromName(n, k); },
	 [](const RenderOptions& o) -> std::string { return demosaicName(o.demosaic); }},
	{"transfer",
	 {"linear", "srgb", "gamma", "filmic"},
	 [](RenderOptions& o, const std::string& k, const std::string& n)
	 { o.transfer = transferFromName(n, k); },
	 [](const RenderOptions& o) -> std::string { return transferName(o.transfer); }},
	{"chroma_subsampling",
	 {"none", "422", "420"},
	 [](RenderOptions& o, const std::string& k, const std::string& n)
	 { o.chroma_subsampling = chromaFromName(n, k); },
	 [](const RenderOptions& o) -> std::string { return chromaName(o.chroma_subsampling); }},
};

const ChoiceKey& choiceKey(const std::string& key)
{
	for (const auto& k : kChoices)
		if (key == k.key) return k;
	throw std::logic_error("not a choice key: " + key);
}

void setChoice(RenderOptions& o, const std::string& key, const std::string& name)
{
	choiceKey(key).set(o, key, name);
}

template <typename D>
void dropDraw(std::vector<D>& draws, const std::string& key)
{
	draws.erase(
		std::remove_if(draws.begin(), draws.end(), [&](const D& d) { return d.key == key; }),
		draws.end());
}

std::vector<std::string> tokens(std::string text)
{
	// MRPT keeps a trailing ';' or '#' comment in a value.
	const auto cut = text.find_first_of(";#");
	if (cut != std::string::npos) text.resize(cut);
	std::istringstream in(text);
	std::vector<std::string> out;
	for (std::string t; in >> t;) out.push_back(t);
	return out;
}

/** A value that is not numbers at all: the file's line is worth naming. */
[[noreturn]] void badIni(
	const std::string& section, const std::string& key, const std::string& value,
	const std::string& what)
{
	throw IniValueError(section, key, "[" + section + "] " + key + " = '" + value + "': " + what);
}

/** A value out of its range or an unknown name (std::invalid_argument, as
 * validate() throws). */
[[noreturn]] void badValue(
	const std::string& key, const std::string& value, const std::string& what)
{
	bad(key, "= '" + value + "': " + what);
}

/** Reads the drawable and choice keys that [\a s] sets: one value sets the
 * field (and ends a draw of it), "lo hi" or several names draw per frame. */
void loadDrawableKeys(
	RenderOptions& o, const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	for (const auto& k : kDrawable)
	{
		const std::string text = c.read_string(s, k.key, "");
		const auto tok = tokens(text);
		if (tok.empty()) continue;
		std::vector<double> v;
		for (const auto& t : tok)
		{
			const auto x = parseFiniteNumber(t);
			if (!x) badIni(s, k.key, text, "not a finite number");
			if (!k.real && *x != std::round(*x)) badIni(s, k.key, text, "not a whole number");
			v.push_back(*x);
		}
		if (v.size() > 2) badIni(s, k.key, text, "one number, or two (lo hi) drawn per frame");
		for (double x : v)
			if (x < k.lo || x > k.hi)
			{
				std::ostringstream m;
				m << "out of range [" << k.lo << ", " << k.hi << "]";
				badValue(k.key, text, m.str());
			}
		dropDraw(o.range_draws, k.key);
		if (v.size() == 2)
		{
			if (v[0] > v[1]) badValue(k.key, text, "a range must be 'lo hi' with lo <= hi");
			o.range_draws.push_back({k.key, v[0], v[1]});
			k.set(o, 0.5 * (v[0] + v[1]));
		}
		else
			k.set(o, v[0]);
	}
	for (const auto& k : kChoices)
	{
		const std::string text = c.read_string(s, k.key, "");
		auto names = tokens(text);
		if (names.empty()) continue;
		if (names.size() == 1 && (names[0] == "any" || names[0] == "ANY")) names = k.any;
		try
		{
			for (const auto& n : names) k.set(o, k.key, n);
		}
		catch (const std::invalid_argument& e)
		{
			throw std::invalid_argument(std::string(e.what()) + " (or several names, or any)");
		}
		dropDraw(o.choice_draws, k.key);
		if (names.size() > 1)
		{
			o.choice_draws.push_back({k.key, names});
			k.set(o, k.key, names[0]);
		}
	}
}

/** The presets as [render] keys (RenderOptions::applyPreset documents them). */
struct Preset
{
	const char* name;
	const char* keys;
};
const Preset kPresets[] = {
	{"linear", "full_well_e = 10000\nread_noise_e = 5\n"},
	{"machine-vision",
	 "blur_sigma_px = 0.5\nvignetting = 0.05\nfull_well_e = 20000\nread_noise_e = 3\n"},
	{"webcam",
	 "blur_sigma_px = 0.6\nca_red_px = 0.3\nca_blue_px = -0.3\nvignetting = 0.2\n"
	 "wb_red = 1.05\nwb_blue = 0.95\nfull_well_e = 8000\nread_noise_e = 6\n"
	 "bayer = RGGB\ndemosaic = bilinear\ntransfer = srgb\n"
	 "unsharp_sigma_px = 1.0\nunsharp_amount = 0.5\njpeg_quality = 85\n"},
	{"phone",
	 "blur_sigma_px = 0.5\nca_red_px = 0.2\nca_blue_px = -0.2\nvignetting = 0.1\n"
	 "full_well_e = 5000\nread_noise_e = 3\nbayer = BGGR\ndemosaic = edge-aware\n"
	 "transfer = filmic\nfilmic_strength = 0.25\n"
	 "unsharp_sigma_px = 1.0\nunsharp_amount = 0.9\njpeg_quality = 75\n"},
	{"family",
	 "blur_sigma_px = 0 1.2\ndefocus_radius_px = 0 1.5\nca_red_px = -0.7 0.7\n"
	 "ca_blue_px = -0.7 0.7\nvignetting = 0 0.35\nexposure = 0.5 1.5\n"
	 "wb_red = 0.75 1.3\nwb_blue = 0.75 1.3\nfull_well_e = 5000 20000\n"
	 "read_noise_e = 2 10\nbayer = any\ndemosaic = any\ntransfer = any\n"
	 "gamma = 1.8 2.6\nfilmic_strength = 0 0.35\nunsharp_sigma_px = 0.6 1.5\n"
	 "unsharp_amount = 0 1\njpeg_quality = 60 95\n"},
};
}  // namespace

std::vector<std::string> RenderOptions::presetNames()
{
	std::vector<std::string> out;
	for (const auto& p : kPresets) out.emplace_back(p.name);
	return out;
}

std::string RenderOptions::presetKeys(const std::string& name)
{
	for (const auto& p : kPresets)
		if (name == p.name) return p.keys;
	std::string names;
	for (const auto& p : kPresets) names += (names.empty() ? "" : ", ") + std::string(p.name);
	throw std::invalid_argument(
		"render option 'preset' must be one of " + names + ", got '" + name + "'");
}

void RenderOptions::applyPreset(const std::string& name)
{
	const std::string keys = presetKeys(name);
	// The camera's keys start from their defaults; the scene's stay.
	const RenderOptions d;
	for (const auto& k : kDrawable) k.set(*this, k.get(d));
	for (const auto& k : kChoices) k.set(*this, k.key, k.name(d));
	range_draws.clear();
	choice_draws.clear();
	mrpt::config::CConfigFileMemory mem;
	mem.setContent("[p]\n" + keys);
	loadDrawableKeys(*this, mem, "p");
	preset = name;
}

bool RenderOptions::hasCameraStages() const
{
	const RenderOptions d;
	for (const auto& k : kDrawable)
	{
		const std::string key = k.key;
		if (key != "blur_sigma_px" && key != "noise_sigma" && key != "jpeg_quality" &&
			k.get(*this) != k.get(d))
			return true;
	}
	return bayer != d.bayer || transfer != d.transfer ||
		   chroma_subsampling != d.chroma_subsampling || !range_draws.empty() ||
		   !choice_draws.empty();
}

RenderOptions RenderOptions::drawn(uint64_t seed) const
{
	RenderOptions o = *this;
	if (range_draws.empty() && choice_draws.empty()) return o;
	cv::RNG rng(detail::streamSeed(seed, 7));
	for (const auto& d : range_draws)
	{
		const double u = rng.uniform(0.0, 1.0);
		drawableKey(d.key)->set(o, d.lo + u * (d.hi - d.lo));
	}
	for (const auto& d : choice_draws)
		setChoice(o, d.key, d.names[rng.uniform(0, static_cast<int>(d.names.size()))]);
	o.range_draws.clear();
	o.choice_draws.clear();
	return o;
}

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
	checkRange("motion_blur_px", motion_blur_px, 0, 500);
	checkRange("motion_blur_angle_rad", motion_blur_angle_rad, -1e3, 1e3);
	if (jpeg_quality < 0 || jpeg_quality > 100)
		bad("jpeg_quality", "must be in 0..100 (0 = no JPEG), got " + std::to_string(jpeg_quality));
	for (const auto& k : kDrawable) checkRange(k.key, k.get(*this), k.lo, k.hi);
	for (const auto& d : range_draws)
	{
		const DrawableKey* k = drawableKey(d.key);
		if (!k) bad(d.key, "cannot be drawn per frame");
		checkRange(d.key, d.lo, k->lo, k->hi);
		checkRange(d.key, d.hi, d.lo, k->hi);
	}
	for (const auto& d : choice_draws)
	{
		if (d.names.empty()) bad(d.key, "draws from no names");
		RenderOptions probe;
		for (const auto& n : d.names) setChoice(probe, d.key, n);
	}
	checkRange("occlusion", occlusion, 0, 1);
	if (supersampling < 1 || supersampling > 64)
		bad("supersampling", "must be in 1..64, got " + std::to_string(supersampling));
}

void RenderOptions::loadFromConfigFile(
	const mrpt::config::CConfigFileBase& source, const std::string& section)
{
	const auto& c = source;
	const std::string& s = section;
	// MRPT's readers take "abc" as 0 and "2px" as 2: check the numbers first.
	requireIniNumbers(
		c, s,
		{"background_grey", "gain", "gradient", "gradient_angle_rad", "motion_blur_px",
		 "motion_blur_angle_rad", "occlusion"});
	requireIniNumbers(c, s, {"distractors", "supersampling"}, true);
	// The preset first, so that the section's own keys override it.
	const auto preset_name = tokens(c.read_string(s, "preset", ""));
	if (preset_name.size() > 1)
		badIni(s, "preset", c.read_string(s, "preset", ""), "one preset name");
	if (!preset_name.empty()) applyPreset(preset_name[0]);
	loadDrawableKeys(*this, c, s);
	background = backgroundFromName(c.read_string(s, "background", backgroundName(background)));
	MRPT_LOAD_CONFIG_VAR(background_grey, double, c, s);
	MRPT_LOAD_CONFIG_VAR(distractors, int, c, s);
	black_bgr = readBgr(c, s, "black_bgr", black_bgr);
	white_bgr = readBgr(c, s, "white_bgr", white_bgr);
	green_bgr = readBgr(c, s, "green_bgr", green_bgr);
	MRPT_LOAD_CONFIG_VAR(gain, double, c, s);
	MRPT_LOAD_CONFIG_VAR(gradient, double, c, s);
	MRPT_LOAD_CONFIG_VAR(gradient_angle_rad, double, c, s);
	MRPT_LOAD_CONFIG_VAR(motion_blur_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(motion_blur_angle_rad, double, c, s);
	MRPT_LOAD_CONFIG_VAR(occlusion, double, c, s);
	MRPT_LOAD_CONFIG_VAR(supersampling, int, c, s);
	validate();
}

void RenderOptions::saveToConfigFile(
	mrpt::config::CConfigFileBase& target, const std::string& section) const
{
	auto& c = target;
	const std::string& s = section;
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
	c.write(s, "motion_blur_px", motion_blur_px, -1, -1, "linear motion blur length [px]");
	c.write(
		s, "motion_blur_angle_rad", motion_blur_angle_rad, -1, -1,
		"motion direction, counter-clockwise from +u [rad]");
	c.write(
		s, "occlusion", occlusion, -1, -1,
		"fraction of each reference square hidden by a grey bar [0..1]");
	c.write(
		s, "supersampling", supersampling, -1, -1, "samples per pixel side with lens distortion");
	// The camera pipeline; a key drawn per frame is written as "lo hi".
	if (!preset.empty())
		c.write(s, "preset", preset, -1, -1, "camera preset (the keys below override it)");
	for (const auto& k : kDrawable)
	{
		std::ostringstream v;
		v << k.get(*this);
		for (const auto& d : range_draws)
			if (d.key == k.key)
			{
				v.str("");
				v << d.lo << " " << d.hi;
			}
		c.write(s, k.key, v.str(), -1, -1, k.doc);
	}
	for (const auto& k : kChoices)
	{
		std::string v = k.name(*this);
		for (const auto& d : choice_draws)
			if (d.key == k.key)
			{
				v.clear();
				for (const auto& n : d.names) v += (v.empty() ? "" : " ") + n;
			}
		c.write(s, k.key, v, -1, -1, "one name, several drawn per frame, or any");
	}
}

}  // namespace codemark::sim
