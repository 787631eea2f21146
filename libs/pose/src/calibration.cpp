#include <codemark/landmark/camera.h>
#include <codemark/landmark/text.h>
#include <codemark/pose/calibration.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace codemark::pose
{
namespace
{
/** What a calibration key's value must be. */
enum class Kind
{
	Positive,  //!< a finite number > 0
	NonNegative,  //!< a finite number >= 0
	Correlation,  //!< in (-1, 1)
	UnitCorrelation,  //!< in [0, 1)
	Table  //!< size:value pairs, both > 0, sizes increasing; may be empty
};

struct Key
{
	const char* name;
	Kind kind;
	double PoseOptions::*number = nullptr;	//!< the field of a number
	SigmaTable PoseOptions::*table = nullptr;  //!< the field of a table
	/** A key the format gained later: a file without it keeps loading, the
	 * key's model off (0, or an empty table). */
	bool optional = false;
};

Key number(const char* name, Kind kind, double PoseOptions::*field) { return {name, kind, field}; }
Key table(const char* name, SigmaTable PoseOptions::*field)
{
	return {name, Kind::Table, nullptr, field};
}
Key optional(Key k)
{
	k.optional = true;
	return k;
}

// PoseOptions' noise model (measurement.h documents each field).
const Key kKeys[] = {
	number("sigma_px", Kind::Positive, &PoseOptions::sigma_px),
	number("sigma_y_px", Kind::NonNegative, &PoseOptions::sigma_y_px),
	number("growth_x_px", Kind::NonNegative, &PoseOptions::growth_x_px),
	number("growth_y_px", Kind::NonNegative, &PoseOptions::growth_y_px),
	number("size_exponent_x", Kind::NonNegative, &PoseOptions::size_exponent_x),
	number("size_exponent_y", Kind::NonNegative, &PoseOptions::size_exponent_y),
	number("size_reference_px", Kind::Positive, &PoseOptions::size_reference_px),
	number("corr_x12", Kind::Correlation, &PoseOptions::corr_x12),
	number("corr_growth_x12", Kind::Correlation, &PoseOptions::corr_growth_x12),
	number("corr_y12", Kind::Correlation, &PoseOptions::corr_y12),
	number("corr_growth_y12", Kind::Correlation, &PoseOptions::corr_growth_y12),
	table("sigma_x_table", &PoseOptions::sigma_x_table),
	table("sigma_y_table", &PoseOptions::sigma_y_table),
	number("reference_noise_grey", Kind::NonNegative, &PoseOptions::reference_noise_grey),
	table("noise_sigma_x_table", &PoseOptions::noise_sigma_x_table),
	table("noise_sigma_y_table", &PoseOptions::noise_sigma_y_table),
	number("clipped_side_sigma_px", Kind::NonNegative, &PoseOptions::clipped_side_sigma_px),
	number(
		"clipped_side_correlation", Kind::UnitCorrelation, &PoseOptions::clipped_side_correlation),
	number("aligned_edge_ratio", Kind::NonNegative, &PoseOptions::aligned_edge_ratio),
	number("corner_midpoint_ratio", Kind::Positive, &PoseOptions::corner_midpoint_ratio),
	number("corner_tilt_ratio", Kind::Positive, &PoseOptions::corner_tilt_ratio),
	table("corner_tilt_ratio_table", &PoseOptions::corner_tilt_ratio_table),
	number("corner_tilt_noise_ratio", Kind::NonNegative, &PoseOptions::corner_tilt_noise_ratio),
	optional(number("band_ratio_x", Kind::NonNegative, &PoseOptions::band_ratio_x)),
	optional(number("band_ratio_y", Kind::NonNegative, &PoseOptions::band_ratio_y)),
	optional(table("band_floor_x_table", &PoseOptions::band_floor_x_table)),
	optional(table("band_floor_y_table", &PoseOptions::band_floor_y_table)),
};

std::string trimmed(const std::string& s)
{
	const auto a = s.find_first_not_of(" \t\r");
	if (a == std::string::npos) return {};
	return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

/** The value without a trailing comment ("//", or '#' / ';' after a blank). */
std::string withoutComment(std::string v)
{
	if (const auto c = v.find("//"); c != std::string::npos) v.resize(c);
	for (size_t k = 1; k < v.size(); ++k)
		if ((v[k] == '#' || v[k] == ';') && (v[k - 1] == ' ' || v[k - 1] == '\t'))
		{
			v.resize(k);
			break;
		}
	return trimmed(v);
}

/** Why \a value is not a \a kind, or empty when it is one. */
std::string checkValue(Kind kind, const std::string& value)
{
	if (kind == Kind::Table)
	{
		try
		{
			sigmaTableFromString(value);
			return {};
		}
		catch (const std::invalid_argument& e)
		{
			return e.what();
		}
	}
	const auto v = parseFiniteNumber(value);
	if (!v) return "not a finite number";
	switch (kind)
	{
		case Kind::Positive:
			return *v > 0 ? "" : "must be > 0";
		case Kind::NonNegative:
			return *v >= 0 ? "" : "must be >= 0";
		case Kind::Correlation:
			return std::abs(*v) < 1 ? "" : "a correlation must lie in (-1, 1)";
		case Kind::UnitCorrelation:
			return *v >= 0 && *v < 1 ? "" : "must lie in [0, 1)";
		default:
			return {};
	}
}

/** The shortest text of \a v that reads back as \a v. */
std::string exactText(double v)
{
	char buf[40];
	for (int digits = 6; digits <= 17; ++digits)
	{
		std::snprintf(buf, sizeof buf, "%.*g", digits, v);
		if (std::strtod(buf, nullptr) == v) break;
	}
	return buf;
}

std::string tableText(const SigmaTable& t)
{
	std::string s;
	for (const auto& [size, value] : t)
		s += (s.empty() ? "" : " ") + exactText(size) + ":" + exactText(value);
	return s;
}

/** \a o's value of \a k as calibration text. */
std::string valueText(const PoseOptions& o, const Key& k)
{
	return k.table ? tableText(o.*k.table) : exactText(o.*k.number);
}

const std::string kFolder = "calibration";
}  // namespace

const std::vector<std::string>& calibrationKeys()
{
	static const std::vector<std::string> keys = []
	{
		std::vector<std::string> k;
		for (const Key& key : kKeys) k.emplace_back(key.name);
		return k;
	}();
	return keys;
}

// A hand-written reader: MRPT's ini readers know no line numbers, take
// "0.2x" as 0.2, and cannot tell a key set empty (an unused table) from a
// missing one.
PoseOptions loadCalibration(const std::string& path, const PoseOptions& base)
{
	std::ifstream in(path);
	if (!in) throw std::runtime_error(path + ": cannot open the calibration file");
	std::string section;
	bool has_pose = false;
	std::map<std::string, int> line_of;
	std::map<std::string, std::string> values;
	int n = 0;
	for (std::string line; std::getline(in, line);)
	{
		++n;
		const std::string t = trimmed(line);
		if (t.empty() || t[0] == '#' || t[0] == ';' || t.rfind("//", 0) == 0) continue;
		const std::string where = path + ":" + std::to_string(n) + ": ";
		if (t[0] == '[')
		{
			const auto close = t.find(']');
			if (close == std::string::npos)
				throw std::invalid_argument(where + "expected a section header '[name]'");
			section = trimmed(t.substr(1, close - 1));
			has_pose = has_pose || section == "pose";
			continue;
		}
		if (section != "pose") continue;  // other sections are not the calibration's
		const auto eq = t.find('=');
		if (eq == std::string::npos)
			throw std::invalid_argument(where + "expected 'key = value', got '" + t + "'");
		const std::string key = trimmed(t.substr(0, eq));
		const std::string value = withoutComment(t.substr(eq + 1));
		const auto known = std::find_if(
			std::begin(kKeys), std::end(kKeys), [&](const Key& k) { return key == k.name; });
		if (known == std::end(kKeys))
			throw std::invalid_argument(
				where + "unknown key '" + key +
				"' in [pose] (a calibration holds the noise model's keys only; "
				"docs/calibration.md lists them)");
		if (line_of.count(key))
			throw std::invalid_argument(
				where + "key '" + key + "' set twice (first on line " +
				std::to_string(line_of[key]) + ")");
		if (const std::string why = checkValue(known->kind, value); !why.empty())
			throw std::invalid_argument(where + key + " = '" + value + "': " + why);
		line_of[key] = n;
		values[key] = value;
	}
	if (!has_pose) throw std::runtime_error(path + ": no [pose] section (not a calibration file)");
	for (const Key& k : kKeys)
		if (!line_of.count(k.name) && !k.optional)
			throw std::invalid_argument(
				path + ": [pose] misses key '" + k.name +
				"' (a calibration sets every key of the noise model; docs/calibration.md)");
	PoseOptions o = base;
	for (const Key& k : kKeys)
		if (!line_of.count(k.name))
		{
			if (k.table)
				(o.*k.table).clear();
			else
				o.*k.number = 0;
		}
		else if (k.table)
			o.*k.table = sigmaTableFromString(values[k.name]);
		else
			o.*k.number = *parseFiniteNumber(values[k.name]);
	try
	{
		o.validate();
	}
	catch (const std::invalid_argument& e)
	{
		throw std::invalid_argument(path + ": " + e.what());
	}
	return o;
}

void saveCalibration(
	const std::string& path, const PoseOptions& o, const std::vector<std::string>& provenance)
{
	o.validate();
	std::ostringstream s;
	for (const auto& line : provenance)
	{
		std::istringstream lines(line);
		for (std::string l; std::getline(lines, l);) s << "# " << l << "\n";
	}
	s << "# The noise model of P (docs/calibration.md).\n[pose]\n";
	for (const Key& k : kKeys)
	{
		const std::string v = valueText(o, k);
		s << k.name << " =" << (v.empty() ? "" : " ") << v << "\n";
	}
	std::ofstream out(path);
	out << s.str();
	if (!out.flush()) throw std::runtime_error(path + ": cannot write the calibration file");
}

std::string shippedCalibrationPath(const std::string& name)
{
	const std::string relative = kFolder + "/" + name + ".ini";
	std::string p = findShareFile(relative);
	if (!p.empty()) return p;
	std::string looked;
	for (const auto& d : shareSearchDirs()) looked += (looked.empty() ? "" : ", ") + d;
	throw std::runtime_error(
		"shipped calibration '" + name + "' not found: looked for " + relative + " in " + looked +
		" (set CODEMARK_SHARE_DIR to the folder holding calibration/)");
}

std::vector<std::string> shippedCalibrationNames()
{
	std::vector<std::string> names;
	for (const auto& d : shareSearchDirs())
	{
		std::error_code ec;
		const std::filesystem::path folder = std::filesystem::path(d) / kFolder;
		for (const auto& e : std::filesystem::directory_iterator(folder, ec))
			if (e.path().extension() == ".ini") names.push_back(e.path().stem().string());
		if (!names.empty()) break;
	}
	std::sort(names.begin(), names.end());
	names.erase(std::unique(names.begin(), names.end()), names.end());
	return names;
}

std::string resolveCalibration(const std::string& path_or_name)
{
	const bool word = path_or_name.find('/') == std::string::npos &&
					  path_or_name.find(".ini") == std::string::npos;
	if (word && !std::filesystem::exists(path_or_name)) return shippedCalibrationPath(path_or_name);
	return path_or_name;
}

PoseOptions scaledNoiseModel(const PoseOptions& in, double factor)
{
	if (!(factor > 0) || !std::isfinite(factor))
		throw std::invalid_argument("scaledNoiseModel: the factor must be finite and > 0");
	PoseOptions o = in;
	o.sigma_px *= factor;
	o.sigma_y_px *= factor;
	o.growth_x_px *= factor;
	o.growth_y_px *= factor;
	o.clipped_side_sigma_px *= factor;
	o.band_ratio_x *= factor;
	o.band_ratio_y *= factor;
	for (auto* t :
		 {&o.sigma_x_table, &o.sigma_y_table, &o.noise_sigma_x_table, &o.noise_sigma_y_table,
		  &o.band_floor_x_table, &o.band_floor_y_table})
		for (auto& entry : *t) entry.second *= factor;
	return o;
}

}  // namespace codemark::pose
