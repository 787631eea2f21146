// Stage 8: frame verification and the code.
#include "stages.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

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

namespace
{
double normalCdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }
}  // namespace

double frameNeighbourShare(double width_px, double blur_px, double half_band)
{
	// Under two blur widths the dip's depth depends on the actual blur more
	// than on the ink: no correction.
	if (!(blur_px > 0) || !(width_px >= 2 * blur_px)) return 0;
	double share = 0;
	for (int i = -2; i <= 2; ++i)
		share += normalCdf(-(0.5 + half_band * i / 2.0) * width_px / blur_px);
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

/** A patch that readCode() averages: centre and half-sizes in normalised
 * face coordinates. */
struct FacePatch
{
	Eigen::Vector2d centre;
	double rx = 0, ry = 0;
};

/** The patch of code cell \a i (row by row): its centre, a \a
 * patch_fraction of the cell wide. */
FacePatch cellPatch(const LandmarkGeometry& geo, int i, double patch_fraction)
{
	const double h = geo.innerHalf(), r = 0.5 * patch_fraction * geo.cell_size_m / h;
	return {geo.cellCentreFace(i / 3, i % 3) / h, r, r};
}

/** Patch \a k (0..2, along the side's middle) of the green ring on side
 * \a side (top, right, bottom, left): midway between the code board and
 * the frame, half the ring wide across the side. */
FacePatch ringPatch(const LandmarkGeometry& geo, int side, int k)
{
	const double board = 1.5 * geo.cell_size_m / geo.innerHalf();
	const double rg = 0.5 * (board + 1), band = 0.25 * (1 - board);
	const double t = -0.5 + 0.5 * k;
	const double nx = kSideNormals[side][0], ny = kSideNormals[side][1];
	// Along-side direction is (ny, -nx).
	return {
		Eigen::Vector2d(rg * (nx + ny * t), rg * (ny - nx * t)), nx != 0 ? band : 0.08,
		ny != 0 ? band : 0.08};
}

std::optional<double> patchMean(const cv::Mat& bgr, const FaceMap& map, const FacePatch& f)
{
	return patchMean(bgr, map, f.centre.x(), f.centre.y(), f.rx, f.ry);
}

/** The references of the code read, side by side (top, right, bottom,
 * left): the black frame's mean G midway between its inner and outer edge,
 * and the green ring's between the code board and the frame, three patches
 * each along the side's middle. */
struct SideLevels
{
	std::array<double, 4> black{}, green{};
};

/** SideLevels under \a map; nullopt when a patch leaves the image. With
 * \a middle_only, one patch a side (the middle one) instead of three. */
std::optional<SideLevels> sideLevels(
	const cv::Mat& bgr, const FaceMap& map, const LandmarkGeometry& geo, bool middle_only = false)
{
	const double outer = geo.outerHalf() / geo.innerHalf();
	const double rb = 0.5 * (1 + outer);
	const double band_b = 0.25 * (outer - 1);
	SideLevels out;
	for (int side = 0; side < 4; ++side)
	{
		double sb = 0, sg = 0;
		const int first = middle_only ? 1 : 0, last = middle_only ? 1 : 2;
		for (int k = first; k <= last; ++k)
		{
			const double t = -0.5 + 0.5 * k;  // along the side, within its middle
			const double nx = kSideNormals[side][0], ny = kSideNormals[side][1];
			// Along-side direction is (ny, -nx).
			const double ax = ny * t, ay = -nx * t;
			const double rx_b = nx != 0 ? band_b : 0.08, ry_b = ny != 0 ? band_b : 0.08;
			const auto b = patchMean(bgr, map, nx * rb + ax, ny * rb + ay, rx_b, ry_b);
			const auto g = patchMean(bgr, map, ringPatch(geo, side, k));
			if (!b || !g) return std::nullopt;
			sb += *b;
			sg += *g;
		}
		out.black[side] = sb / (last - first + 1);
		out.green[side] = sg / (last - first + 1);
	}
	return out;
}

/** The mean of the two smallest of \a x: the frame's level from its two
 * darkest sides (at an oblique view the foreshortened sides are thin and
 * blur towards their neighbours). */
double meanOfTwoSmallest(std::array<double, 4> x)
{
	std::sort(x.begin(), x.end());
	return 0.5 * (x[0] + x[1]);
}

/** Mean over 5 samples evenly spread over [c - r, c + r] of the Gaussian
 * (std \a s) blurred indicator of [a, b]. */
double blurredInterval(double a, double b, double c, double r, double s)
{
	double sum = 0;
	for (int k = -2; k <= 2; ++k)
	{
		const double x = c + r * k / 2.0;
		sum += normalCdf((b - x) / s) - normalCdf((a - x) / s);
	}
	return sum / 5;
}
}  // namespace

