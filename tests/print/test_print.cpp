// Tests of libs/print and apps/codemark-print: the printed files read back
// give the right ID and the right physical sizes.
#include <codemark/landmark/codebook.h>
#include <codemark/print/output.h>
#include <codemark/print/page.h>
#include <codemark/print/print.h>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <unistd.h>
#include <sys/wait.h>
#include <algorithm>
#include <array>
#include <sstream>
#include <string>
#include <vector>

using namespace codemark;
using namespace codemark::print;
namespace fs = std::filesystem;

namespace
{
constexpr double kMmPerInch = 25.4;
constexpr double kPtPerMm = 72.0 / 25.4;

// A fresh, empty folder under the system's temp dir, removed at the end.
struct TempDir
{
	fs::path path;
	explicit TempDir(const std::string& name)
	{
		path = fs::temp_directory_path() /
			   ("codemark-test-print-" + name + "-" + std::to_string(::getpid()));
		fs::remove_all(path);
	}
	~TempDir()
	{
		std::error_code ec;
		fs::remove_all(path, ec);
	}
	std::string str() const { return path.string(); }
};

std::string readFile(const fs::path& p)
{
	std::ifstream f(p, std::ios::binary);
	std::ostringstream s;
	s << f.rdbuf();
	return s.str();
}

PrintOptions options(
	const std::vector<int>& ids, const std::string& dir, const std::string& formats)
{
	PrintOptions o;
	o.ids = ids;
	o.out_dir = dir;
	o.formats = parseFormats(formats);
	return o;
}

// ---- PNG chunks -------------------------------------------------------
struct PngChunk
{
	std::string type;
	std::string data;
	bool crc_ok = false;
};

std::uint32_t be32(const std::string& s, std::size_t at)
{
	const auto* p = reinterpret_cast<const unsigned char*>(s.data() + at);
	return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) |
		   std::uint32_t(p[3]);
}

