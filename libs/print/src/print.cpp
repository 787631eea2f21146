#include <codemark/landmark/text.h>
#include <codemark/print/output.h>
#include <codemark/print/page.h>
#include <codemark/print/print.h>

#include <mrpt/config/CConfigFile.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace codemark::print
{
namespace fs = std::filesystem;

namespace
{
std::string trimmed(const std::string& s)
{
	const auto b = s.find_first_not_of(" \t");
	if (b == std::string::npos) return {};
	const auto e = s.find_last_not_of(" \t");
	return s.substr(b, e - b + 1);
}

std::vector<std::string> splitCommas(const std::string& s)
{
	std::vector<std::string> out;
	std::string item;
	std::istringstream in(s);
	while (std::getline(in, item, ',')) out.push_back(trimmed(item));
	if (!s.empty() && s.back() == ',') out.emplace_back();
	return out;
}

// An integer from an optionally signed digit string; long strings, which
// would overflow stoi, are out of 0..255 anyway and become +-1000000.
int toInt(const std::string& digits)
{
	if (digits.size() > 6) return digits[0] == '-' ? -1000000 : 1000000;
	return std::stoi(digits);
}

std::string sizeMm(double m)
{
	std::ostringstream s;
	s << m * 1e3;
	return s.str();
}
}  // namespace

std::string formatName(Format f)
{
	switch (f)
	{
		case Format::Svg:
			return "svg";
		case Format::Png:
			return "png";
		case Format::Pdf:
			return "pdf";
	}
	return "?";
}

Format formatFromName(const std::string& name)
{
	std::string n = trimmed(name);
	std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return std::tolower(c); });
	for (Format f : {Format::Svg, Format::Png, Format::Pdf})
		if (n == formatName(f)) return f;
	throw std::invalid_argument(
		"unknown format '" + trimmed(name) + "' (known formats: svg, png, pdf)");
}

std::vector<Format> parseFormats(const std::string& csv)
{
	std::vector<Format> out;
	for (const std::string& item : splitCommas(csv))
	{
		if (item.empty())
			throw std::invalid_argument(
				"empty entry in format list '" + csv + "' (give e.g. svg,png,pdf)");
		const Format f = formatFromName(item);
		if (std::find(out.begin(), out.end(), f) == out.end()) out.push_back(f);
	}
	if (out.empty()) throw std::invalid_argument("no output format given (give e.g. svg,png,pdf)");
	return out;
}

void parseIds(const std::string& arg, std::vector<int>& ids)
{
	static const std::regex kOne(R"(^(-?[0-9]+)$)");
	static const std::regex kRange(R"(^([0-9]+)-([0-9]+)$)");
	for (const std::string& item : splitCommas(arg))
	{
		std::smatch m;
		if (std::regex_match(item, m, kOne))
			ids.push_back(toInt(m[1]));
		else if (std::regex_match(item, m, kRange))
		{
			const int a = toInt(m[1]), b = toInt(m[2]);
			if (a > b)
				throw std::invalid_argument(
					"ID range '" + item + "' runs backwards (write the smaller ID first)");
			if (b > 255)
				throw std::invalid_argument("landmark ID range '" + item + "' goes outside 0..255");
			for (int id = a; id <= b; ++id) ids.push_back(id);
		}
		else
			throw std::invalid_argument(
				"--id '" + arg + "': '" + item +
				"' is not an ID (an integer 0..255, a list 1,2,3 or a range 0-7)");
	}
}

LandmarkGeometry geometryOf(const PrintOptions& o)
{
	if (!std::isfinite(o.scale) || !(o.scale > 0))
	{
		std::ostringstream s;
		s << "--scale must be a finite number > 0, got " << o.scale;
		throw std::invalid_argument(s.str());
	}
	LandmarkGeometry g;
	if (!o.landmark_ini.empty())
	{
		const std::string& path = o.landmark_ini;
		if (!fs::is_regular_file(path) || !std::ifstream(path))
			throw std::invalid_argument("cannot read landmark file '" + path + "'");
		try
		{
			mrpt::config::CConfigFile cfg(path);
			if (!cfg.sectionExists("LANDMARK"))
				throw std::invalid_argument("it has no [LANDMARK] section");
			g.loadFromConfigFile(cfg, "LANDMARK");
		}
		catch (const std::exception&)
		{
			rethrowNamingIniFile(path);	 // one line, with the line of a bad number
		}
	}
	g.outer_size_m *= o.scale;
	g.inner_size_m *= o.scale;
	g.cell_size_m *= o.scale;
	g.margin_m *= o.scale;
	g.validate();
	return g;
}