BoardShares blurredCellShares(
	const FaceMap& map, const LandmarkGeometry& geo, double patch_fraction, double sigma_px)
{
	const double h = geo.innerHalf(), cell = geo.cell_size_m / h, board = 1.5 * cell;
	BoardShares A;
	// Row i: patch f (readCode()'s), 5 x 5 samples. The
	// blur in face coordinates is sigma^2 (J^T J)^-1, J the map's Jacobian
	// at the patch; its marginal standard deviations are used. The patch
	// is a product grid: its mean of a blurred rectangle is the product of
	// the means along each axis.
	const auto row = [&](int i, const FacePatch& f)
	{
		const Eigen::Vector2d& c = f.centre;
		const double e = 0.25 * cell;
		Eigen::Matrix2d J;
		J.col(0) = (map(c.x() + e, c.y()) - map(c.x() - e, c.y())) / (2 * e);
		J.col(1) = (map(c.x(), c.y() + e) - map(c.x(), c.y() - e)) / (2 * e);
		const Eigen::Matrix2d S = sigma_px * sigma_px * (J.transpose() * J).inverse();
		const double sx = std::sqrt(std::max(S(0, 0), 1e-12)),
					 sy = std::sqrt(std::max(S(1, 1), 1e-12));
		const auto rect = [&](double x0, double x1, double y0, double y1) {
			return blurredInterval(x0, x1, c.x(), f.rx, sx) *
				   blurredInterval(y0, y1, c.y(), f.ry, sy);
		};
		for (int j = 0; j < 9; ++j)
		{
			const Eigen::Vector2d cj = geo.cellCentreFace(j / 3, j % 3) / h;
			A(i, j) =
				rect(cj.x() - cell / 2, cj.x() + cell / 2, cj.y() - cell / 2, cj.y() + cell / 2);
		}
		A(i, 9) = rect(-1, 1, -1, 1) - rect(-board, board, -board, board);
	};
	for (int i = 0; i < 9; ++i) row(i, cellPatch(geo, i, patch_fraction));
	// The ring's patches: three along each side's middle, averaged.
	for (int side = 0; side < 4; ++side)
	{
		Eigen::Matrix<double, 1, 10> sum = Eigen::Matrix<double, 1, 10>::Zero();
		for (int k = 0; k < 3; ++k)
		{
			row(9 + side, ringPatch(geo, side, k));
			sum += A.row(9 + side);
		}
		A.row(9 + side) = sum / 3;
	}
	return A;
}

