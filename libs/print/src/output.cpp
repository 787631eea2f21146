#include <codemark/print/output.h>

#include <cairo-pdf.h>
#include <cairo.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace codemark::print
{
namespace
{
constexpr double kMmPerInch = 25.4;
constexpr double kPointsPerInch = 72.0;
constexpr double kMinDpi = 10, kMaxDpi = 1200;
constexpr double kMaxPixels = 2e8;	// 800 MB of RGB24 while drawing
const char* const kFontFamily = "DejaVu Sans";	// Debian's default sans font
const char* const kSvgFontFamily = "DejaVu Sans, Arial, Helvetica, sans-serif";

// A length for SVG: 4 decimals (0.1 um), trailing zeros dropped.
std::string num(double v)
{
	char buf[64];
	std::snprintf(buf, sizeof(buf), "%.4f", v);
	std::string s = buf;
	if (s.find('.') != std::string::npos)
	{
		while (s.back() == '0') s.pop_back();
		if (s.back() == '.') s.pop_back();
	}
	if (s == "-0") s = "0";
	return s;
}

std::string hexColour(const Colour& c)
{
	char buf[8];
	std::snprintf(buf, sizeof(buf), "#%02x%02x%02x", c.r, c.g, c.b);
	return buf;
}

std::string xmlEscape(const std::string& in)
{
	std::string out;
	for (char ch : in)
	{
		switch (ch)
		{
			case '&':
				out += "&amp;";
				break;
			case '<':
				out += "&lt;";
				break;
			case '>':
				out += "&gt;";
				break;
			case '"':
				out += "&quot;";
				break;
			default:
				out += ch;
		}
	}
	return out;
}

void writeFile(const std::string& path, const std::string& bytes)
{
	std::ofstream f(path, std::ios::binary | std::ios::trunc);
	if (!f) throw std::runtime_error("cannot open '" + path + "' for writing");
	f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
	f.close();
	if (!f) throw std::runtime_error("failed writing '" + path + "'");
}

void checkCairo(cairo_status_t st, const std::string& what)
{
	if (st != CAIRO_STATUS_SUCCESS)
		throw std::runtime_error(what + ": cairo: " + cairo_status_to_string(st));
}

// Paints \a page in the current user space, which must be millimetres.
void drawPage(cairo_t* cr, const Page& page)
{
	cairo_set_source_rgb(cr, 1, 1, 1);
	cairo_rectangle(cr, 0, 0, page.width_mm, page.height_mm);
	cairo_fill(cr);
	// Consecutive rects of one colour are filled as one path: their union,
	// so that abutting code cells show no antialiasing seam between them.
	for (std::size_t i = 0; i < page.rects.size(); ++i)
	{
		const FilledRect& r = page.rects[i];
		cairo_rectangle(cr, r.x_mm, r.y_mm, r.w_mm, r.h_mm);
		if (i + 1 < page.rects.size() && page.rects[i + 1].colour == r.colour) continue;
		cairo_set_source_rgb(cr, r.colour.r / 255.0, r.colour.g / 255.0, r.colour.b / 255.0);
		cairo_fill(cr);
	}
	cairo_set_source_rgb(cr, 0, 0, 0);
	cairo_select_font_face(cr, kFontFamily, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
	for (const TextLine& t : page.texts)
	{
		cairo_set_font_size(cr, t.size_mm);
		cairo_text_extents_t ext;
		cairo_text_extents(cr, t.text.c_str(), &ext);
		cairo_move_to(cr, t.centre_x_mm - 0.5 * ext.x_advance, t.baseline_y_mm);
		cairo_show_text(cr, t.text.c_str());
	}
}

std::uint32_t readBe32(const std::string& s, std::size_t at)
{
	const auto* p = reinterpret_cast<const unsigned char*>(s.data() + at);
	return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) |
		   std::uint32_t(p[3]);
}

void appendBe32(std::string& s, std::uint32_t v)
{
	s += static_cast<char>((v >> 24) & 0xff);
	s += static_cast<char>((v >> 16) & 0xff);
	s += static_cast<char>((v >> 8) & 0xff);
	s += static_cast<char>(v & 0xff);
}

void checkDpi(double dpi)
{
	if (!std::isfinite(dpi) || dpi < kMinDpi || dpi > kMaxDpi)
	{
		std::ostringstream s;
		s << "dpi must be in " << kMinDpi << ".." << kMaxDpi << ", got " << dpi;
		throw std::invalid_argument(s.str());
	}
}

using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using ContextPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;
}  // namespace

std::string svgDocument(const Page& page)
{
	std::ostringstream s;
	s << "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n"
	  << "<!-- codemark landmark(s) at exact size: 1 user unit = 1 mm -->\n"
	  << "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" << num(page.width_mm)
	  << "mm\" height=\"" << num(page.height_mm) << "mm\" viewBox=\"0 0 " << num(page.width_mm)
	  << " " << num(page.height_mm) << "\">\n";
	s << "  <rect id=\"page\" x=\"0\" y=\"0\" width=\"" << num(page.width_mm) << "\" height=\""
	  << num(page.height_mm) << "\" fill=\"#ffffff\"/>\n";
	for (const FilledRect& r : page.rects)
		s << "  <rect id=\"" << xmlEscape(r.name) << "\" x=\"" << num(r.x_mm) << "\" y=\""
		  << num(r.y_mm) << "\" width=\"" << num(r.w_mm) << "\" height=\"" << num(r.h_mm)
		  << "\" fill=\"" << hexColour(r.colour) << "\"/>\n";
	for (const TextLine& t : page.texts)
		s << "  <text x=\"" << num(t.centre_x_mm) << "\" y=\"" << num(t.baseline_y_mm)
		  << "\" font-family=\"" << kSvgFontFamily << "\" font-size=\"" << num(t.size_mm)
		  << "\" text-anchor=\"middle\" fill=\"#000000\">" << xmlEscape(t.text) << "</text>\n";
	s << "</svg>\n";
	return s.str();
}

void writeSvg(const Page& page, const std::string& path) { writeFile(path, svgDocument(page)); }

void pngSize(const Page& page, double dpi, int& width_px, int& height_px)
{
	width_px = static_cast<int>(std::lround(page.width_mm / kMmPerInch * dpi));
	height_px = static_cast<int>(std::lround(page.height_mm / kMmPerInch * dpi));
}

void checkPngRaster(const Page& page, double dpi)
{
	checkDpi(dpi);
	int w = 0, h = 0;
	pngSize(page, dpi, w, h);
	if (w < 1 || h < 1 || double(w) * double(h) > kMaxPixels || w > 32767 || h > 32767)
	{
		std::ostringstream s;
		s << "a " << w << " x " << h << " px PNG is outside what codemark-print draws "
		  << "(at most 32767 px a side and " << kMaxPixels << " px); lower --dpi";
		throw std::invalid_argument(s.str());
	}
}

std::string pngBytes(const Page& page, double dpi)
{
	checkPngRaster(page, dpi);
	int w = 0, h = 0;
	pngSize(page, dpi, w, h);
	SurfacePtr surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h), cairo_surface_destroy);
	checkCairo(cairo_surface_status(surface.get()), "creating the PNG image");
	ContextPtr cr(cairo_create(surface.get()), cairo_destroy);
	// Exactly dpi: one mm is dpi / 25.4 px on both axes; the page's pixel
	// size is rounded, so its last row/column may be cut by < 0.5 px.
	const double px_per_mm = dpi / kMmPerInch;
	cairo_scale(cr.get(), px_per_mm, px_per_mm);
	drawPage(cr.get(), page);
	checkCairo(cairo_status(cr.get()), "drawing the PNG image");
	cairo_surface_flush(surface.get());
	// OpenCV encodes: 3x faster than cairo's writer on these flat images.
	// RGB24 pixels are 32-bit xRGB words, i.e. B, G, R, x bytes on a
	// little-endian machine and x, R, G, B on a big-endian one.
	const cv::Mat xrgb(
		h, w, CV_8UC4, cairo_image_surface_get_data(surface.get()),
		static_cast<std::size_t>(cairo_image_surface_get_stride(surface.get())));
	cv::Mat bgr;
	const std::uint32_t probe = 1;
	if (*reinterpret_cast<const unsigned char*>(&probe) == 1)
		cv::cvtColor(xrgb, bgr, cv::COLOR_BGRA2BGR);
	else
	{
		bgr.create(h, w, CV_8UC3);
		const int from_to[] = {3, 0, 2, 1, 1, 2};  // B, G, R from x, R, G, B
		cv::mixChannels(&xrgb, 1, &bgr, 1, from_to, 3);
	}
	std::vector<unsigned char> png;
	if (!cv::imencode(".png", bgr, png)) throw std::runtime_error("PNG encoding failed");
	return withPngResolution(std::string(png.begin(), png.end()), dpi);
}

