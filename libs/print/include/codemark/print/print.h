#pragma once
/** \file print.h
 * What codemark-print does, callable from tests: validate the options, lay
 * out the landmarks and write the files. The app only parses arguments.
 */
#include <codemark/landmark/geometry.h>
#include <codemark/print/page.h>

#include <iosfwd>
#include <string>
#include <vector>

namespace codemark::print
{
/** An output file format, read by name ("svg", "png", "pdf"). */
enum class Format
{
	Svg,  //!< SVG, width/height in mm
	Png,  //!< PNG at PrintOptions::dpi, dpi recorded in pHYs
	Pdf	 //!< PDF at exact size
};

/** "svg", "png" or "pdf". */
std::string formatName(Format f);

/** The format named \a name (case-insensitive, surrounding blanks ignored).
 * Throws std::invalid_argument naming it otherwise. */
Format formatFromName(const std::string& name);

/** A comma-separated list of format names, e.g. "svg,png"; repeated names
 * count once. Throws std::invalid_argument on an empty list or an unknown
 * name. */
std::vector<Format> parseFormats(const std::string& csv);

/** One --id argument: an integer ("37"), a comma-separated list ("1,2,3") or
 * an inclusive range ("0-7"), appended to \a ids in order. Range checks are
 * left to validate(). Throws std::invalid_argument on text that is none of
 * these. */
void parseIds(const std::string& arg, std::vector<int>& ids);

/** Options of one codemark-print run. */
struct PrintOptions
{
	std::vector<int> ids;  //!< landmark IDs, each 0..255, no repeats, at least one
	std::string out_dir;  //!< output folder; created when missing
	std::vector<Format> formats = {
		Format::Svg, Format::Png, Format::Pdf};	 //!< files per landmark (or per sheet page)
	double scale = 1.0;	 //!< multiplies every size of the landmark (> 0) [-]
	bool sheet = false;	 //!< lay the landmarks on A4 pages instead of one file each
	double paper_border_mm =
		kDefaultPaperBorder_mm;	 //!< with sheet: blank border the printer leaves [mm], 0..50
	double dpi = 600;  //!< PNG resolution [dots per inch], 10..1200
	std::string landmark_ini;  //!< optional ini whose [LANDMARK] section gives the sizes (then
							   //!< multiplied by scale); empty: the spec's A4 landmark
};

/** What run() did. */
struct PrintReport
{
	std::vector<std::string> files;	 //!< every file written, in order
	int pages = 0;	//!< pages (one per landmark, or A4 sheets with --sheet)
};

/** The landmark geometry of \a options: the ini's [LANDMARK] section (or the
 * spec's defaults) multiplied by options.scale. Throws
 * std::invalid_argument with a message naming the file on any problem. */
LandmarkGeometry geometryOf(const PrintOptions& options);

/** Checks \a options without writing anything: IDs in 0..255, no
 * duplicates, at least one ID, formats present, scale finite and > 0, dpi in
 * 10..1200, the geometry valid, and with sheet that one landmark fits on A4.
 * Throws std::invalid_argument with one clear line. */
void validate(const PrintOptions& options);

/** Validates, creates out_dir when missing, checks that it is writable, then
 * writes out_dir/codemark-<id>.<ext> for each ID and format, or with sheet
 * out_dir/codemark-sheet.pdf (all pages) and
 * out_dir/codemark-sheet-<page>.svg / .png (page from 1). Writes a line per
 * file to \a log when given. Throws std::invalid_argument for bad options and
 * std::runtime_error for files it cannot write. */
PrintReport run(const PrintOptions& options, std::ostream* log = nullptr);

}  // namespace codemark::print