std::vector<PngChunk> pngChunks(const std::string& png)
{
	std::vector<PngChunk> out;
	if (png.size() < 8 || png.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return out;
	std::size_t at = 8;
	while (at + 12 <= png.size())
	{
		const std::uint32_t len = be32(png, at);
		if (at + 12 + len > png.size()) break;
		PngChunk c;
		c.type = png.substr(at + 4, 4);
		c.data = png.substr(at + 8, len);
		const auto crc = crc32(0L, reinterpret_cast<const Bytef*>(png.data() + at + 4), len + 4);
		c.crc_ok = crc == be32(png, at + 8 + len);
		out.push_back(c);
		at += 12 + len;
	}
	return out;
}

// ---- SVG elements -----------------------------------------------------
using Attributes = std::map<std::string, std::string>;

// The attributes of every <tag ...> element of \a svg, in order. Enough for
// the flat documents that svgDocument() writes.
std::vector<Attributes> svgElements(const std::string& svg, const std::string& tag)
{
	std::vector<Attributes> out;
	const std::regex element("<" + tag + R"(\s([^>]*)>)");
	const std::regex attribute(R"(([A-Za-z_:][-A-Za-z0-9_:.]*)\s*=\s*"([^"]*)\")");
	for (auto it = std::sregex_iterator(svg.begin(), svg.end(), element);
		 it != std::sregex_iterator(); ++it)
	{
		Attributes a;
		const std::string body = (*it)[1];
		for (auto jt = std::sregex_iterator(body.begin(), body.end(), attribute);
			 jt != std::sregex_iterator(); ++jt)
			a[(*jt)[1]] = (*jt)[2];
		out.push_back(a);
	}
	return out;
}

const Attributes* byId(const std::vector<Attributes>& v, const std::string& id)
{
	for (const auto& a : v)
		if (a.count("id") && a.at("id") == id) return &a;
	return nullptr;
}

double mmAttribute(const Attributes& a, const std::string& key)
{
	const std::string v = a.at(key);
	EXPECT_EQ(v.substr(v.size() - 2), "mm") << key << "=" << v;
	return std::stod(v.substr(0, v.size() - 2));
}

// ---- PDF pages --------------------------------------------------------
// Every page's MediaBox [x0 y0 x1 y1] in points.
std::vector<std::array<double, 4>> pdfMediaBoxes(const std::string& pdf)
{
	std::vector<std::array<double, 4>> out;
	const std::regex box(
		R"(/MediaBox\s*\[\s*([-0-9.]+)\s+([-0-9.]+)\s+([-0-9.]+)\s+([-0-9.]+)\s*\])");
	for (auto it = std::sregex_iterator(pdf.begin(), pdf.end(), box); it != std::sregex_iterator();
		 ++it)
		out.push_back(
			{std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3]), std::stod((*it)[4])});
	return out;
}

// ---- reading a printed landmark back -----------------------------------
// Mean BGR of a small square around the point (x_mm, y_mm) of the page.
cv::Vec3d meanAt(const cv::Mat& img, double px_per_mm, double x_mm, double y_mm, int half = 2)
{
	// Pixel (0,0) is the centre of the top-left pixel: the point x_mm lies at
	// x_mm * px_per_mm - 0.5.
	const int u = static_cast<int>(std::lround(x_mm * px_per_mm - 0.5));
	const int v = static_cast<int>(std::lround(y_mm * px_per_mm - 0.5));
	const cv::Rect r(u - half, v - half, 2 * half + 1, 2 * half + 1);
	const cv::Scalar m = cv::mean(img(r & cv::Rect(0, 0, img.cols, img.rows)));
	return {m[0], m[1], m[2]};
}

bool isBlack(const cv::Vec3d& bgr) { return bgr[0] < 40 && bgr[1] < 40 && bgr[2] < 40; }
bool isGreen(const cv::Vec3d& bgr) { return bgr[0] < 40 && bgr[1] > 215 && bgr[2] < 40; }
bool isWhite(const cv::Vec3d& bgr) { return bgr[0] > 215 && bgr[1] > 215 && bgr[2] > 215; }

// Reads the ID of the landmark whose outer frame has its top-left corner at
// (frame_x_mm, frame_y_mm), sizes in mm of the spec times \a scale, by
// sampling the nine cell centres; -1 when a cell is neither black nor green
// or the centre is green.
int decodeAt(
	const cv::Mat& img, double px_per_mm, double frame_x_mm, double frame_y_mm, double scale)
{
	CodeCells cells{};
	const double cx = frame_x_mm + 100 * scale, cy = frame_y_mm + 100 * scale;
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
		{
			const cv::Vec3d m =
				meanAt(img, px_per_mm, cx + (c - 1) * 30 * scale, cy + (r - 1) * 30 * scale);
			if (!isBlack(m) && !isGreen(m)) return -1;
			cells[r][c] = isBlack(m);
		}
	const auto id = decodeCells(cells);
	return id ? *id : -1;
}

// Positions [mm] along the row through \a y_mm where the colour class
// changes (white/black/green), at the middle of the transition pixel.
std::vector<double> transitionsAlongRow(const cv::Mat& img, double px_per_mm, double y_mm)
{
	const int v = static_cast<int>(std::lround(y_mm * px_per_mm - 0.5));
	auto cls = [&](int u)
	{
		const cv::Vec3b p = img.at<cv::Vec3b>(v, u);
		if (p[1] > 128 && p[2] > 128) return 0;	 // white
		if (p[1] > 128) return 2;  // green
		return 1;  // black
	};
	std::vector<double> out;
	for (int u = 1; u < img.cols; ++u)
		if (cls(u) != cls(u - 1)) out.push_back(u / px_per_mm);	 // edge between u-1 and u
	return out;
}
}  // namespace