void writePng(const Page& page, const std::string& path, double dpi)
{
	writeFile(path, pngBytes(page, dpi));
}

// Hand-written because neither cairo's PNG writer nor OpenCV's imencode
// writes a pHYs chunk; the chunk's CRC comes from zlib, as in libpng.
std::string withPngResolution(const std::string& png, double dpi)
{
	checkDpi(dpi);
	static const char kSignature[8] = {'\x89', 'P', 'N', 'G', '\r', '\n', '\x1a', '\n'};
	if (png.size() < 8 + 25 || std::memcmp(png.data(), kSignature, 8) != 0 ||
		png.compare(12, 4, "IHDR") != 0)
		throw std::invalid_argument("not a PNG file (no signature and IHDR chunk)");

	std::string chunk = "pHYs";
	const auto ppm = static_cast<std::uint32_t>(std::lround(dpi / 0.0254));
	appendBe32(chunk, ppm);	 // pixels per unit, x
	appendBe32(chunk, ppm);	 // pixels per unit, y
	chunk += '\x01';  // unit: metre
	const auto crc = static_cast<std::uint32_t>(
		crc32(0L, reinterpret_cast<const Bytef*>(chunk.data()), static_cast<uInt>(chunk.size())));

	std::string out(png, 0, 8);
	std::size_t at = 8;
	bool first = true;
	while (at + 12 <= png.size())
	{
		const std::uint32_t len = readBe32(png, at);
		const std::size_t total = 12 + std::size_t(len);
		if (at + total > png.size()) throw std::invalid_argument("truncated PNG chunk");
		const bool is_phys = png.compare(at + 4, 4, "pHYs") == 0;
		if (!is_phys) out.append(png, at, total);
		if (first)
		{
			appendBe32(out, 9);
			out += chunk;
			appendBe32(out, crc);
			first = false;
		}
		at += total;
	}
	return out;
}

