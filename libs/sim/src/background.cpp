#include "background.h"

#include <opencv2/imgproc.hpp>

#include <array>
#include <cmath>

namespace codemark::sim::detail
{
uint64_t streamSeed(uint64_t seed, uint64_t stream)
{
	uint64_t z = seed + 0x9E3779B97F4A7C15ull * (stream + 1);
	z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
	z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
	z ^= z >> 31;
	return z ? z : 1;
}

namespace
{
/** A smooth random field of about unit variance and correlation length
 * \a cell_px over a width x height image, sampled on a grid of \a grid
 * nodes spread over the image: white noise on a grid of cell_px / 4
 * spacing, low-pass filtered there (Gaussian, 2 grid steps) and resampled
 * bicubically to \a grid. Filtering before upsampling keeps the bicubic
 * grid pattern invisible and costs little. */
cv::Mat smoothField(
	cv::RNG& rng, int width, int height, double cell_px, int channels, const cv::Size& grid)
{
	const double step = std::max(1.0, cell_px / 4);
	const int gw = std::max(4, static_cast<int>(std::ceil(width / step)) + 1);
	const int gh = std::max(4, static_cast<int>(std::ceil(height / step)) + 1);
	cv::Mat g(gh, gw, CV_32FC(channels));
	rng.fill(g, cv::RNG::NORMAL, 0.0, 1.0);
	constexpr double sigma = 2.0;
	cv::GaussianBlur(g, g, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT);
	g *= 2 * std::sqrt(CV_PI) * sigma;	// the blur divides the variance by 4 pi sigma^2
	if (g.size() == grid) return g;
	cv::Mat out;
	cv::resize(g, out, grid, 0, 0, cv::INTER_CUBIC);
	return out;
}

/** Draws shapes in a local frame (centre, rotation, unit = 1 px) with
 * anti-aliased sub-pixel fills. */
struct LocalFrame
{
	cv::Point2d centre;
	double angle_rad;

	cv::Point toImage(double x, double y) const
	{
		const double c = std::cos(angle_rad), s = std::sin(angle_rad);
		const double u = centre.x + c * x - s * y, v = centre.y + s * x + c * y;
		// 4 fractional bits (shift = 4 in the cv:: fill calls).
		return {static_cast<int>(std::lround(u * 16)), static_cast<int>(std::lround(v * 16))};
	}