// (a) The printed PNG, read back and sampled at the cell centres located from
// the spec's geometry, gives the ID; its frame measures 200 / 160 mm.
TEST(PrintPng, ReadBackDecodesTheIdAndMeasuresTheFrame)
{
	TempDir dir("png");
	const std::vector<int> ids = {0, 255, 37, 170, 85, 1, 128};
	for (int id : ids)
	{
		// 600 dpi for the extreme IDs, a lighter 200 dpi for the others.
		const double dpi = (id == 0 || id == 255) ? 600 : 200;
		PrintOptions o = options({id}, dir.str(), "png");
		o.dpi = dpi;
		run(o);
		const fs::path file = dir.path / ("codemark-" + std::to_string(id) + ".png");
		const cv::Mat img = cv::imread(file.string(), cv::IMREAD_COLOR);
		ASSERT_FALSE(img.empty()) << file;
		const double ppmm = dpi / kMmPerInch;
		// The page: the 200 mm frame and a 5 mm quiet margin each side.
		EXPECT_NEAR(img.cols / ppmm, 210.0, 1.0 / ppmm) << "id " << id;
		EXPECT_GT(img.rows / ppmm, 210.0) << "room for the label";
		const double fx = 0.5 * (img.cols / ppmm - 200.0), fy = 5.0;

		EXPECT_EQ(decodeAt(img, ppmm, fx, fy, 1.0), id) << "dpi " << dpi;

		// Along the row through the centre (the centre cell is black):
		// white | black frame | green | black centre cell | green | black frame | white.
		const auto t = transitionsAlongRow(img, ppmm, fy + 100);
		const double tol = 1.0 / ppmm;	// one pixel
		ASSERT_GE(t.size(), 6u) << "id " << id;
		EXPECT_NEAR(t.front(), fx, tol);
		EXPECT_NEAR(t.back() - t.front(), 200.0, tol) << "outer frame [mm]";
		EXPECT_NEAR(t[t.size() - 2] - t[1], 160.0, tol) << "reference square [mm]";
		EXPECT_NEAR(t[1] - t[0], 20.0, tol) << "frame bar [mm]";

		// Abutting black cells print as one black area: not a trace of green
		// along their shared edge (separately antialiased cells leave a seam
		// of up to 25% green in the pixels the edge crosses).
		const CodeCells cells = encodeId(id);
		auto maxGreen = [&](double x0, double y0, double x1, double y1)
		{
			const cv::Rect r(
				cv::Point(int(std::floor(x0 * ppmm)), int(std::floor(y0 * ppmm))),
				cv::Point(int(std::ceil(x1 * ppmm)), int(std::ceil(y1 * ppmm))));
			std::vector<cv::Mat> ch;
			cv::split(img(r), ch);
			double lo, hi;
			cv::minMaxLoc(ch[1], &lo, &hi);
			return hi;
		};
		for (int r = 0; r < 3; ++r)
			for (int c = 0; c < 3; ++c)
			{
				const double x = fx + 55 + 30 * c, y = fy + 55 + 30 * r;  // cell's top-left [mm]
				if (c < 2 && cells[r][c] && cells[r][c + 1])
				{
					EXPECT_LE(maxGreen(x + 29, y + 2, x + 31, y + 28), 3)
						<< "seam right of r" << r << "c" << c << " of ID " << id;
				}
				if (r < 2 && cells[r][c] && cells[r + 1][c])
				{
					EXPECT_LE(maxGreen(x + 2, y + 29, x + 28, y + 31), 3)
						<< "seam below r" << r << "c" << c << " of ID " << id;
				}
			}

		// The quiet margin is white all round, 2.5 mm off the frame, and
		// the label lies below it.
		for (double s = 0; s <= 200; s += 10)
		{
			EXPECT_TRUE(isWhite(meanAt(img, ppmm, fx - 2.5, fy + s, 1)));
			EXPECT_TRUE(isWhite(meanAt(img, ppmm, fx + 202.5, fy + s, 1)));
			EXPECT_TRUE(isWhite(meanAt(img, ppmm, fx + s, fy - 2.5, 1)));
			EXPECT_TRUE(isWhite(meanAt(img, ppmm, fx + s, fy + 202.5, 1)));
		}
		const int label_top = static_cast<int>(std::ceil((fy + 205) * ppmm));
		cv::Mat band;
		cv::cvtColor(img.rowRange(label_top, img.rows), band, cv::COLOR_BGR2GRAY);
		EXPECT_GT(cv::countNonZero(band < 128), 50) << "no label text below the margin";
	}
}

