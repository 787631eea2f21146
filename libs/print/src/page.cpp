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
constexpr double kSpecInner_mm = 160.0;	 // the spec's reference square at scale 1
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
	if (end == dot + 1) --end;	// no decimals left: drop the point
	return s.substr(0, end);
}
}  // namespace

std::string labelText(const LandmarkGeometry& geometry, int id)
{
	std::ostringstream s;
	s << "codemark ID " << id << " (scale " << shortNumber(scaleOf(geometry), 3, 1)
	  << ", reference square " << shortNumber(geometry.inner_size_m * 1e3, 1, 0) << " mm)";
	return s.str();
}

LandmarkExtent landmarkExtent(const LandmarkGeometry& geometry)
{
	LandmarkExtent e;
	e.frame_mm = geometry.outer_size_m * 1e3;
	e.margin_mm = geometry.margin_m * 1e3;
	e.label_size_mm = std::max(kLabelMinSize_mm, kLabelSizeAtScale1_mm * scaleOf(geometry));
	// The longest label: a three-digit ID.
	const double label_w =
		kLabelAdvance_em * e.label_size_mm * static_cast<double>(labelText(geometry, 255).size());
	e.width_mm = std::max(e.frame_mm, label_w);
	e.height_mm = e.frame_mm + e.margin_mm + kLabelBand_em * e.label_size_mm;
	return e;
}

Placement appendLandmark(
	Page& page, const LandmarkGeometry& g, int id, double frame_x_mm, double frame_y_mm)
{
	const CodeCells cells = encodeId(id);  // throws outside 0..255
	const LandmarkExtent ext = landmarkExtent(g);
	const double outer = ext.frame_mm;
	const double inner = g.inner_size_m * 1e3;
	const double cell = g.cell_size_m * 1e3;
	const std::string prefix = "lm" + std::to_string(id) + "-";

	Placement p;
	p.id = id;
	p.frame_x_mm = frame_x_mm;
	p.frame_y_mm = frame_y_mm;
	p.ink_x_mm = frame_x_mm + 0.5 * (outer - ext.width_mm);
	p.ink_y_mm = frame_y_mm;
	p.ink_w_mm = ext.width_mm;
	p.ink_h_mm = ext.height_mm;

	page.rects.push_back({prefix + "frame-outer", frame_x_mm, frame_y_mm, outer, outer, kBlack});
	const double inset = 0.5 * (outer - inner);
	page.rects.push_back(
		{prefix + "fill", frame_x_mm + inset, frame_y_mm + inset, inner, inner, kGreen});

	// Face coordinates (s right, t up) [m] to page coordinates (x right, y
	// down) [mm] about the centre of the fill.
	const double cx = frame_x_mm + 0.5 * outer;
	const double cy = frame_y_mm + 0.5 * outer;
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
		{
			if (!cells[r][c]) continue;	 // green: the fill shows through
			const Eigen::Vector2d st = g.cellCentreFace(r, c);
			page.rects.push_back(
				{prefix + "cell-r" + std::to_string(r) + "c" + std::to_string(c),
				 cx + st.x() * 1e3 - 0.5 * cell, cy - st.y() * 1e3 - 0.5 * cell, cell, cell,
				 kBlack});
		}

	page.texts.push_back(
		{labelText(g, id), cx,
		 frame_y_mm + outer + ext.margin_mm + kLabelBaseline_em * ext.label_size_mm,
		 ext.label_size_mm});
	return p;
}

Page landmarkPage(const LandmarkGeometry& geometry, int id)
{
	const LandmarkExtent e = landmarkExtent(geometry);
	Page page;
	page.width_mm = e.width_mm + 2 * e.margin_mm;
	page.height_mm = e.height_mm + 2 * e.margin_mm;
	appendLandmark(page, geometry, id, e.margin_mm + 0.5 * (e.width_mm - e.frame_mm), e.margin_mm);
	return page;
}