	/** Fills the local axis-aligned rectangle [x0, x1] x [y0, y1]. */
	void rect(
		cv::Mat& img, double x0, double y0, double x1, double y1, const cv::Scalar& colour) const
	{
		const std::array<cv::Point, 4> p{
			toImage(x0, y0), toImage(x1, y0), toImage(x1, y1), toImage(x0, y1)};
		cv::fillConvexPoly(img, p.data(), 4, colour, cv::LINE_AA, 4);
	}
};

cv::Scalar jitter(cv::RNG& rng, const cv::Scalar& c, double amount)
{
	cv::Scalar out;
	for (int i = 0; i < 3; ++i)
		out[i] = std::clamp(c[i] + rng.uniform(-amount, amount), 0.0, 255.0);
	return out;
}

/** One distractor: shapes a landmark detector must reject. */
void drawDistractor(cv::Mat& img, cv::RNG& rng, const RenderOptions& o)
{
	const double w = img.cols, h = img.rows;
	const double size = rng.uniform(0.04, 0.3) * std::min(w, h);
	const LocalFrame f{{rng.uniform(0.0, w), rng.uniform(0.0, h)}, rng.uniform(0.0, CV_PI)};
	const double a = 0.5 * size;
	const double aspect = rng.uniform(0.6, 1.6);
	const double b = a * aspect;
	const cv::Scalar green = jitter(rng, o.green_bgr, 30);
	const cv::Scalar black = jitter(rng, o.black_bgr, 10);
	switch (rng.uniform(0, 5))
	{
		case 0:	 // a green blob (no frame)
		{
			cv::ellipse(
				img, cv::Point(f.toImage(0, 0)),
				cv::Size(static_cast<int>(a * 16), static_cast<int>(b * 16)),
				f.angle_rad * 180 / CV_PI, 0, 360, green, cv::FILLED, cv::LINE_AA, 4);
			break;
		}
		case 1:	 // a green rectangle without a frame
			f.rect(img, -a, -b, a, b, green);
			break;
		case 2:	 // a black frame filled with another colour
		{
			static const std::array<cv::Scalar, 4> fills{
				cv::Scalar(30, 30, 200), cv::Scalar(200, 40, 30), o.white_bgr,
				cv::Scalar(128, 128, 128)};
			const double t = rng.uniform(0.1, 0.25);
			f.rect(img, -a, -a, a, a, black);
			f.rect(
				img, -a * (1 - t), -a * (1 - t), a * (1 - t), a * (1 - t),
				jitter(rng, fills[rng.uniform(0, 4)], 15));
			break;
		}
		case 3:	 // a poster: light sheet with black text lines and green print
		{
			f.rect(img, -a, -b, a, b, jitter(rng, o.white_bgr, 20));
			const int lines = rng.uniform(3, 9);
			for (int i = 0; i < lines; ++i)
			{
				const double y = -b + (i + 1) * 2 * b / (lines + 1);
				const double x1 = -0.85 * a + rng.uniform(0.3, 1.7) * a;
				f.rect(img, -0.85 * a, y - 0.03 * b, x1, y + 0.03 * b, black);
			}
			const double gx = rng.uniform(-0.6, 0.2) * a, gy = rng.uniform(-0.7, 0.2) * b;
			f.rect(img, gx, gy, gx + 0.4 * a, gy + 0.45 * b, green);
			f.rect(img, gx + 0.1 * a, gy + 0.1 * b, gx + 0.25 * a, gy + 0.25 * b, black);
			break;
		}
		default:  // a marker-like black square with a white/black grid
		{
			const int n = rng.uniform(4, 7);
			const double cell = 2 * a / (n + 2);
			f.rect(img, -a, -a, a, a, black);
			for (int r = 0; r < n; ++r)
				for (int c = 0; c < n; ++c)
					if (rng.uniform(0, 2))
						f.rect(
							img, -a + (c + 1) * cell, -a + (r + 1) * cell, -a + (c + 2) * cell,
							-a + (r + 2) * cell, o.white_bgr);
			break;
		}
	}
}
}  // namespace

cv::Mat makeBackground(const RenderOptions& o, int width, int height, uint64_t seed)
{
	const double g = o.background_grey;
	if (o.background == Background::Flat)
		return cv::Mat(height, width, CV_32FC3, cv::Scalar(g, g, g));

	// A wall: smooth luminance at two scales plus a faint colour tint,
	// summed on the finest field's grid (3 px) and upsampled once.
	cv::RNG rng(streamSeed(seed, 1));
	constexpr double kFineCell = 12, kCoarseCell = 96, kTintCell = 160;
	const cv::Size grid(
		std::max(4, static_cast<int>(std::ceil(width / (kFineCell / 4))) + 1),
		std::max(4, static_cast<int>(std::ceil(height / (kFineCell / 4))) + 1));
	const cv::Mat coarse = smoothField(rng, width, height, kCoarseCell, 1, grid);
	const cv::Mat fine = smoothField(rng, width, height, kFineCell, 1, grid);
	const cv::Mat tint = smoothField(rng, width, height, kTintCell, 3, grid);
	const cv::Mat lum = g + 25 * coarse + 7 * fine;
	cv::Mat small;
	cv::merge(std::vector<cv::Mat>(3, lum), small);
	small += 6 * tint;
	cv::Mat bg;
	cv::resize(small, bg, cv::Size(width, height), 0, 0, cv::INTER_CUBIC);
	if (o.background == Background::Textured || o.distractors == 0) return bg;

	// Distractors are drawn in 8 bits for OpenCV's anti-aliasing (float
	// images get none), always before (under) the landmarks.
	cv::Mat bg8;
	bg.convertTo(bg8, CV_8UC3);
	cv::RNG drng(streamSeed(seed, 2));
	for (int i = 0; i < o.distractors; ++i) drawDistractor(bg8, drng, o);
	bg8.convertTo(bg, CV_32FC3);
	return bg;
}

}  // namespace codemark::sim::detail