// The printed label lies where the layout reserves room for it: below the
// frame's quiet margin and inside the ink box that sheets keep apart, also
// at small scales where it is wider than the frame.
TEST(PrintPng, LabelStaysInsideItsBox)
{
	for (double scale : {0.2, 1.0})
	{
		const LandmarkGeometry g = LandmarkGeometry::scaled(scale);
		Page page;
		page.width_mm = 150 * scale + 60;
		page.height_mm = 250 * scale + 20;
		const Placement p = appendLandmark(page, g, 255, 30, 10);
		const double dpi = 300, ppmm = dpi / kMmPerInch;
		const std::string png = pngBytes(page, dpi);
		const cv::Mat img =
			cv::imdecode(std::vector<unsigned char>(png.begin(), png.end()), cv::IMREAD_GRAYSCALE);
		ASSERT_FALSE(img.empty());
		const double below_margin_mm = p.frame_y_mm + 200 * scale + 5 * scale;
		const int top = static_cast<int>(std::ceil(below_margin_mm * ppmm));
		std::vector<cv::Point> ink;
		cv::findNonZero(img.rowRange(top, img.rows) < 128, ink);
		ASSERT_GT(ink.size(), 20u) << "no label at scale " << scale;
		const cv::Rect box = cv::boundingRect(ink);
		EXPECT_GE(box.x / ppmm, p.ink_x_mm) << "scale " << scale;
		EXPECT_LE((box.x + box.width) / ppmm, p.ink_x_mm + p.ink_w_mm) << "scale " << scale;
		EXPECT_LE((top + box.y + box.height) / ppmm, p.ink_y_mm + p.ink_h_mm) << "scale " << scale;
		// Nothing but the label between the frame's margin and the label.
		std::vector<cv::Point> in_margin;
		const int frame_bottom =
			static_cast<int>(std::ceil((p.frame_y_mm + 200 * scale) * ppmm)) + 1;
		cv::findNonZero(img.rowRange(frame_bottom, top) < 250, in_margin);
		EXPECT_TRUE(in_margin.empty()) << "ink in the quiet margin at scale " << scale;
	}
}

// (b) The PNG records 600 dpi in its pHYs chunk (pixels per metre, unit 1),
// before the image data, with valid CRCs throughout.
TEST(PrintPng, PhysChunkStates600Dpi)
{
	TempDir dir("phys");
	run(options({37}, dir.str(), "png"));
	const std::string png = readFile(dir.path / "codemark-37.png");
	const auto chunks = pngChunks(png);
	ASSERT_GE(chunks.size(), 3u);
	EXPECT_EQ(chunks.front().type, "IHDR");
	EXPECT_EQ(chunks.back().type, "IEND");
	int phys = -1, first_idat = -1;
	for (std::size_t i = 0; i < chunks.size(); ++i)
	{
		EXPECT_TRUE(chunks[i].crc_ok) << chunks[i].type;
		if (chunks[i].type == "pHYs") phys = static_cast<int>(i);
		if (chunks[i].type == "IDAT" && first_idat < 0) first_idat = static_cast<int>(i);
	}
	ASSERT_GE(phys, 0) << "no pHYs chunk";
	EXPECT_LT(phys, first_idat) << "pHYs must precede IDAT";
	const std::string& d = chunks[phys].data;
	ASSERT_EQ(d.size(), 9u);
	EXPECT_EQ(static_cast<int>(d[8]), 1) << "unit must be the metre";
	EXPECT_NEAR(be32(d, 0) * 0.0254, 600.0, 0.02) << "x dpi";
	EXPECT_NEAR(be32(d, 4) * 0.0254, 600.0, 0.02) << "y dpi";
	// The image's size in pixels is the page at 600 dpi.
	const Page page = landmarkPage(LandmarkGeometry::scaled(1.0), 37);
	EXPECT_NEAR(be32(chunks[0].data, 0), page.width_mm / kMmPerInch * 600, 0.5);
	EXPECT_NEAR(be32(chunks[0].data, 4), page.height_mm / kMmPerInch * 600, 0.5);

	// Re-stamping replaces the chunk rather than adding a second one.
	const auto again = pngChunks(withPngResolution(png, 300));
	int count = 0;
	for (const auto& c : again)
		if (c.type == "pHYs")
		{
			++count;
			EXPECT_NEAR(be32(c.data, 0) * 0.0254, 300.0, 0.02);
			EXPECT_TRUE(c.crc_ok);
		}
	EXPECT_EQ(count, 1);
	EXPECT_THROW(
		withPngResolution("not a png at all, but long enough to look", 600), std::invalid_argument);
}

