#pragma once
/** \file output.h
 * Writers of a Page (page.h) at exact physical size: SVG in millimetres
 * (written directly, since cairo's SVG surface uses points and paths), PNG
 * drawn by cairo and encoded by OpenCV with the resolution recorded in a pHYs
 * chunk, PDF through cairo's PDF surface. Every writer throws
 * std::runtime_error naming the file when it cannot write it.
 */
#include <codemark/print/page.h>

#include <string>
#include <vector>

namespace codemark::print
{
/** The SVG document of \a page: root width/height in mm (e.g.
 * width="210mm") with a viewBox in mm, one <rect> per FilledRect (its name as
 * the id attribute), one <text> per TextLine. */
std::string svgDocument(const Page& page);

/** Writes svgDocument(page) to \a path. */
void writeSvg(const Page& page, const std::string& path);

/** Pixel size of \a page at \a dpi: round(mm / 25.4 * dpi) on each axis. */
void pngSize(const Page& page, double dpi, int& width_px, int& height_px);

/** Throws std::invalid_argument unless \a dpi is in 10..1200 and the PNG of
 * \a page at \a dpi has at most 32767 px a side and 2e8 pixels (800 MB
 * while drawing). */
void checkPngRaster(const Page& page, double dpi);

/** The PNG file bytes of \a page rendered at \a dpi (antialiased, 8-bit
 * RGB, one mm = dpi / 25.4 px exactly on both axes), with a pHYs chunk of
 * round(dpi / 0.0254) pixels per metre on both axes. Throws as
 * checkPngRaster(). */
std::string pngBytes(const Page& page, double dpi);

/** Writes pngBytes(page, dpi) to \a path. */
void writePng(const Page& page, const std::string& path, double dpi);

/** Returns \a png (a PNG file's bytes) with a pHYs chunk stating \a dpi
 * (pixels per metre = round(dpi / 0.0254), unit metre) right after IHDR,
 * replacing any pHYs it had. Throws std::invalid_argument when \a png is not
 * a PNG. */
std::string withPngResolution(const std::string& png, double dpi);

/** Writes \a pages as one PDF, one PDF page per Page at its exact size
 * (points = mm / 25.4 * 72). */
void writePdf(const std::vector<Page>& pages, const std::string& path);

}  // namespace codemark::print
