// Stage 8: frame verification and the code.
#include "stages.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace codemark::detect
{
Eigen::Matrix3d faceToImage(const Quad& c)
{
	// Four-point DLT with h33 = 1 (the reference square is never degenerate
	// here: linkQuadrangle checked convexity).

	Eigen::Matrix<double, 8, 8> A;
	Eigen::Matrix<double, 8, 1> b;
	for (int k = 0; k < 4; ++k)
	{
		const double x = kFaceCorners[k].x(), y = kFaceCorners[k].y(), u = c[k].x(), v = c[k].y();
		A.row(2 * k) << x, y, 1, 0, 0, 0, -u * x, -u * y;
		A.row(2 * k + 1) << 0, 0, 0, x, y, 1, -v * x, -v * y;
		b(2 * k) = u;
		b(2 * k + 1) = v;
	}
	const Eigen::Matrix<double, 8, 1> h = A.partialPivLu().solve(b);
	Eigen::Matrix3d H;
	H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0;
	return H;
}

std::optional<double> sampleG(const cv::Mat& bgr, double u, double v)
{
	if (!(u >= 0 && v >= 0 && u <= bgr.cols - 1 && v <= bgr.rows - 1)) return std::nullopt;
	const int x0 = std::min(static_cast<int>(u), bgr.cols - 2 < 0 ? 0 : bgr.cols - 2);
	const int y0 = std::min(static_cast<int>(v), bgr.rows - 2 < 0 ? 0 : bgr.rows - 2);
	const int x1 = std::min(x0 + 1, bgr.cols - 1), y1 = std::min(y0 + 1, bgr.rows - 1);
	const double fx = u - x0, fy = v - y0;
	const uint8_t* r0 = bgr.ptr<uint8_t>(y0);
	const uint8_t* r1 = bgr.ptr<uint8_t>(y1);
	const double top = (1 - fx) * r0[3 * x0 + 1] + fx * r0[3 * x1 + 1];
	const double bot = (1 - fx) * r1[3 * x0 + 1] + fx * r1[3 * x1 + 1];
	return (1 - fy) * top + fy * bot;
}

double frameNeighbourShare(double width_px, double blur_px, double half_band)
{
	// Under two blur widths the dip's depth depends on the actual blur more
	// than on the ink: no correction.
	if (!(blur_px > 0) || !(width_px >= 2 * blur_px)) return 0;
	const auto phi = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
	double share = 0;
	for (int i = -2; i <= 2; ++i) share += phi(-(0.5 + half_band * i / 2.0) * width_px / blur_px);
	return share / 5;
}

FrameSurround frameSurround(
	const cv::Mat& bgr, const FaceMap& map, const LandmarkGeometry& geo, int side, double blur_px)
{
	const double h = geo.innerHalf(), outer = geo.outerHalf() / h;
	const double nx = kSideNormals[side][0], ny = kSideNormals[side][1];
	FrameSurround out;
	out.width_px = (map(nx * outer, ny * outer) - map(nx, ny)).norm();
	// The sheet where the blur takes it from: two blur widths beyond the
	// frame, or the quiet margin's middle if that is farther (whatever lies
	// there is what the blur brings in).
	const double rs =
		outer +
		std::max(0.5 * geo.margin_m / h, 2 * blur_px * (outer - 1) / std::max(out.width_px, 1.0));
	double sum = 0;
	int reads = 0;
	for (const double t : {-0.5, 0.0, 0.5})
	{
		const Eigen::Vector2d px = map(rs * (nx + ny * t), rs * (ny - nx * t));
		if (const auto g = sampleG(bgr, px.x(), px.y()))
		{
			sum += *g;
			++reads;
		}
	}
	// No sheet in the image: the level as read.
	if (reads == 0) return out;
	out.sheet_g = sum / reads;
	out.share = frameNeighbourShare(out.width_px, blur_px, 0.25);
	return out;
}

namespace
{

/** Mean G over a square patch of half-size \a r centred on (x, y) in
 * normalised face coordinates, on a 5 x 5 grid; nullopt if outside. */
std::optional<double> patchMean(
	const cv::Mat& bgr, const FaceMap& map, double x, double y, double rx, double ry)
{
	double s = 0;
	for (int i = -2; i <= 2; ++i)
		for (int j = -2; j <= 2; ++j)
		{
			const Eigen::Vector2d px = map(x + rx * j / 2.0, y + ry * i / 2.0);
			const auto g = sampleG(bgr, px.x(), px.y());
			if (!g) return std::nullopt;
			s += *g;
		}
	return s / 25;
}
}  // namespace

std::optional<CodeReading> readCode(
	const cv::Mat& bgr, const RefinedQuad& q, const CameraModel& cam, const LandmarkGeometry& geo,
	const CodeParams& p, double frame_blur_px)
{
	const FaceMap map{faceToImage(q.corners_ideal), cam, cam.hasDistortion()};
	const double h = geo.innerHalf();
	// The whole outer frame must be in the image: a landmark cut by the
	// border is not reported.
	const double outer = geo.outerHalf() / h;
	const double lo_u = p.border_px - 0.5, hi_u = bgr.cols - 0.5 - p.border_px;
	const double lo_v = p.border_px - 0.5, hi_v = bgr.rows - 0.5 - p.border_px;
	for (int k = 0; k < 8; ++k)
	{
		// Corners and side midpoints of the outer edge (distortion bends it).
		const double xs[8] = {-1, 0, 1, 1, 1, 0, -1, -1}, ys[8] = {1, 1, 1, 0, -1, -1, -1, 0};
		const Eigen::Vector2d px = map(outer * xs[k], outer * ys[k]);
		if (!(px.x() >= lo_u && px.x() <= hi_u && px.y() >= lo_v && px.y() <= hi_v))
			return std::nullopt;
	}
	// References: the black frame, midway between its inner and outer edge,
	// and the green ring between the code board and the frame, side by
	// side (top, right, bottom, left).
	const double rb = 0.5 * (1 + outer);
	const double board = 1.5 * geo.cell_size_m / h;
	const double rg = 0.5 * (board + 1);
	const double band_b = 0.25 * (outer - 1), band_g = 0.25 * (1 - board);
	// The frame's ink, without the fill and the sheet that blur spreads over
	// it (frameNeighbourShare()): the level the ratio checks compare.
	std::array<double, 4> black{}, green{}, ink{};
	for (int side = 0; side < 4; ++side)
	{
		double sb = 0, sg = 0;
		const int n = 3;
		for (int k = 0; k < n; ++k)
		{
			const double t = -0.5 + 0.5 * k;  // along the side, within its middle
			const double nx = kSideNormals[side][0], ny = kSideNormals[side][1];
			// Along-side direction is (ny, -nx).
			const double ax = ny * t, ay = -nx * t;
			const double rx_b = nx != 0 ? band_b : 0.08, ry_b = ny != 0 ? band_b : 0.08;
			const double rx_g = nx != 0 ? band_g : 0.08, ry_g = ny != 0 ? band_g : 0.08;
			const auto b = patchMean(bgr, map, nx * rb + ax, ny * rb + ay, rx_b, ry_b);
			const auto g = patchMean(bgr, map, nx * rg + ax * rg, ny * rg + ay * rg, rx_g, ry_g);
			if (!b || !g) return std::nullopt;
			sb += *b;
			sg += *g;
		}
		black[side] = sb / n;
		green[side] = sg / n;
		ink[side] = frameSurround(bgr, map, geo, side, frame_blur_px).ink(black[side], green[side]);
	}
	CodeReading r;
	r.green_g = 0.25 * (green[0] + green[1] + green[2] + green[3]);
	// The two darkest frame sides: at an oblique view the foreshortened
	// sides are thin and blur towards their neighbours.
	std::array<double, 4> sorted = black;
	std::sort(sorted.begin(), sorted.end());
	r.black_g = 0.5 * (sorted[0] + sorted[1]);
	const double contrast = r.green_g - r.black_g;
	if (contrast < p.min_contrast) return std::nullopt;
	std::array<double, 4> ink_sorted = ink;
	std::sort(ink_sorted.begin(), ink_sorted.end());
	if (0.5 * (ink_sorted[0] + ink_sorted[1]) > p.max_black_ratio * r.green_g) return std::nullopt;
	for (int side = 0; side < 4; ++side)
		if (ink[side] > p.max_side_black_ratio * green[side] ||
			green[side] < r.black_g + 0.5 * contrast)
			return std::nullopt;
	const double thr = 0.5 * (r.green_g + r.black_g);
	const double cell = geo.cell_size_m / h;
	const double pr = 0.5 * p.patch_fraction * cell;
	r.margin = contrast;
	for (int row = 0; row < 3; ++row)
		for (int col = 0; col < 3; ++col)
		{
			const Eigen::Vector2d f = geo.cellCentreFace(row, col) / h;
			const auto g = patchMean(bgr, map, f.x(), f.y(), pr, pr);
			if (!g) return std::nullopt;
			r.cell_g[3 * row + col] = *g;
			r.cells[row][col] = *g < thr;
			r.margin = std::min(r.margin, std::abs(*g - thr));
		}
	if (r.margin < p.min_margin * contrast) return std::nullopt;
	// The frame and the black cells are the same ink: the frame's G must
	// lie near the black cells' (the centre one at least), whatever the
	// camera's transfer curve does to both.
	double cells_g = 0;
	int black_cells = 0;
	for (int k = 0; k < 9; ++k)
		if (r.cells[k / 3][k % 3])
		{
			cells_g += r.cell_g[k];
			++black_cells;
		}
	cells_g /= std::max(1, black_cells);
	if (r.black_g - cells_g > p.max_frame_cell_ratio * (r.green_g - cells_g)) return std::nullopt;
	const auto id = decodeCells(r.cells);
	if (!id) return std::nullopt;
	r.id = *id;
	return r;
}

}  // namespace codemark::detect