// (c) The SVG is in millimetres: root width/height in mm equal to the viewBox,
// the outer frame 200 mm, the reference square 160 mm, cells 30 mm; all
// times 1.5 at --scale 1.5.
TEST(PrintSvg, FrameAndReferenceSquareMeasureTheSpecTimesScale)
{
	for (double scale : {1.0, 1.5})
	{
		TempDir dir("svg");
		PrintOptions o = options({200}, dir.str(), "svg");
		o.scale = scale;
		run(o);
		const std::string svg = readFile(dir.path / "codemark-200.svg");
		const auto roots = svgElements(svg, "svg");
		ASSERT_EQ(roots.size(), 1u);
		const double w = mmAttribute(roots[0], "width"), h = mmAttribute(roots[0], "height");
		std::istringstream vb(roots[0].at("viewBox"));
		double vx, vy, vw, vh;
		vb >> vx >> vy >> vw >> vh;
		EXPECT_EQ(vx, 0);
		EXPECT_EQ(vy, 0);
		EXPECT_NEAR(vw, w, 1e-9) << "one user unit must be one mm";
		EXPECT_NEAR(vh, h, 1e-9);

		const auto rects = svgElements(svg, "rect");
		const Attributes* outer = byId(rects, "lm200-frame-outer");
		const Attributes* fill = byId(rects, "lm200-fill");
		ASSERT_TRUE(outer && fill);
		EXPECT_NEAR(std::stod(outer->at("width")), 200 * scale, 1e-3);
		EXPECT_NEAR(std::stod(outer->at("height")), 200 * scale, 1e-3);
		EXPECT_EQ(outer->at("fill"), "#000000");
		EXPECT_NEAR(std::stod(fill->at("width")), 160 * scale, 1e-3);
		EXPECT_NEAR(std::stod(fill->at("height")), 160 * scale, 1e-3);
		EXPECT_EQ(fill->at("fill"), "#00ff00");
		// The reference square is centred in the frame.
		EXPECT_NEAR(std::stod(fill->at("x")) - std::stod(outer->at("x")), 20 * scale, 1e-3);
		EXPECT_NEAR(std::stod(fill->at("y")) - std::stod(outer->at("y")), 20 * scale, 1e-3);
		// Quiet margin of at least 5 mm (times the scale) on all sides.
		const double ox = std::stod(outer->at("x")), oy = std::stod(outer->at("y"));
		EXPECT_GE(ox, 5 * scale - 1e-3);
		EXPECT_GE(oy, 5 * scale - 1e-3);
		EXPECT_GE(w - ox - 200 * scale, 5 * scale - 1e-3);
		EXPECT_GE(h - oy - 200 * scale, 5 * scale - 1e-3);

		// The black cells of ID 200 = 0b11001000 (spec bit order: bits 7, 6, 3
		// are r0c0, r0c1, r1c2) plus the centre, each 30 mm, at the right
		// place; an asymmetric ID, so a transposed board fails.
		const bool expected[3][3] = {
			{true, true, false}, {false, true, true}, {false, false, false}};
		const CodeCells cells = encodeId(200);
		int black = 0;
		for (int r = 0; r < 3; ++r)
			for (int c = 0; c < 3; ++c)
			{
				const Attributes* cell =
					byId(rects, "lm200-cell-r" + std::to_string(r) + "c" + std::to_string(c));
				EXPECT_EQ(cell != nullptr, cells[r][c]) << r << "," << c;
				EXPECT_EQ(cell != nullptr, expected[r][c]) << r << "," << c;
				if (!cell) continue;
				++black;
				EXPECT_NEAR(std::stod(cell->at("width")), 30 * scale, 1e-3);
				EXPECT_NEAR(std::stod(cell->at("x")) - ox, (55 + 30 * c) * scale, 1e-3);
				EXPECT_NEAR(std::stod(cell->at("y")) - oy, (55 + 30 * r) * scale, 1e-3);
			}
		EXPECT_EQ(black, 4);

		// The label, below the frame and outside the quiet margin.
		const auto texts = svgElements(svg, "text");
		ASSERT_EQ(texts.size(), 1u);
		EXPECT_GT(
			std::stod(texts[0].at("y")) - std::stod(texts[0].at("font-size")) * 0.8,
			oy + 205 * scale);
		EXPECT_NE(
			svg.find("codemark ID 200 (scale " + std::string(scale == 1.0 ? "1.0" : "1.5")),
			std::string::npos);
		EXPECT_NE(
			svg.find(scale == 1.0 ? "reference square 160 mm" : "reference square 240 mm"),
			std::string::npos);
	}
}

// (d) The PDF page is the page's size in points (mm / 25.4 * 72).
TEST(PrintPdf, MediaBoxIsTheExactPageSize)
{
	for (double scale : {1.0, 0.5})
	{
		TempDir dir("pdf");
		PrintOptions o = options({200}, dir.str(), "pdf,svg");
		o.scale = scale;
		run(o);
		const std::string svg = readFile(dir.path / "codemark-200.svg");
		const auto roots = svgElements(svg, "svg");
		ASSERT_EQ(roots.size(), 1u);
		const double w_mm = mmAttribute(roots[0], "width"), h_mm = mmAttribute(roots[0], "height");
		EXPECT_NEAR(w_mm, 210 * scale, 1e-6);

		const auto boxes = pdfMediaBoxes(readFile(dir.path / "codemark-200.pdf"));
		ASSERT_EQ(boxes.size(), 1u);
		EXPECT_NEAR(boxes[0][0], 0, 1e-6);
		EXPECT_NEAR(boxes[0][1], 0, 1e-6);
		EXPECT_NEAR(boxes[0][2], w_mm * kPtPerMm, 1e-3);
		EXPECT_NEAR(boxes[0][3], h_mm * kPtPerMm, 1e-3);
	}
}

