// codemark-bench: the benchmark ini (share/codemark/bench.ini documents it).
#include <codemark/filters/localizer.h>
#include <codemark/landmark/camera.h>
#include <codemark/landmark/text.h>
#include <codemark/pipeline/pipeline.h>
#include <mrpt/config/CConfigFile.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "bench.h"

namespace codemark::bench
{
namespace fs = std::filesystem;

namespace
{
std::string trim(const std::string& s)
{
	const auto a = s.find_first_not_of(" \t\r\n");
	if (a == std::string::npos) return {};
	return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

// "FILE:LINE: [SECTION] KEY: what" (the line where the file sets KEY; the
// file alone when it does not), "FILE: [SECTION]: what" without a key.
[[noreturn]] void fail(
	const std::string& file, const std::string& section, const std::string& key,
	const std::string& what)
{
	if (!key.empty())
		throw std::runtime_error(
			iniWhere(file, section, key) + "[" + section + "] " + key + ": " + what);
	std::string where = file;
	if (!section.empty()) where += ": [" + section + "]";
	throw std::runtime_error(where + ": " + what);
}

// A positive finite number, the whole value consumed.
double positiveNumber(
	const mrpt::config::CConfigFileBase& c, const std::string& file, const std::string& section,
	const std::string& key, double fallback)
{
	if (!c.keyExists(section, key)) return fallback;
	const std::string v = trim(c.read_string(section, key, ""));
	char* end = nullptr;
	const double d = std::strtod(v.c_str(), &end);
	if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(d) || !(d > 0))
		fail(file, section, key, "'" + v + "' is not a positive number");
	return d;
}
}  // namespace

std::vector<std::string> parseMethods(const std::string& list, const std::string& what)
{
	std::vector<std::string> out;
	std::stringstream ss(list);
	std::string m;
	while (std::getline(ss, m, ','))
	{
		m = trim(m);
		if (m.empty()) continue;
		const auto& k = filters::localizationMethods();
		if (std::find(k.begin(), k.end(), m) == k.end())
			throw std::invalid_argument(
				what + ": unknown method '" + m + "' (expected ekf, ekf-pose, ekf-slam or pf)");
		if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
	}
	if (out.empty()) throw std::invalid_argument(what + ": no method given");
	return out;
}

BenchConfig loadBenchConfig(const std::string& path)
{
	if (!std::ifstream(path).good()) fail(path, "", "", "cannot open the benchmark ini");
	mrpt::config::CConfigFile c(path);
	BenchConfig cfg;
	cfg.file = path;
	const fs::path ini_dir = fs::absolute(fs::path(path)).parent_path();
	fs::path data_dir = ini_dir;

	std::vector<std::string> sections;
	c.getAllSections(sections);
	static const std::set<std::string> bench_keys{
		"methods", "config_dir", "data_dir", "min_span_px", "rpe_interval_s"};
	static const std::set<std::string> dataset_keys{"rawlog", "map", "gt", "camera", "calibration"};
	for (const auto& s : sections)
	{
		if (s.empty()) continue;  // keys before any section
		const bool is_bench = s == "bench", is_dataset = s.rfind("dataset:", 0) == 0;
		if (!is_bench && !is_dataset)
			fail(path, s, "", "unknown section (expected [bench] or [dataset:NAME])");
		std::vector<std::string> keys;
		c.getAllKeys(s, keys);
		for (const auto& k : keys)
			if (!(is_bench ? bench_keys : dataset_keys).count(k))
				fail(
					path, s, k,
					is_bench ? "unknown key (expected methods, config_dir, data_dir, "
							   "min_span_px or rpe_interval_s)"
							 : "unknown key (expected rawlog, map, gt, camera or calibration)");
	}

	if (c.sectionExists("bench"))
	{
		if (c.keyExists("bench", "methods"))
		{
			try
			{
				cfg.methods = parseMethods(c.read_string("bench", "methods", ""), "methods");
			}
			catch (const std::invalid_argument& e)
			{
				// parseMethods() names the key itself.
				throw std::runtime_error(
					iniWhere(path, "bench", "methods") + "[bench] " + e.what());
			}
		}
		if (c.keyExists("bench", "config_dir"))
		{
			const fs::path d = ini_dir / trim(c.read_string("bench", "config_dir", ""));
			if (!fs::is_directory(d))
				fail(path, "bench", "config_dir", d.string() + ": no such folder");
			cfg.config_dir = fs::weakly_canonical(d).string();
		}
		if (c.keyExists("bench", "data_dir"))
			data_dir = ini_dir / trim(c.read_string("bench", "data_dir", ""));
		cfg.min_span_px = positiveNumber(c, path, "bench", "min_span_px", cfg.min_span_px);
		cfg.rpe_interval_s = positiveNumber(c, path, "bench", "rpe_interval_s", cfg.rpe_interval_s);
	}
	if (cfg.config_dir.empty())
	{
		const std::string ekf = findShareFile("config/ekf.ini");
		if (ekf.empty())
			fail(
				path, "bench", "config_dir",
				"not set, and share/codemark/config/ekf.ini was not found (set "
				"CODEMARK_SHARE_DIR)");
		cfg.config_dir = fs::path(ekf).parent_path().string();
	}
	for (const auto& m : cfg.methods)
		if (!std::ifstream(cfg.config_dir + "/" + m + ".ini").good())
			fail(path, "bench", "config_dir", cfg.config_dir + "/" + m + ".ini: cannot open");

	for (const auto& s : sections)
	{
		if (s.rfind("dataset:", 0) != 0) continue;
		Dataset d;
		d.name = trim(s.substr(8));
		if (d.name.empty() || d.name.find_first_of("/\\ \t") != std::string::npos)
			fail(path, s, "", "a dataset name must be non-empty, without spaces or slashes");
		auto file = [&](const std::string& key, bool required) -> std::string
		{
			const std::string v = trim(c.read_string(s, key, ""));
			if (v.empty())
			{
				if (required) fail(path, s, key, "missing (required)");
				return {};
			}
			const fs::path p = fs::path(v).is_absolute() ? fs::path(v) : data_dir / v;
			if (!fs::is_regular_file(p)) fail(path, s, key, p.string() + ": no such file");
			return p.lexically_normal().string();
		};
		d.rawlog = file("rawlog", true);
		d.map = file("map", true);
		d.gt = file("gt", true);
		d.camera = file("camera", false);
		// A calibration file (relative to data_dir), else what
		// pose::resolveCalibration() makes of it (a shipped one's name).
		if (const std::string v = trim(c.read_string(s, "calibration", "")); !v.empty())
		{
			const fs::path p = fs::path(v).is_absolute() ? fs::path(v) : data_dir / v;
			d.calibration = fs::is_regular_file(p) ? p.lexically_normal().string() : v;
			try
			{
				pipeline::calibratedPoseOptions(d.calibration);
			}
			catch (const std::exception& e)
			{
				fail(path, s, "calibration", oneLineMessage(e.what()));
			}
		}
		cfg.datasets.push_back(d);
	}
	if (cfg.datasets.empty()) fail(path, "", "", "no [dataset:NAME] section");
	return cfg;
}

}  // namespace codemark::bench
