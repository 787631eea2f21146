/** \file main.cpp
 * codemark-print: writes printable landmarks at exact physical size. Parses
 * the command line and calls codemark::print::run().
 */
#include <codemark/print/print.h>

#include <tclap/CmdLine.h>

#include <exception>
#include <iostream>

#include "errors.h"

int main(int argc, char** argv)
{
	namespace cp = codemark::print;
	try
	{
		TCLAP::CmdLine cmd(
			"Writes coded landmarks (docs/spec.md section 1) at exact physical size: "
			"a 200 mm black frame around a 160 mm #00FF00 square (the reference square) "
			"holding the 3x3 code board of 30 mm cells, a white quiet margin of at least "
			"5 mm, and below it, outside the margin, the label \"codemark ID <id> (scale <s>, "
			"reference square <mm> mm)\". Every size is multiplied by --scale. Print the "
			"files at 100% (no 'fit to page') and measure the reference square.",
			' ', "0.1.0");
		TCLAP::MultiArg<std::string> id_arg(
			"", "id",
			"Landmark ID to print, 0..255; repeat the option for more (--id 37 --id 38), or "
			"give a list (--id 1,2,3) or a range (--id 0-7). Every ID at most once.",
			true, "ID", cmd);
		TCLAP::ValueArg<std::string> out_arg(
			"", "out",
			"Output folder, created when missing. Without --sheet it receives "
			"codemark-<id>.<ext> per ID and format; with --sheet codemark-sheet.pdf (all pages) "
			"and codemark-sheet-<page>.svg/.png per A4 page (page from 1).",
			true, "", "DIR", cmd);
		TCLAP::ValueArg<std::string> format_arg(
			"", "format",
			"Comma-separated output formats: svg (width/height in mm, viewBox in mm), png (at "
			"--dpi, the dpi recorded in the pHYs chunk), pdf (page size in points = mm / 25.4 * "
			"72). Default: svg,png,pdf.",
			false, "svg,png,pdf", "LIST", cmd);
		TCLAP::ValueArg<double> scale_arg(
			"", "scale",
			"Multiplies every size of the landmark (frame, fill, cells, quiet margin) and, "
			"above 3/7, the label's font; must be > 0. Scale 1 is the spec's A4 landmark (200 "
			"mm frame, 160 mm reference square). Use the same value as the map file's scale "
			"column. Default 1.",
			false, 1.0, "S", cmd);
		TCLAP::SwitchArg sheet_arg(
			"", "sheet",
			"Lay the landmarks on A4 portrait pages (210 x 297 mm), in the order given, as many "
			"per page as fit in a grid at the requested scale (1 at scale 1, 4 at scale 0.5), "
			"the spare space spread evenly. Every frame keeps its quiet margin and stays at "
			"least the --border from the paper's edge. A landmark that does not fit on A4 is an "
			"error (exit 1): lower --scale or --border, or print without --sheet, which sizes "
			"each page to its landmark.",
			cmd, false);
		TCLAP::ValueArg<double> border_arg(
			"", "border",
			"With --sheet: the blank border (0..50 mm) that your printer leaves at the paper's "
			"edges. Most inkjets print to 3 mm; many laser printers need 4.2 (then scale 0.5 "
			"gives one column). Default 3. Ignored without --sheet.",
			false, 3.0, "MM", cmd);
		TCLAP::ValueArg<double> dpi_arg(
			"", "dpi", "Resolution of the PNG files, 10..1200 dots per inch. Default 600.", false,
			600.0, "DPI", cmd);
		TCLAP::ValueArg<std::string> landmark_arg(
			"", "landmark",
			"Landmark ini file; its [LANDMARK] section (outer_size_m, inner_size_m, "
			"cell_size_m, margin_m, scale; see share/codemark/landmark.ini) gives the sizes, "
			"then multiplied by --scale. Default: the spec's sizes.",
			false, "", "LM.ini", cmd);
		cmd.setExceptionHandling(false);
		cmd.parse(argc, argv);

		cp::PrintOptions opt;
		for (const std::string& a : id_arg.getValue()) cp::parseIds(a, opt.ids);
		opt.out_dir = out_arg.getValue();
		opt.formats = cp::parseFormats(format_arg.getValue());
		opt.scale = scale_arg.getValue();
		opt.sheet = sheet_arg.getValue();
		opt.paper_border_mm = border_arg.getValue();
		opt.dpi = dpi_arg.getValue();
		opt.landmark_ini = landmark_arg.getValue();
		cp::run(opt, &std::cout);
		return 0;
	}
	catch (const TCLAP::ExitException& e)
	{
		return e.getExitStatus();  // after --help or --version
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << codemark::app::argumentError("codemark-print", e) << "\n";
		return 1;
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-print: error: " << codemark::app::oneLine(e.what()) << "\n";
		return 1;
	}
}