// (e) Bad options give one clear error and write nothing.
TEST(PrintRun, RejectsBadOptionsWithOneClearLine)
{
	TempDir dir("errors");
	auto expectInvalid = [&](PrintOptions o, const std::string& needle)
	{
		try
		{
			run(o);
			ADD_FAILURE() << "no error for " << needle;
		}
		catch (const std::invalid_argument& e)
		{
			const std::string msg = e.what();
			EXPECT_NE(msg.find(needle), std::string::npos) << msg;
			EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
		}
		EXPECT_FALSE(fs::exists(dir.path)) << "nothing may be written on error";
	};
	expectInvalid(options({256}, dir.str(), "svg"), "ID 256 is outside 0..255");
	expectInvalid(options({-1}, dir.str(), "svg"), "ID -1 is outside 0..255");
	expectInvalid(options({37, 38, 37}, dir.str(), "svg"), "ID 37 is given more than once");
	expectInvalid(options({}, dir.str(), "svg"), "no landmark ID");
	PrintOptions o = options({37}, dir.str(), "svg");
	for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL})
	{
		o.scale = bad;
		expectInvalid(o, "--scale must be");
	}
	o = options({37}, dir.str(), "png");
	o.dpi = 0;
	expectInvalid(o, "dpi must be in 10..1200");
	o.dpi = 600;
	o.sheet = true;
	o.scale = 1.1;	// a 220 mm frame on a 210 mm page
	expectInvalid(o, "does not fit on A4");
	o.scale = 1.0;
	o.paper_border_mm = 5.5;  // 200 + 2 x 5.5 > 210
	expectInvalid(o, "does not fit on A4");
	o.paper_border_mm = -1;
	expectInvalid(o, "paper border");
	o = options({37}, dir.str(), "svg");
	o.landmark_ini = (dir.path.parent_path() / "no-such-landmark.ini").string();
	expectInvalid(o, "no-such-landmark.ini");

	// Formats and IDs as the app receives them.
	EXPECT_THROW(parseFormats("svg,jpg"), std::invalid_argument);
	try
	{
		parseFormats("svg,jpg");
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("'jpg'"), std::string::npos) << e.what();
	}
	EXPECT_THROW(parseFormats(""), std::invalid_argument);
	EXPECT_THROW(parseFormats("svg,,png"), std::invalid_argument);
	EXPECT_EQ(parseFormats(" PNG , svg,png").size(), 2u);
	std::vector<int> ids;
	EXPECT_THROW(parseIds("abc", ids), std::invalid_argument);
	EXPECT_THROW(parseIds("3.5", ids), std::invalid_argument);
	EXPECT_THROW(parseIds("9-3", ids), std::invalid_argument);
	EXPECT_THROW(parseIds("250-300", ids), std::invalid_argument);
	ids.clear();
	parseIds("7", ids);
	parseIds("1,2, 3", ids);
	parseIds("10-12", ids);
	EXPECT_EQ(ids, (std::vector<int>{7, 1, 2, 3, 10, 11, 12}));

	// An output folder that cannot be created: below a regular file.
	fs::create_directories(dir.path);
	const fs::path file = dir.path / "a-file";
	std::ofstream(file) << "x";
	EXPECT_THROW(run(options({37}, (file / "sub").string(), "svg")), std::runtime_error);
	EXPECT_THROW(run(options({37}, file.string(), "svg")), std::runtime_error);
	EXPECT_FALSE(fs::exists(dir.path / "codemark-37.svg"));
}