std::optional<BlurredCells> readCellsThroughBlur(
	const std::array<double, 9>& cell_g, const std::array<double, 4>& ring_g, double frame_g,
	double frame_ink, const FaceMap& map, const LandmarkGeometry& geo, double patch_fraction,
	double min_margin, double sigma_px)
{
	using Vec = Eigen::Matrix<double, 13, 1>;
	Vec m;
	for (int i = 0; i < 9; ++i) m[i] = cell_g[i];
	for (int i = 0; i < 4; ++i) m[9 + i] = ring_g[i];
	const BoardShares A = blurredCellShares(map, geo, patch_fraction, sigma_px);
	// Each ID's green share at every patch, the black and green levels
	// fitted by least squares (m = k0 + k1 f, k1 > 0); the least residual
	// wins.
	std::array<Vec, 256> fs;
	const double mm = m.mean();
	int best = -1;
	double best_sse = std::numeric_limits<double>::infinity(), k0 = 0, k1 = 0;
	for (int code = 0; code < 256; ++code)
	{
		const CodeCells cells = encodeId(code);
		Vec f = A.col(9);
		for (int j = 0; j < 9; ++j)
			if (!cells[j / 3][j % 3]) f += A.col(j);
		fs[code] = f;
		const double fm = f.mean();
		const double sff = (f.array() - fm).square().sum();
		if (!(sff > 1e-12)) continue;
		const double b1 = ((f.array() - fm) * (m.array() - mm)).sum() / sff;
		if (!(b1 > 0)) continue;
		const double b0 = mm - b1 * fm;
		const double sse = (m.array() - b0 - b1 * f.array()).square().sum();
		if (sse < best_sse)
		{
			best = code;
			best_sse = sse;
			k0 = b0;
			k1 = b1;
		}
	}
	if (best < 0) return std::nullopt;
	// The frame is the cells' ink, and the blur can only lighten it (its
	// neighbours, the ring and the sheet, are lighter): a black level
	// lighter than the frame reads takes a cell for black that is not.
	if (k0 > frame_g + min_margin * k1) return std::nullopt;
	// Nor is it darker than the frame's ink (its G without the blur's
	// share of fill and sheet) by more: with the black fitted to the cells
	// rather than set by the frame as the threshold read's, a dark print
	// on green inside a grey surround would otherwise read as a code.
	if (k0 < frame_ink - min_margin * k1) return std::nullopt;
	// Each patch as the code and the blur predict it, within the threshold
	// read's tolerance: a mean further from its prediction than that is not
	// explained by the blur (a stain, glare, another print). The ring's
	// patches pin the green level, the centre cell the black.
	const Vec e = m - (k0 + k1 * fs[best].array()).matrix();
	if (e.cwiseAbs().maxCoeff() > (0.5 - min_margin) * k1) return std::nullopt;
	// Distance of the cell means to the boundary between the code read and
	// each other code, along the line joining their cell means, against the
	// distance between them: the thresholded read's margin rule.
	BlurredCells out;
	out.margin = std::numeric_limits<double>::infinity();
	for (int code = 0; code < 256; ++code)
	{
		if (code == best) continue;
		const Vec d = k1 * (fs[code] - fs[best]);
		const double dn = d.norm();
		if (!(dn > 1e-9)) return std::nullopt;
		// ||e - d||^2 - ||e||^2 = dn^2 - 2 e.d; half of it over dn.
		const double dist = (dn * dn - 2 * e.dot(d)) / (2 * dn);
		if (dist < min_margin * dn) return std::nullopt;
		out.margin = std::min(out.margin, dist);
	}
	out.cells = encodeId(best);
	return out;
}

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
	const auto levels = sideLevels(bgr, map, geo);
	if (!levels) return std::nullopt;
	const auto& [black, green] = *levels;
	// The frame's ink, without the fill and the sheet that blur spreads over
	// it (frameNeighbourShare()): the level the ratio checks compare.
	std::array<double, 4> ink{};
	for (int side = 0; side < 4; ++side)
		ink[side] = frameSurround(bgr, map, geo, side, frame_blur_px).ink(black[side], green[side]);
	CodeReading r;
	r.green_g = 0.25 * (green[0] + green[1] + green[2] + green[3]);
	r.black_g = meanOfTwoSmallest(black);
	const double contrast = r.green_g - r.black_g;
	if (contrast < p.min_contrast) return std::nullopt;
	const double frame_ink = meanOfTwoSmallest(ink);
	if (frame_ink > p.max_black_ratio * r.green_g) return std::nullopt;
	for (int side = 0; side < 4; ++side)
		if (ink[side] > p.max_side_black_ratio * green[side] ||
			green[side] < r.black_g + 0.5 * contrast)
			return std::nullopt;
	const double thr = 0.5 * (r.green_g + r.black_g);
	r.margin = contrast;
	for (int row = 0; row < 3; ++row)
		for (int col = 0; col < 3; ++col)
		{
			const auto g = patchMean(bgr, map, cellPatch(geo, 3 * row + col, p.patch_fraction));
			if (!g) return std::nullopt;
			r.cell_g[3 * row + col] = *g;
			r.cells[row][col] = *g < thr;
			r.margin = std::min(r.margin, std::abs(*g - thr));
		}
	// A cell near the threshold: a thin or distant board's cells blur into
	// their neighbours, which a threshold between the frame's and the ring's
	// levels does not know; read them again with the blur.
	if (r.margin < p.min_margin * contrast)
	{
		const auto blurred = readCellsThroughBlur(
			r.cell_g, green, r.black_g, frame_ink, map, geo, p.patch_fraction, p.min_margin,
			frame_blur_px);
		if (!blurred) return std::nullopt;
		r.cells = blurred->cells;
		r.margin = blurred->margin;
	}
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

bool centreMayBeBlack(
	const cv::Mat& bgr, const Quad& corners_ideal, const CameraModel& cam,
	const LandmarkGeometry& geo, const CodeParams& p)
{
	const FaceMap map{faceToImage(corners_ideal), cam, cam.hasDistortion()};
	const auto levels = sideLevels(bgr, map, geo, true);
	const auto centre = patchMean(bgr, map, cellPatch(geo, 4, p.patch_fraction));
	// A patch outside the image: readCode() decides on the refined corners.
	if (!levels || !centre) return true;
	const auto& [black, green] = *levels;
	const double green_g = 0.25 * (green[0] + green[1] + green[2] + green[3]);
	const double contrast = green_g - meanOfTwoSmallest(black);
	return contrast > 0 && green_g - *centre >= p.min_margin * contrast;
}

}  // namespace codemark::detect
