// The image's noise at a landmark (DetectionQuality::image_noise_grey): in
// its black centre cell where that is large enough, else in flat blocks
// around it.
//
// Written by hand: OpenCV 4.6 has no noise estimator (cv::xphoto and
// cv::quality have none), and MRPT none for images.
#include "stages.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace codemark::detect
{
namespace
{
/** |G(x + 1, y) - G(x, y)| over the centre cell of \a q, shrunk by
 * \a margin_px on each side; nullopt when that leaves a half-width under
 * \a min_half px. \a foreshortened: the window's width and height from
 * the quadrangle's own (a cell seen obliquely is narrower than tall), else
 * a square from its mean side. */
std::optional<std::vector<double>> centreCellDifferences(
	const cv::Mat& bgr, const Quad& q, double cell_rel, double margin_px, int min_half,
	bool foreshortened)
{
	// The diagonals' intersection.
	const Eigen::Vector3d d1 =
		Eigen::Vector3d(q[0].x(), q[0].y(), 1).cross(Eigen::Vector3d(q[2].x(), q[2].y(), 1));
	const Eigen::Vector3d d2 =
		Eigen::Vector3d(q[1].x(), q[1].y(), 1).cross(Eigen::Vector3d(q[3].x(), q[3].y(), 1));
	const Eigen::Vector3d c = d1.cross(d2);
	if (std::abs(c.z()) < 1e-12) return std::nullopt;
	const double cx = c.x() / c.z(), cy = c.y() / c.z();
	const double side = 0.25 * ((q[1] - q[0]).norm() + (q[2] - q[1]).norm() + (q[3] - q[2]).norm() +
								(q[0] - q[3]).norm());
	const double width = foreshortened
							 ? 0.5 * (std::abs(q[1].x() - q[0].x()) + std::abs(q[2].x() - q[3].x()))
							 : side;
	const double height =
		foreshortened ? 0.5 * (std::abs(q[3].y() - q[0].y()) + std::abs(q[2].y() - q[1].y()))
					  : side;
	const int hx = static_cast<int>(std::floor(0.5 * cell_rel * width - margin_px));
	const int hy = static_cast<int>(std::floor(0.5 * cell_rel * height - margin_px));
	if (hx < min_half || hy < min_half) return std::nullopt;
	const int x0 = static_cast<int>(std::lround(cx)) - hx,
			  y0 = static_cast<int>(std::lround(cy)) - hy;
	if (x0 < 0 || y0 < 0 || x0 + 2 * hx + 1 >= bgr.cols || y0 + 2 * hy >= bgr.rows)
		return std::nullopt;
	std::vector<double> diffs;
	diffs.reserve(size_t(2 * hx + 1) * (2 * hy + 1));
	for (int y = y0; y <= y0 + 2 * hy; ++y)
	{
		const uint8_t* row = bgr.ptr<uint8_t>(y);
		for (int x = x0; x <= x0 + 2 * hx; ++x)
			diffs.push_back(std::abs(double(row[3 * (x + 1) + 1]) - row[3 * x + 1]));
	}
	return diffs;
}

// The difference of two samples has sqrt(2) sigma; its median absolute value
// is 0.6745 of that.
constexpr double kMadToSigma = 1 / (0.6745 * 1.4142135623730951);
}  // namespace

std::optional<double> centreCellNoise(const cv::Mat& bgr, const Quad& q, double cell_rel)
{
	// Half the cell, less the reach of a blur and of JPEG ringing.
	auto diffs = centreCellDifferences(bgr, q, cell_rel, 2.5, 1, false);
	if (!diffs) return std::nullopt;
	return medianOf(*diffs) * kMadToSigma;
}

std::optional<double> centreCellNoiseRms(const cv::Mat& bgr, const Quad& q, double cell_rel)
{
	// 3.5 px from the cell's sides: at 2.5 px a 0.8 px blur of the black to
	// green step (230 grey levels) still slopes by about a grey level a
	// pixel, which the RMS would count as noise. The window as wide and as
	// tall as the cell looks (narrower seen obliquely; a square window read
	// 2.64 for noise 2 over views to 70 deg). At least 5 x 5 pixels: the
	// estimate is then within about 15% (a cell over about 11 px, a
	// landmark of the spec's size nearer than about 1.5 m with the paper's
	// camera; beyond, C_P is the detector's bias more than its noise).
	auto diffs = centreCellDifferences(bgr, q, cell_rel, 3.5, 2, true);
	if (!diffs) return std::nullopt;
	// The median of integer differences is coarse (it reads 1.05 for any
	// sigma from about 0.8 to 1.3): the RMS of the differences within 4
	// robust sigmas (one more grey level for the rounding) instead, which a
	// stray edge pixel does not move and a Gaussian loses 0.1% of.
	// (The RMS below does not care about the order medianOf() leaves.)
	const double cut = 4 * std::sqrt(2.0) * medianOf(*diffs) * kMadToSigma + 1;
	double ss = 0;
	int n = 0;
	for (const double d : *diffs)
		if (d <= cut)
		{
			ss += d * d;
			++n;
		}
	return n > 0 ? std::sqrt(ss / n / 2) : 0.0;
}

namespace
{
// Flat blocks: 8 x 8 px, each 8 rows of 7 horizontal differences.
constexpr int kBlockPx = 8;
// At most this many blocks per side of the window (evenly spread): the
// estimate is then within a few percent and costs about 16k pixels.
constexpr int kMaxBlocksPerSide = 16;
// Blocks kept as flat: above this many the estimate is within about 5%.
constexpr int kMinFlatBlocks = 8;
// A flat block's variance estimate scatters by 23% (relative sd; 99.9% of
// them under 1.9x the mean, simulated at noise 1-4 with the rounding):
// blocks beyond 2.5x the current estimate hold an edge or texture.
constexpr double kFlatCut = 2.5;
}  // namespace

std::optional<double> surroundNoiseRms(const cv::Mat& bgr, const Quad& q)
{
	double xmin = q[0].x(), xmax = xmin, ymin = q[0].y(), ymax = ymin;
	for (const auto& c : q)
	{
		xmin = std::min(xmin, c.x());
		xmax = std::max(xmax, c.x());
		ymin = std::min(ymin, c.y());
		ymax = std::max(ymax, c.y());
	}
	if (!std::isfinite(xmin + xmax + ymin + ymax)) return std::nullopt;
	// A window three times the landmark's size, at least 64 px across.
	const double half = std::max(1.5 * std::max(xmax - xmin, ymax - ymin), 32.0);
	const double cx = 0.5 * (xmin + xmax), cy = 0.5 * (ymin + ymax);
	const int x0 = std::max(0, static_cast<int>(std::floor(cx - half)));
	const int y0 = std::max(0, static_cast<int>(std::floor(cy - half)));
	const int x1 = std::min(bgr.cols, static_cast<int>(std::ceil(cx + half)));
	const int y1 = std::min(bgr.rows, static_cast<int>(std::ceil(cy + half)));
	const int nbx = (x1 - x0) / kBlockPx, nby = (y1 - y0) / kBlockPx;
	if (nbx <= 0 || nby <= 0) return std::nullopt;
	const int sx = (nbx + kMaxBlocksPerSide - 1) / kMaxBlocksPerSide;
	const int sy = (nby + kMaxBlocksPerSide - 1) / kMaxBlocksPerSide;

	// Per block, the variance of the differences about their mean (a
	// linear shading along the row cancels) over twice the noise's: a
	// row's differences telescope, so their sum has 2 sigma^2 a row and
	// the sum of squares about the mean expects 2 sigma^2 (n - rows / n).
	constexpr int kRows = kBlockPx, kDiffs = kBlockPx * (kBlockPx - 1);
	constexpr double kNorm = 2.0 * (kDiffs - double(kRows) / kDiffs);
	std::vector<double> v;
	v.reserve(size_t((nbx + sx - 1) / sx) * ((nby + sy - 1) / sy));
	for (int by = 0; by < nby; by += sy)
		for (int bx = 0; bx < nbx; bx += sx)
		{
			int sum = 0, sum2 = 0;
			bool clipped = false;
			for (int y = y0 + by * kBlockPx; y < y0 + (by + 1) * kBlockPx && !clipped; ++y)
			{
				const uint8_t* g = bgr.ptr<uint8_t>(y) + 3 * (x0 + bx * kBlockPx) + 1;
				for (int x = 0; x < kBlockPx; ++x)
					// A clipped pixel has lost its noise.
					clipped = clipped || g[3 * x] == 0 || g[3 * x] == 255;
				for (int x = 0; x + 1 < kBlockPx; ++x)
				{
					const int d = int(g[3 * (x + 1)]) - int(g[3 * x]);
					sum += d;
					sum2 += d * d;
				}
			}
			if (!clipped) v.push_back((sum2 - double(sum) * sum / kDiffs) / kNorm);
		}
	if (static_cast<int>(v.size()) < kMinFlatBlocks) return std::nullopt;

	// The flat blocks' mean: from the lower quartile (flat blocks there
	// unless three quarters of the window has texture; 0.84 of their mean),
	// the mean of the blocks under kFlatCut times the estimate, to its
	// fixed point. Texture that passes the cut can only raise it.
	std::nth_element(v.begin(), v.begin() + v.size() / 4, v.end());
	double s2 = v[v.size() / 4];
	for (int it = 0; it < 8; ++it)
	{
		double sum = 0;
		int n = 0;
		for (const double b : v)
			if (b <= kFlatCut * s2)
			{
				sum += b;
				++n;
			}
		if (n < kMinFlatBlocks) return std::nullopt;
		const double next = sum / n;
		const bool settled = std::abs(next - s2) <= 1e-3 * s2;
		s2 = next;
		if (settled) break;
	}
	return std::sqrt(s2);
}

double landmarkNoiseRms(const cv::Mat& bgr, const Quad& q, double cell_rel)
{
	if (const auto c = centreCellNoiseRms(bgr, q, cell_rel)) return *c;
	return surroundNoiseRms(bgr, q).value_or(0);
}

}  // namespace codemark::detect