// The --landmark ini sets the sizes (its own scale included), and --scale
// multiplies them further; a broken ini is an error naming the file.
TEST(PrintRun, LandmarkIniSetsTheSizes)
{
	TempDir dir("ini");
	fs::create_directories(dir.path);
	const fs::path ini = dir.path / "lm.ini";
	std::ofstream(ini) << "[LANDMARK]\nouter_size_m = 0.200\ninner_size_m = 0.160\n"
						  "cell_size_m = 0.030\nmargin_m = 0.005\nscale = 0.5\n";
	PrintOptions o = options({5}, (dir.path / "out").string(), "svg");
	o.landmark_ini = ini.string();
	o.scale = 3.0;
	const LandmarkGeometry g = geometryOf(o);
	EXPECT_NEAR(g.outer_size_m, 0.300, 1e-12);
	EXPECT_NEAR(g.inner_size_m, 0.240, 1e-12);
	run(o);
	const auto rects = svgElements(readFile(dir.path / "out" / "codemark-5.svg"), "rect");
	ASSERT_TRUE(byId(rects, "lm5-fill"));
	EXPECT_NEAR(std::stod(byId(rects, "lm5-fill")->at("width")), 240.0, 1e-3);

	const fs::path bad = dir.path / "bad.ini";
	std::ofstream(bad) << "[LANDMARK]\nouter_size_m = 0.100\ninner_size_m = 0.160\n";
	o.landmark_ini = bad.string();
	try
	{
		run(o);
		ADD_FAILURE() << "inner > outer accepted";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("bad.ini"), std::string::npos) << e.what();
	}
}

// (f) An A4 sheet at scale 0.5 holds several landmarks that do not overlap,
// and each reads back as its ID.
TEST(PrintSheet, HalfScaleSheetHoldsSeveralDisjointLandmarks)
{
	const LandmarkGeometry g = LandmarkGeometry::scaled(0.5);
	EXPECT_EQ(landmarksPerSheet(LandmarkGeometry::scaled(1.0)), 1);
	EXPECT_EQ(landmarksPerSheet(g), 4) << "2 x 2 at scale 0.5 with the 3 mm border";
	EXPECT_EQ(landmarksPerSheet(g, 4.2), 2) << "one column with a 4.2 mm border";
	EXPECT_EQ(landmarksPerSheet(LandmarkGeometry::scaled(1.0), 5.5), 0);
	EXPECT_EQ(landmarksPerSheet(LandmarkGeometry::scaled(1.1)), 0);
	EXPECT_GE(landmarksPerSheet(LandmarkGeometry::scaled(0.25)), 12);

	std::vector<int> ids;
	for (int id = 0; id < 10; ++id) ids.push_back(id * 25);
	for (double border : {kDefaultPaperBorder_mm, 0.0, 4.2})
	{
		std::vector<std::vector<Placement>> placed;
		const auto pages = sheetPages(g, ids, border, &placed);
		const int per_page = landmarksPerSheet(g, border);
		ASSERT_GT(per_page, 1);
		ASSERT_EQ(pages.size(), static_cast<std::size_t>((10 + per_page - 1) / per_page));
		ASSERT_EQ(placed.size(), pages.size());
		EXPECT_EQ(static_cast<int>(placed[0].size()), per_page);
		std::size_t total = 0;
		const double frame = 100, margin = 2.5;	 // scale 0.5
		const double edge = std::max(margin, border) - 1e-9;
		for (const auto& page_placements : placed)
		{
			total += page_placements.size();
			for (std::size_t i = 0; i < page_placements.size(); ++i)
			{
				const Placement& a = page_placements[i];
				// The frame keeps its quiet margin and the printer's border
				// from the paper's edge; the label stays inside the border.
				EXPECT_GE(a.frame_x_mm, edge);
				EXPECT_GE(a.frame_y_mm, edge);
				EXPECT_LE(a.frame_x_mm + frame, kA4Width_mm - edge);
				EXPECT_LE(a.frame_y_mm + frame, kA4Height_mm - edge);
				EXPECT_GE(a.ink_x_mm, border - 1e-9);
				EXPECT_LE(a.ink_x_mm + a.ink_w_mm, kA4Width_mm - border + 1e-9);
				EXPECT_LE(a.ink_y_mm + a.ink_h_mm, kA4Height_mm - border + 1e-9);
				EXPECT_GT(a.ink_h_mm, frame + margin) << "the label's band";
				for (std::size_t j = 0; j < page_placements.size(); ++j)
				{
					if (i == j) continue;
					const Placement& b = page_placements[j];
					// No ink of b inside a's frame grown by its quiet margin.
					const double x0 = a.frame_x_mm - margin, x1 = a.frame_x_mm + frame + margin;
					const double y0 = a.frame_y_mm - margin, y1 = a.frame_y_mm + frame + margin;
					const bool apart =
						b.ink_x_mm >= x1 - 1e-9 || b.ink_x_mm + b.ink_w_mm <= x0 + 1e-9 ||
						b.ink_y_mm >= y1 - 1e-9 || b.ink_y_mm + b.ink_h_mm <= y0 + 1e-9;
					EXPECT_TRUE(apart) << b.id << " intrudes on " << a.id << "'s quiet margin";
				}
			}
		}
		EXPECT_EQ(total, ids.size());
	}

	// The written sheet: one multi-page PDF of A4 pages and a PNG/SVG per page
	// in which every landmark reads back.
	TempDir dir("sheet");
	PrintOptions o = options(ids, dir.str(), "svg,png,pdf");
	o.scale = 0.5;
	o.sheet = true;
	o.dpi = 150;
	std::vector<std::vector<Placement>> placed;
	const auto pages = sheetPages(g, ids, o.paper_border_mm, &placed);
	const PrintReport report = run(o);
	EXPECT_EQ(report.pages, static_cast<int>(pages.size()));
	const auto boxes = pdfMediaBoxes(readFile(dir.path / "codemark-sheet.pdf"));
	ASSERT_EQ(boxes.size(), pages.size());
	for (const auto& b : boxes)
	{
		EXPECT_NEAR(b[2], kA4Width_mm * kPtPerMm, 1e-3);
		EXPECT_NEAR(b[3], kA4Height_mm * kPtPerMm, 1e-3);
	}
	EXPECT_FALSE(fs::exists(dir.path / "codemark-0.svg")) << "--sheet writes sheets only";
	for (std::size_t p = 0; p < pages.size(); ++p)
	{
		const std::string stem = "codemark-sheet-" + std::to_string(p + 1);
		EXPECT_TRUE(fs::exists(dir.path / (stem + ".svg")));
		const cv::Mat img = cv::imread((dir.path / (stem + ".png")).string(), cv::IMREAD_COLOR);
		ASSERT_FALSE(img.empty());
		const double ppmm = o.dpi / kMmPerInch;
		EXPECT_NEAR(img.cols / ppmm, kA4Width_mm, 1 / ppmm);
		EXPECT_NEAR(img.rows / ppmm, kA4Height_mm, 1 / ppmm);
		for (const Placement& a : placed[p])
			EXPECT_EQ(decodeAt(img, ppmm, a.frame_x_mm, a.frame_y_mm, 0.5), a.id);
	}
}

