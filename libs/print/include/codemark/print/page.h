#pragma once
/** \file page.h
 * The printable page of one or several landmarks as plain drawing data in
 * millimetres (docs/spec.md section 1): filled rectangles and text lines
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
constexpr Colour kGreen{0, 255, 0};	 //!< the fill, sRGB #00FF00 (spec section 1)
constexpr Colour kWhite{255, 255, 255};	 //!< the sheet and the quiet margin

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
	double centre_x_mm = 0;	 //!< horizontal centre of the line [mm]
	double baseline_y_mm = 0;  //!< baseline, from the page's top edge [mm]
	double size_mm = 0;	 //!< font size (em height) [mm]
};

/** One physical page [mm]: white background, then rects, then texts. */
struct Page
{
	double width_mm = 0;  //!< page width [mm]
	double height_mm = 0;  //!< page height [mm]
	std::vector<FilledRect> rects;	//!< in painting order
	std::vector<TextLine> texts;
};

/** Where one landmark sits on a page [mm]. */
struct Placement
{
	int id = 0;	 //!< landmark ID 0..255
	double frame_x_mm = 0;	//!< outer frame's left edge [mm]
	double frame_y_mm = 0;	//!< outer frame's top edge [mm]
	double ink_x_mm = 0;  //!< left edge of everything printed for it (frame, label) [mm]
	double ink_y_mm = 0;  //!< top edge of the ink (the frame's top) [mm]
	double ink_w_mm = 0;  //!< width of the ink (frame or estimated label width) [mm]
	double ink_h_mm = 0;  //!< height of the ink, frame top to below the label's descenders [mm]
};

/** The extent of one landmark of a geometry [mm]. */
struct LandmarkExtent
{
	double frame_mm = 0;  //!< side of the outer frame [mm]
	double margin_mm = 0;  //!< quiet margin around the frame, kept free of ink [mm]
	double width_mm = 0;  //!< ink width: the frame or the label, whichever is wider [mm]
	double height_mm = 0;  //!< ink height: frame, quiet margin, label band [mm]
	double label_size_mm = 0;  //!< font size of the label [mm]
};

/** A4 portrait, the sheet of --sheet [mm]. */
constexpr double kA4Width_mm = 210.0;
constexpr double kA4Height_mm = 297.0;

/** Default border of the paper that printers leave blank [mm]: most inkjets
 * print to 3 mm from the edge; many laser printers need 4.2 mm. */
constexpr double kDefaultPaperBorder_mm = 3.0;

/** The human-readable label printed below the frame, outside the quiet
 * margin, e.g. "codemark ID 37 (scale 1.0, reference square 160 mm)". The
 * scale is inner_size_m relative to the spec's 160 mm. */
std::string labelText(const LandmarkGeometry& geometry, int id);

/** The extent of one landmark of \a geometry [mm]. The label's font is
 * 3.5 mm at scale 1, proportional to the scale, never below 1.5 mm; its
 * width is estimated for a three-digit ID (0.62 em per character). */
LandmarkExtent landmarkExtent(const LandmarkGeometry& geometry);

/** Appends landmark \a id with its outer frame's top-left corner at
 * (frame_x_mm, frame_y_mm) to \a page: black outer frame square, green fill
 * of the inner square, the black cells of encodeId(id) (the centre always
 * black), and the label centred below the frame, outside the quiet margin.
 * The caller keeps the quiet margin free. Throws std::out_of_range for an ID
 * outside 0..255. Returns where it went. */
Placement appendLandmark(
	Page& page, const LandmarkGeometry& geometry, int id, double frame_x_mm, double frame_y_mm);

/** A page holding landmark \a id alone: the ink with the quiet margin on
 * all sides (the landmark's exact size plus margin and label). */
Page landmarkPage(const LandmarkGeometry& geometry, int id);

/** How many landmarks of \a geometry fit on one A4 portrait page (columns
 * x rows; 0 when one does not fit) with every frame at least
 * max(quiet margin, paper border) from the paper's edge, neighbours'
 * ink at least one quiet margin from a frame (neighbouring margins may
 * share their white), and the labels at least the paper border from the
 * edge. */
int landmarksPerSheet(
	const LandmarkGeometry& geometry, double paper_border_mm = kDefaultPaperBorder_mm);

/** A4 pages holding the landmarks \a ids in order, landmarksPerSheet() per
 * page in a grid, the spare space spread evenly between the landmarks and
 * the paper edges. Throws std::invalid_argument, saying how much room one
 * landmark needs, when none fits. \a placements (optional) receives, per
 * page, where each landmark went. */
std::vector<Page> sheetPages(
	const LandmarkGeometry& geometry, const std::vector<int>& ids,
	double paper_border_mm = kDefaultPaperBorder_mm,
	std::vector<std::vector<Placement>>* placements = nullptr);

}  // namespace codemark::print
