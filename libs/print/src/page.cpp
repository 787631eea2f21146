#include <codemark/landmark/codebook.h>
#include <codemark/print/page.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>

namespace codemark::print
{
namespace
{
constexpr double kSpecInner_mm = 160.0;  // the spec's reference square at scale 1
constexpr double kLabelSizeAtScale1_mm = 3.5;  // about 10 pt
constexpr double kLabelMinSize_mm = 1.5;  // about 4 pt, still legible
// Average advance of the label's characters in DejaVu Sans / Arial, in em,
// rounded up so that the estimated width never falls short.
constexpr double kLabelAdvance_em = 0.62;
// The band below the quiet margin: the baseline sits 1 em below the margin
// (the glyphs' tops about 0.25 em below it), descenders end 0.4 em lower.
constexpr double kLabelBaseline_em = 1.0;
constexpr double kLabelBand_em = 1.4;
constexpr double kFitTolerance_mm = 1e-6;

double scaleOf(const LandmarkGeometry& g) { return g.inner_size_m * 1e3 / kSpecInner_mm; }

// A number with at most \a decimals decimals, trailing zeros dropped but at
// least \a keep decimals kept ("1.0", "0.25", "160").
std::string shortNumber(double v, int decimals, int keep)
{
	char buf[64];
	std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
	std::string s = buf;
	const auto dot = s.find('.');
	if (dot == std::string::npos) return s;
	std::size_t end = s.size();
	while (end > dot + 1 + static_cast<std::size_t>(keep) && s[end - 1] == '0') --end;
	if (end == dot + 1) --end;  // no decimals left: drop the point
	return s.substr(0, end);
}
}  // namespace

std::string labelText(const LandmarkGeometry& geometry, int id)
{
	std::ostringstream s;
	s << "codemark ID " << id << " (scale " << shortNumber(scaleOf(geometry), 3, 1)
	  << ", reference square " << shortNumber(geometry.inner_size_m * 1e3, 1, 0)
	  << " mm)";
	return s.str();
}

TileSize tileSize(const LandmarkGeometry& geometry)
{
	const double outer = geometry.outer_size_m * 1e3;
	const double margin = geometry.margin_m * 1e3;
	TileSize t;
	t.label_size_mm = std::max(kLabelMinSize_mm, kLabelSizeAtScale1_mm * scaleOf(geometry));
	// The longest label: a three-digit ID.
	const double label_w =
		kLabelAdvance_em * t.label_size_mm * static_cast<double>(labelText(geometry, 255).size());
	t.width_mm = std::max(outer, label_w) + 2 * margin;
	t.height_mm = 2 * margin + outer + kLabelBand_em * t.label_size_mm;
	return t;
}

Placement appendLandmark(
	Page& page, const LandmarkGeometry& g, int id, double tile_x_mm, double tile_y_mm)
{
	const CodeCells cells = encodeId(id);  // throws outside 0..255
	const TileSize tile = tileSize(g);
	const double outer = g.outer_size_m * 1e3;
	const double inner = g.inner_size_m * 1e3;
	const double cell = g.cell_size_m * 1e3;
	const double margin = g.margin_m * 1e3;
	const std::string prefix = "lm" + std::to_string(id) + "-";

	Placement p;
	p.id = id;
	p.tile_x_mm = tile_x_mm;
	p.tile_y_mm = tile_y_mm;
	p.frame_x_mm = tile_x_mm + 0.5 * (tile.width_mm - outer);
	p.frame_y_mm = tile_y_mm + margin;

	page.rects.push_back(
		{prefix + "tile", tile_x_mm, tile_y_mm, tile.width_mm, tile.height_mm, kWhite});
	page.rects.push_back({prefix + "frame-outer", p.frame_x_mm, p.frame_y_mm, outer, outer, kBlack});
	const double inset = 0.5 * (outer - inner);
	page.rects.push_back(
		{prefix + "fill", p.frame_x_mm + inset, p.frame_y_mm + inset, inner, inner, kGreen});

	// Face coordinates (s right, t up) [m] to page coordinates (x right, y
	// down) [mm] about the centre of the fill.
	const double cx = p.frame_x_mm + 0.5 * outer;
	const double cy = p.frame_y_mm + 0.5 * outer;
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
		{
			if (!cells[r][c]) continue;  // green: the fill shows through
			const Eigen::Vector2d st = g.cellCentreFace(r, c);
			page.rects.push_back(
				{prefix + "cell-r" + std::to_string(r) + "c" + std::to_string(c),
				 cx + st.x() * 1e3 - 0.5 * cell, cy - st.y() * 1e3 - 0.5 * cell, cell, cell,
				 kBlack});
		}

	page.texts.push_back(
		{labelText(g, id), tile_x_mm + 0.5 * tile.width_mm,
		 p.frame_y_mm + outer + margin + kLabelBaseline_em * tile.label_size_mm,
		 tile.label_size_mm});
	return p;
}

Page landmarkPage(const LandmarkGeometry& geometry, int id)
{
	const TileSize tile = tileSize(geometry);
	Page page;
	page.width_mm = tile.width_mm;
	page.height_mm = tile.height_mm;
	appendLandmark(page, geometry, id, 0.0, 0.0);
	return page;
}

namespace
{
void gridOnA4(const TileSize& tile, int& cols, int& rows)
{
	cols = static_cast<int>(std::floor((kA4Width_mm + kFitTolerance_mm) / tile.width_mm));
	rows = static_cast<int>(std::floor((kA4Height_mm + kFitTolerance_mm) / tile.height_mm));
}
}  // namespace

int landmarksPerSheet(const LandmarkGeometry& geometry)
{
	int cols = 0, rows = 0;
	gridOnA4(tileSize(geometry), cols, rows);
	return cols * rows;
}

std::vector<Page> sheetPages(
	const LandmarkGeometry& geometry, const std::vector<int>& ids,
	std::vector<std::vector<Placement>>* placements)
{
	const TileSize tile = tileSize(geometry);
	int cols = 0, rows = 0;
	gridOnA4(tile, cols, rows);
	if (cols < 1 || rows < 1)
	{
		std::ostringstream s;
		s << "a landmark at this size needs " << shortNumber(tile.width_mm, 1, 0) << " x "
		  << shortNumber(tile.height_mm, 1, 0)
		  << " mm (frame, quiet margin and label) but an A4 page is 210 x 297 mm; "
			 "use a smaller --scale or print without --sheet";
		throw std::invalid_argument(s.str());
	}
	// Spread the spare space evenly between the tiles and the paper edges.
	const double gap_x = std::max(0.0, (kA4Width_mm - cols * tile.width_mm) / (cols + 1));
	const double gap_y = std::max(0.0, (kA4Height_mm - rows * tile.height_mm) / (rows + 1));
	const std::size_t per_page = static_cast<std::size_t>(cols * rows);

	std::vector<Page> pages;
	if (placements) placements->clear();
	for (std::size_t i = 0; i < ids.size(); ++i)
	{
		const std::size_t slot = i % per_page;
		if (slot == 0)
		{
			pages.push_back(Page{kA4Width_mm, kA4Height_mm, {}, {}});
			if (placements) placements->emplace_back();
		}
		const int col = static_cast<int>(slot) % cols;
		const int row = static_cast<int>(slot) / cols;
		const Placement p = appendLandmark(
			pages.back(), geometry, ids[i], gap_x + col * (tile.width_mm + gap_x),
			gap_y + row * (tile.height_mm + gap_y));
		if (placements) placements->back().push_back(p);
	}
	return pages;
}

}  // namespace codemark::print