// The app: --help explains every option; a bad ID is one error line and
// exit status 1; a good run exits 0.
TEST(PrintApp, HelpAndErrorsThroughTheCommandLine)
{
	TempDir dir("app");
	fs::create_directories(dir.path);
	const std::string app = CODEMARK_PRINT_APP;
	const fs::path out = dir.path / "stdout.txt", err = dir.path / "stderr.txt";
	auto runApp = [&](const std::string& args)
	{
		const std::string cmd =
			"'" + app + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
		const int st = std::system(cmd.c_str());
		return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
	};
	EXPECT_EQ(runApp("--help"), 0);
	const std::string help = readFile(out);
	for (const char* opt :
		 {"--id", "--out", "--format", "--scale", "--sheet", "--dpi", "--landmark"})
		EXPECT_NE(help.find(opt), std::string::npos) << opt;

	const std::string o = "--out '" + (dir.path / "o").string() + "'";
	EXPECT_EQ(runApp("--id 300 " + o), 1);
	std::string e = readFile(err);
	EXPECT_NE(e.find("ID 300 is outside 0..255"), std::string::npos) << e;
	EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 1) << e;
	EXPECT_EQ(runApp("--id 3 --id 3 " + o), 1);
	EXPECT_NE(readFile(err).find("more than once"), std::string::npos);
	EXPECT_EQ(runApp("--id 3 --format gif " + o), 1);
	EXPECT_NE(readFile(err).find("'gif'"), std::string::npos);
	EXPECT_EQ(runApp("--id 3 --scale 0 " + o), 1);
	EXPECT_EQ(runApp("--id 3"), 1) << "--out is required";
	EXPECT_FALSE(fs::exists(dir.path / "o"));
	EXPECT_EQ(runApp("--id 3 --format svg " + o), 0) << readFile(err);
	EXPECT_TRUE(fs::exists(dir.path / "o" / "codemark-3.svg"));
}