namespace
{
// One axis of the sheet's grid: blocks of \a block mm, at least \a gap mm
// apart, at least \a lo / \a hi mm from the paper's edges. Returns the
// start of each block, the spare length spread evenly over the n + 1 spaces.
std::vector<double> fitAxis(double length, double block, double gap, double lo, double hi)
{
	std::vector<double> starts;
	int n = 0;
	while ((n + 1) * block + n * gap + lo + hi <= length + kFitTolerance_mm) ++n;
	if (n == 0) return starts;
	const double spare = std::max(0.0, length - (n * block + (n - 1) * gap + lo + hi)) / (n + 1);
	for (int i = 0; i < n; ++i) starts.push_back(lo + spare + i * (block + gap + spare));
	return starts;
}

struct Grid
{
	std::vector<double> ink_x;	// left edge of each column's ink [mm]
	std::vector<double> ink_y;	// top edge of each row's ink (the frame's top) [mm]
};

Grid gridOnA4(const LandmarkExtent& e, double border)
{
	// Across: the frame needs max(margin, border) from the edge (the paper's
	// blank border is white, so it counts as quiet margin), and so does a
	// label wider than the frame (reduced by the overhang). Between columns
	// one quiet margin of white.
	const double overhang = 0.5 * (e.width_mm - e.frame_mm);
	const double edge_x = std::max(std::max(e.margin_mm, border) - overhang, border);
	// Down: the frame's top needs max(margin, border); below the label's
	// band the border; between rows one quiet margin above the next frame.
	Grid g;
	g.ink_x = fitAxis(kA4Width_mm, e.width_mm, e.margin_mm, edge_x, edge_x);
	g.ink_y =
		fitAxis(kA4Height_mm, e.height_mm, e.margin_mm, std::max(e.margin_mm, border), border);
	return g;
}

void checkBorder(double border)
{
	if (!std::isfinite(border) || border < 0 || border > 50)
		throw std::invalid_argument(
			"the paper border must be 0..50 mm, got " + shortNumber(border, 3, 0));
}
}  // namespace

int landmarksPerSheet(const LandmarkGeometry& geometry, double paper_border_mm)
{
	checkBorder(paper_border_mm);
	const Grid g = gridOnA4(landmarkExtent(geometry), paper_border_mm);
	return static_cast<int>(g.ink_x.size() * g.ink_y.size());
}

std::vector<Page> sheetPages(
	const LandmarkGeometry& geometry, const std::vector<int>& ids, double paper_border_mm,
	std::vector<std::vector<Placement>>* placements)
{
	checkBorder(paper_border_mm);
	const LandmarkExtent e = landmarkExtent(geometry);
	const Grid grid = gridOnA4(e, paper_border_mm);
	const std::size_t cols = grid.ink_x.size();
	const std::size_t per_page = cols * grid.ink_y.size();
	if (per_page == 0)
	{
		const double need = e.frame_mm + 2 * std::max(e.margin_mm, paper_border_mm);
		std::ostringstream s;
		s << "a landmark with a " << shortNumber(e.frame_mm, 1, 0)
		  << " mm frame does not fit on A4 (210 x 297 mm) with a "
		  << shortNumber(paper_border_mm, 1, 0) << " mm paper border: it needs "
		  << shortNumber(std::max(need, e.width_mm + 2 * paper_border_mm), 1, 0) << " x "
		  << shortNumber(
				 e.height_mm + std::max(e.margin_mm, paper_border_mm) + paper_border_mm, 1, 0)
		  << " mm; use a smaller --scale or --border, or print without --sheet";
		throw std::invalid_argument(s.str());
	}

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
		const double ink_x = grid.ink_x[slot % cols];
		const double ink_y = grid.ink_y[slot / cols];
		const Placement p = appendLandmark(
			pages.back(), geometry, ids[i], ink_x + 0.5 * (e.width_mm - e.frame_mm), ink_y);
		if (placements) placements->back().push_back(p);
	}
	return pages;
}

}  // namespace codemark::print
