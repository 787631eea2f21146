#pragma once
/** \file page.h
 * The printable page of one or several landmarks as plain drawing data in
 * millimetres (landmark-spec.md section 1): filled rectangles and text lines
 * on a white page, origin at the page's top-left corner, x right, y down
 * (the SVG and PDF page convention). The writers of output.h turn a Page into
 * SVG, PNG or PDF at exact physical size.
 */
#include <codemark/landmark/geometry.h>

#include <cstdint>
#include <string>
#include <vector>

namespace codemark::print
{
/** An sRGB colour, 8 bits per channel. */
struct Colour
{
	std::uint8_t r = 0, g = 0, b = 0;
	bool operator==(const Colour& o) const { return r == o.r && g == o.g && b == o.b; }
};

constexpr Colour kBlack{0, 0, 0};  //!< frame and black code cells
constexpr Colour kGreen{0, 255, 0};  //!< the fill, sRGB #00FF00 (spec section 1)
constexpr Colour kWhite{255, 255, 255};  //!< the sheet and the quiet margin

/** One axis-aligned filled rectangle on the page [mm]. Later rectangles are
 * painted over earlier ones. */
struct FilledRect
{
	std::string name;  //!< unique on its page, e.g. "lm37-frame-outer" (the SVG id)
	double x_mm = 0;  //!< left edge, from the page's left edge [mm]
	double y_mm = 0;  //!< top edge, from the page's top edge [mm]
	double w_mm = 0;  //!< width [mm]
	double h_mm = 0;  //!< height [mm]
	Colour colour;
};

/** One line of black sans-serif text, centred horizontally on centre_x_mm. */
struct TextLine
{
	std::string text;  //!< UTF-8 (ASCII in practice)
	double centre_x_mm = 0;  //!< horizontal centre of the line [mm]
	double baseline_y_mm = 0;  //!< baseline, from the page's top edge [mm]
	double size_mm = 0;  //!< font size (em height) [mm]
};

/** One physical page [mm]: white background, then rects, then texts. */
struct Page
{
	double width_mm = 0;  //!< page width [mm]
	double height_mm = 0;  //!< page height [mm]
	std::vector<FilledRect> rects;  //!< in painting order
	std::vector<TextLine> texts;
};

/** Where one landmark sits on a page: the top-left corner of its tile [mm]
 * and of its outer black frame [mm]. */
struct Placement
{
	int id = 0;  //!< landmark ID 0..255
	double tile_x_mm = 0;  //!< tile (quiet margin + frame + label) left edge [mm]
	double tile_y_mm = 0;  //!< tile top edge [mm]
	double frame_x_mm = 0;  //!< outer frame left edge [mm]
	double frame_y_mm = 0;  //!< outer frame top edge [mm]
};

/** The white tile around one landmark [mm]: the outer frame, the quiet margin
 * (LandmarkGeometry::margin_m) on all four sides, and below it the band that
 * holds the human-readable label. */
struct TileSize
{
	double width_mm = 0;  //!< tile width [mm]
	double height_mm = 0;  //!< tile height [mm]
	double label_size_mm = 0;  //!< font size of the label [mm]
};

/** A4 portrait, the sheet of --sheet [mm]. */
constexpr double kA4Width_mm = 210.0;
constexpr double kA4Height_mm = 297.0;

/** The human-readable label printed below the frame, outside the quiet
 * margin, e.g. "codemark ID 37 (scale 1.0, reference square 160 mm)". The
 * scale is inner_size_m relative to the spec's 160 mm. */
std::string labelText(const LandmarkGeometry& geometry, int id);

/** Size of the tile of one landmark of \a geometry [mm]. The label's font is
 * 3.5 mm at scale 1, proportional to the scale, never below 1.5 mm; the tile
 * widens when the label is wider than the frame and its margins. */
TileSize tileSize(const LandmarkGeometry& geometry);

/** Appends the tile of landmark \a id with its top-left corner at
 * (tile_x_mm, tile_y_mm) to \a page: white tile, black outer frame square,
 * green fill of the inner square, the black cells of encodeId(id) (the centre
 * always black), the label. Throws std::out_of_range for an ID outside
 * 0..255. Returns where it went. */
Placement appendLandmark(
	Page& page, const LandmarkGeometry& geometry, int id, double tile_x_mm,
	double tile_y_mm);

/** A page holding exactly the tile of landmark \a id. */
Page landmarkPage(const LandmarkGeometry& geometry, int id);

/** A4 pages holding the landmarks \a ids in order, as many per page as fit
 * in a grid (columns x rows) with the spare space spread evenly between the
 * tiles and the paper edges. Throws std::invalid_argument when one tile does
 * not fit on A4 portrait. \a placements (optional) receives, per page, where
 * each landmark went. */
std::vector<Page> sheetPages(
	const LandmarkGeometry& geometry, const std::vector<int>& ids,
	std::vector<std::vector<Placement>>* placements = nullptr);

/** How many tiles of \a geometry fit on one A4 page (columns x rows); 0 when
 * one does not fit. */
int landmarksPerSheet(const LandmarkGeometry& geometry);

}  // namespace codemark::print