void writePdf(const std::vector<Page>& pages, const std::string& path)
{
	if (pages.empty()) throw std::invalid_argument("no pages to write to '" + path + "'");
	const double pt_per_mm = kPointsPerInch / kMmPerInch;
	SurfacePtr surface(
		cairo_pdf_surface_create(
			path.c_str(), pages[0].width_mm * pt_per_mm, pages[0].height_mm * pt_per_mm),
		cairo_surface_destroy);
	checkCairo(cairo_surface_status(surface.get()), "cannot write '" + path + "'");
	cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_TITLE, "codemark landmarks");
	cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_CREATOR, "codemark-print");
	ContextPtr cr(cairo_create(surface.get()), cairo_destroy);
	for (const Page& page : pages)
	{
		cairo_pdf_surface_set_size(
			surface.get(), page.width_mm * pt_per_mm, page.height_mm * pt_per_mm);
		cairo_save(cr.get());
		cairo_scale(cr.get(), pt_per_mm, pt_per_mm);
		drawPage(cr.get(), page);
		cairo_restore(cr.get());
		cairo_show_page(cr.get());
	}
	checkCairo(cairo_status(cr.get()), "drawing '" + path + "'");
	cr.reset();
	cairo_surface_finish(surface.get());
	checkCairo(cairo_surface_status(surface.get()), "writing '" + path + "'");
}

}  // namespace codemark::print
