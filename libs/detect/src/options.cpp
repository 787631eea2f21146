#include <codemark/detect/options.h>
#include <codemark/landmark/text.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileBase.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace codemark::detect
{
namespace
{
/** A key refused while loading or validating: std::invalid_argument, as
 * loadFromConfigFile() and validate() promise, that remembers the key so
 * that load() can name the file's line (iniWhere()). */
class KeyError : public std::invalid_argument
{
   public:
	KeyError(std::string key_, const std::string& what)
		: std::invalid_argument(what), key(std::move(key_))
	{
	}
	std::string key;
};

void require(bool ok, const char* name, const char* rule)
{
	if (!ok) throw KeyError(name, std::string("detector option ") + name + " must be " + rule);
}

// Keys are "<block>.<field>", e.g. segmentation.step_px. A value that is
// not one of its type is refused with the key and the text: MRPT's
// read_bool / read_int / read_double take "maybe" as false and "3x" as 3.
template <typename T>
void readKey(
	const mrpt::config::CConfigFileBase& c, const std::string& s, const std::string& key, T& v)
{
	std::string text = c.read_string(s, key, "", false);
	const auto first = text.find_first_not_of(" \t\r");
	if (first == std::string::npos) return;	 // absent: the default stays
	text = text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
	const auto refuse = [&](const char* what)
	{ throw KeyError(key, key + " = '" + text + "' is not " + what); };
	if constexpr (std::is_same_v<T, bool>)
	{
		const auto b = parseIniBoolean(text);
		if (!b) refuse("a boolean (true/false)");
		v = *b;
	}
	else
	{
		std::istringstream in(text);
		T parsed{};
		in >> parsed;
		if (!in || !(in >> std::ws).eof())
			refuse(std::is_integral_v<T> ? "an integer" : "a number");
		v = parsed;
	}
}

template <typename T>
void writeKey(
	mrpt::config::CConfigFileBase& c, const std::string& s, const std::string& key, const T& v)
{
	c.write(s, key, v, -1, -1);
}

/** Applies \a f(key, field) to every option, so load and save cannot
 * drift apart. */
template <typename Options, typename F>
void forEachField(Options& o, F&& f)
{
	f("segmentation.step_px", o.segmentation.step_px);
	f("segmentation.box_smoothing", o.segmentation.box_smoothing);
	f("segmentation.min_intensity", o.segmentation.min_intensity);
	f("segmentation.hue_min_deg", o.segmentation.hue_min_deg);
	f("segmentation.hue_max_deg", o.segmentation.hue_max_deg);
	f("segmentation.min_saturation", o.segmentation.min_saturation);
	f("components.min_area_px", o.components.min_area_px);
	f("components.max_area_fraction", o.components.max_area_fraction);
	f("components.max_compactness", o.components.max_compactness);
	f("components.max_elongation", o.components.max_elongation);
	f("components.roi_grow_fraction", o.components.roi_grow_fraction);
	f("components.roi_grow_px", o.components.roi_grow_px);
	f("components.max_frame_ratio", o.components.max_frame_ratio);
	f("components.max_side_frame_ratio", o.components.max_side_frame_ratio);
	f("components.frame_blur_px", o.components.frame_blur_px);
	f("components.min_centre_cell_px", o.components.min_centre_cell_px);
	f("components.max_candidates", o.components.max_candidates);
	f("edgels.min_gradient", o.edgels.min_gradient);
	f("edgels.rel_gradient", o.edgels.rel_gradient);
	f("edgels.min_edgels", o.edgels.min_edgels);
	f("edgels.max_roi_px", o.edgels.max_roi_px);
	f("segments.min_rel_length", o.segments.min_rel_length);
	f("segments.max_width_px", o.segments.max_width_px);
	f("quads.max_gap_px", o.quads.max_gap_px);
	f("quads.max_gap_rel", o.quads.max_gap_rel);
	f("quads.min_side_px", o.quads.min_side_px);
	f("subpixel.corner_margin_px", o.subpixel.corner_margin_px);
	f("subpixel.search_px", o.subpixel.search_px);
	f("subpixel.response_floor", o.subpixel.response_floor);
	f("subpixel.reach_px", o.subpixel.reach_px);
	f("subpixel.saturation_level", o.subpixel.saturation_level);
	f("subpixel.min_frame_px_centroid", o.subpixel.min_frame_px_centroid);
	f("subpixel.clipped_fraction", o.subpixel.clipped_fraction);
	f("subpixel.min_rise_rb", o.subpixel.min_rise_rb);
	f("subpixel.outlier_sigmas", o.subpixel.outlier_sigmas);
	f("subpixel.min_outlier_px", o.subpixel.min_outlier_px);
	f("subpixel.min_support", o.subpixel.min_support);
	f("subpixel.max_rms_px", o.subpixel.max_rms_px);
	f("subpixel.max_rms_grey", o.subpixel.max_rms_grey);
	f("code.patch_fraction", o.code.patch_fraction);
	f("code.min_contrast", o.code.min_contrast);
	f("code.max_black_ratio", o.code.max_black_ratio);
	f("code.max_side_black_ratio", o.code.max_side_black_ratio);
	f("code.max_frame_cell_ratio", o.code.max_frame_cell_ratio);
	f("code.min_margin", o.code.min_margin);
	f("code.border_px", o.code.border_px);
}
}  // namespace

void DetectorOptions::validate() const
{
	const auto& s = segmentation;
	require(s.step_px >= 1 && s.step_px <= 4, "segmentation.step_px", "in 1..4");
	require(
		s.min_intensity >= 0 && s.min_intensity < 255, "segmentation.min_intensity", "in [0, 255)");
	require(
		s.hue_min_deg >= 60 && s.hue_min_deg < s.hue_max_deg && s.hue_max_deg <= 180,
		"segmentation.hue_min_deg/hue_max_deg", "60 <= min < max <= 180");
	require(
		s.min_saturation >= 0 && s.min_saturation < 1, "segmentation.min_saturation", "in [0, 1)");
	const auto& c = components;
	require(c.min_area_px >= 1, "components.min_area_px", ">= 1");
	require(
		c.max_area_fraction > 0 && c.max_area_fraction <= 1, "components.max_area_fraction",
		"in (0, 1]");
	require(c.max_compactness >= 1.0 / 6, "components.max_compactness", ">= 1/6 (a filled square)");
	require(c.max_elongation >= 1, "components.max_elongation", ">= 1");
	require(c.roi_grow_fraction >= 0 && c.roi_grow_px >= 0, "components.roi_grow_*", ">= 0");
	require(
		c.max_frame_ratio > 0 && c.max_side_frame_ratio >= c.max_frame_ratio,
		"components.max_frame_ratio/max_side_frame_ratio",
		"> 0 and max_side_frame_ratio >= max_frame_ratio");
	require(
		c.frame_blur_px >= 0 && c.frame_blur_px <= 10, "components.frame_blur_px", "in [0, 10]");
	require(c.max_candidates >= 1, "components.max_candidates", ">= 1");
	require(c.min_centre_cell_px >= 0, "components.min_centre_cell_px", ">= 0");
	require(
		edgels.min_gradient > 0 && edgels.rel_gradient >= 0, "edgels.min_gradient/rel_gradient",
		"> 0 / >= 0");
	require(edgels.min_edgels >= 2, "edgels.min_edgels", ">= 2");
	require(edgels.max_roi_px >= 16, "edgels.max_roi_px", ">= 16");
	require(
		segments.min_rel_length > 0 && segments.min_rel_length <= 1, "segments.min_rel_length",
		"in (0, 1]");
	require(segments.max_width_px > 0, "segments.max_width_px", "> 0");
	require(quads.max_gap_px >= 0 && quads.max_gap_rel >= 0, "quads.max_gap_*", ">= 0");
	require(quads.min_side_px >= 2, "quads.min_side_px", ">= 2");
	const auto& p = subpixel;
	require(p.corner_margin_px >= 0, "subpixel.corner_margin_px", ">= 0");
	require(p.search_px >= 1 && p.search_px <= 10, "subpixel.search_px", "in 1..10");
	require(p.reach_px >= 1 && p.reach_px <= 10, "subpixel.reach_px", "in 1..10");
	require(
		p.saturation_level >= 1 && p.saturation_level <= 256, "subpixel.saturation_level",
		"in 1..256 (256: never)");
	require(p.min_frame_px_centroid >= 0, "subpixel.min_frame_px_centroid", ">= 0");
	require(p.min_rise_rb > 0, "subpixel.min_rise_rb", "> 0");
	require(
		p.clipped_fraction >= 0 && p.clipped_fraction <= 1, "subpixel.clipped_fraction",
		"in [0, 1]");
	require(p.response_floor >= 0 && p.response_floor < 1, "subpixel.response_floor", "in [0, 1)");
	require(
		p.outlier_sigmas > 0 && p.min_outlier_px > 0, "subpixel.outlier_sigmas/min_outlier_px",
		"> 0");
	require(p.min_support >= 3, "subpixel.min_support", ">= 3");
	require(p.max_rms_px > 0, "subpixel.max_rms_px", "> 0");
	require(p.max_rms_grey >= 0, "subpixel.max_rms_grey", ">= 0");
	require(
		code.patch_fraction > 0 && code.patch_fraction <= 1, "code.patch_fraction", "in (0, 1]");
	require(code.min_contrast >= 0, "code.min_contrast", ">= 0");
	require(
		code.max_black_ratio > 0 && code.max_black_ratio < 1, "code.max_black_ratio", "in (0, 1)");
	require(
		code.max_side_black_ratio >= code.max_black_ratio && code.max_side_black_ratio < 1,
		"code.max_side_black_ratio", "in [max_black_ratio, 1)");
	require(
		code.max_frame_cell_ratio > 0 && code.max_frame_cell_ratio <= 1,
		"code.max_frame_cell_ratio", "in (0, 1]");
	require(code.min_margin >= 0 && code.min_margin < 0.5, "code.min_margin", "in [0, 0.5)");
	require(std::isfinite(code.border_px), "code.border_px", "finite");
}

void DetectorOptions::loadFromConfigFile(
	const mrpt::config::CConfigFileBase& source, const std::string& section)
{
	// A key the detector does not read (a misspelling, an option that no
	// longer exists) is refused, never silently ignored.
	std::vector<std::string> keys;
	source.getAllKeys(section, keys);
	for (const auto& k : keys)
	{
		bool known = false;
		forEachField(*this, [&](const char* key, const auto&) { known = known || k == key; });
		if (!known)
			throw KeyError(
				k, "unknown key '" + k +
					   "' (not a detector option; share/codemark/detector.ini lists them all)");
	}
	forEachField(*this, [&](const char* key, auto& v) { readKey(source, section, key, v); });
	validate();
}

void DetectorOptions::saveToConfigFile(
	mrpt::config::CConfigFileBase& target, const std::string& section) const
{
	forEachField(
		const_cast<DetectorOptions&>(*this),
		[&](const char* key, const auto& v) { writeKey(target, section, key, v); });
}

DetectorOptions DetectorOptions::load(const std::string& path, const std::string& section)
{
	if (!std::ifstream(path).good())
		throw std::runtime_error(path + ": cannot open the detector options file");
	mrpt::config::CConfigFile cfg(path);
	if (!cfg.sectionExists(section))
		throw std::runtime_error(path + ": no [" + section + "] section");
	DetectorOptions o;
	try
	{
		o.loadFromConfigFile(cfg, section);
	}
	catch (const KeyError& e)
	{
		throw std::runtime_error(iniWhere(path, section, e.key) + "[" + section + "]: " + e.what());
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error(path + ": [" + section + "]: " + e.what());
	}
	return o;
}

}  // namespace codemark::detect