void validate(const PrintOptions& o)
{
	if (o.ids.empty()) throw std::invalid_argument("no landmark ID given (use --id, e.g. --id 37)");
	std::set<int> seen;
	for (int id : o.ids)
	{
		if (id < 0 || id > 255)
			throw std::invalid_argument("landmark ID " + std::to_string(id) + " is outside 0..255");
		if (!seen.insert(id).second)
			throw std::invalid_argument(
				"landmark ID " + std::to_string(id) + " is given more than once");
	}
	if (o.formats.empty())
		throw std::invalid_argument("no output format given (give e.g. svg,png,pdf)");
	if (o.out_dir.empty()) throw std::invalid_argument("no output folder given (use --out DIR)");
	const LandmarkGeometry g = geometryOf(o);
	// The largest page decides whether the PNG can be drawn.
	Page largest;
	if (o.sheet)
	{
		if (landmarksPerSheet(g, o.paper_border_mm) < 1)
			sheetPages(g, {o.ids.front()}, o.paper_border_mm);	// throws the why
		largest.width_mm = kA4Width_mm;
		largest.height_mm = kA4Height_mm;
	}
	else
		largest = landmarkPage(g, o.ids.front());
	if (std::find(o.formats.begin(), o.formats.end(), Format::Png) != o.formats.end())
		checkPngRaster(largest, o.dpi);
	else if (!std::isfinite(o.dpi) || o.dpi < 10 || o.dpi > 1200)
		checkPngRaster(largest, o.dpi);	 // a bad --dpi is an error even without PNG
}

PrintReport run(const PrintOptions& o, std::ostream* log)
{
	validate(o);
	const LandmarkGeometry g = geometryOf(o);

	const fs::path dir(o.out_dir);
	createFolder(o.out_dir, "the output folder");
	std::error_code ec;
	{
		const fs::path probe = dir / ".codemark-print-write-test";
		std::ofstream f(probe);
		if (!f) throw std::runtime_error("output folder '" + o.out_dir + "' is not writable");
		f.close();
		fs::remove(probe, ec);
	}

	PrintReport report;
	auto wrote = [&](const fs::path& p, const Page& page)
	{
		report.files.push_back(p.string());
		if (log)
			*log << "wrote " << p.string() << " (" << page.width_mm << " x " << page.height_mm
				 << " mm)\n";
	};
	auto has = [&](Format f)
	{ return std::find(o.formats.begin(), o.formats.end(), f) != o.formats.end(); };

	if (log)
		*log << "landmark: outer frame " << sizeMm(g.outer_size_m) << " mm, reference square "
			 << sizeMm(g.inner_size_m) << " mm, cells " << sizeMm(g.cell_size_m)
			 << " mm, quiet margin " << sizeMm(g.margin_m) << " mm\n";

	if (!o.sheet)
	{
		for (int id : o.ids)
		{
			const Page page = landmarkPage(g, id);
			for (Format f : o.formats)
			{
				const fs::path p = dir / ("codemark-" + std::to_string(id) + "." + formatName(f));
				switch (f)
				{
					case Format::Svg:
						writeSvg(page, p.string());
						break;
					case Format::Png:
						writePng(page, p.string(), o.dpi);
						break;
					case Format::Pdf:
						writePdf({page}, p.string());
						break;
				}
				wrote(p, page);
			}
			++report.pages;
		}
		return report;
	}

	const std::vector<Page> pages = sheetPages(g, o.ids, o.paper_border_mm);
	report.pages = static_cast<int>(pages.size());
	if (log)
		*log << "sheet: " << landmarksPerSheet(g, o.paper_border_mm) << " landmark(s) per A4 page, "
			 << pages.size() << " page(s)\n";
	if (has(Format::Pdf))
	{
		const fs::path p = dir / "codemark-sheet.pdf";
		writePdf(pages, p.string());
		wrote(p, pages.front());
	}
	for (std::size_t i = 0; i < pages.size(); ++i)
	{
		const std::string stem = "codemark-sheet-" + std::to_string(i + 1) + ".";
		if (has(Format::Svg))
		{
			writeSvg(pages[i], (dir / (stem + "svg")).string());
			wrote(dir / (stem + "svg"), pages[i]);
		}
		if (has(Format::Png))
		{
			writePng(pages[i], (dir / (stem + "png")).string(), o.dpi);
			wrote(dir / (stem + "png"), pages[i]);
		}
	}
	return report;
}

}  // namespace codemark::print
