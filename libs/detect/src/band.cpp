// Stage 7b: the reference square from the green band's midline.
//
// A camera's transfer curve (sRGB, gamma, a phone's filmic curve) applied
// after the optics' blur, and the sharpening and compression after it,
// move every edge's encoded profile towards its dark side by a few tenths
// of a pixel, and no locator that reads one edge can tell that shift from
// the edge's position without knowing the camera. The green band between
// the frame's inner edge and a black code cell is bounded by two edges of
// one ink and one fill, mirror images of each other: whatever the camera
// does to one it does to the other, so the band's midline stays where the
// homography puts it, and the inner edge lies half the band's width
// outside it. The band's width in the face is known (the code board's
// margin); printers' dot gain narrows it on both sides alike. Every side
// has such a band: its middle code cell, or, where that cell is green, the
// always-black centre cell behind it.
#include "stages.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

namespace codemark::detect
{
double medianOf(std::vector<double>& x)
{
	std::nth_element(x.begin(), x.begin() + x.size() / 2, x.end());
	return x[x.size() / 2];
}

double midmeanOf(std::vector<double>& x)
{
	// A quarter (rounded up) off either end: the median itself up to 6.
	const size_t n = x.size();
	size_t lo = (n + 3) / 4, hi = n - lo;
	if (hi <= lo) lo = (n - 1) / 2, hi = n - lo;
	std::nth_element(x.begin(), x.begin() + lo, x.end());
	std::nth_element(x.begin() + lo, x.begin() + hi - 1, x.end());
	double sum = 0;
	for (size_t k = lo; k < hi; ++k) sum += x[k];
	return sum / static_cast<double>(hi - lo);
}

MedianWithError medianWithError(std::vector<double> x)
{
	const size_t n = x.size();
	const double median = medianOf(x);
	for (double& v : x) v = std::abs(v - median);
	// A normal sample's sigma is 1.4826 MADs; its median's standard error
	// sqrt(pi / 2) sigma / sqrt(n).
	return {median, 1.4826 * medianOf(x) * std::sqrt(M_PI / 2 / n)};
}

namespace
{
/** The search around each predicted edge [+- px]: the bend (a few tenths
 * of a pixel) and the single-edge square's error. */
constexpr int kSearch = 2;
/** Samples beyond each edge of a profile [px]. */
constexpr int kReach = 5;
/** Along each cell, profiles stay this fraction of a cell from its ends
 * (the cell's corners blur its edge). */
constexpr double kCellGuard = 0.2;
/** The narrowest frame across a profile [px]: the inner edge's dark side
 * is the frame, whose far edge pulls the edge's response away from it
 * where the two overlap (a frame under about three pixels, at up to a
 * pixel of blur); the cell edge's dark side is wider (a cell, 30 of 20). */
constexpr double kMinFramePx = 3;
/** The bands' width must differ from the printed one by this many of its
 * standard errors (bandsShowBend()): by chance about once in 370
 * landmarks. */
constexpr double kMinZ = 3;
/** Fewest profiles for a side's offset. */
constexpr int kMinProfiles = 3;
/** The largest move of a side [px]: a camera bends an edge by a few
 * tenths of a pixel, by up to about 1.6 px where a fill clipped at twice
 * the sensor's top meets a 1.5 px blur; a misread band (a cell taken for
 * black) moves it by half a cell or more, 2.8 px on the smallest square
 * detected (30 px). */
constexpr double kMaxMovePx = 2.0;

/** The locator of both band edges: as the single-edge policy reads a
 * side (chooseLocator()), the response's centroid where the frame, the
 * narrower of the two dark bars beside the band, is at least
 * p.min_frame_px_centroid wide (the centroid is exact for any symmetric
 * blur and any phase of the edge in its pixel), the derivative's peak on a
 * thinner one (whose far edge would cut the response). One locator for
 * both edges, mirrored. */
EdgeMode bandLocator(double frame_px, const SubpixelParams& p)
{
	return frame_px >= p.min_frame_px_centroid ? EdgeMode::Centroid : EdgeMode::Peak;
}

/** The centroid's reach either side of each band edge's peak [px]: at
 * most p.reach_px, and short of the frame's far edge. The frame (the
 * narrower dark bar, 20 of 200) puts its far edge frame_px from the band's
 * inner edge; that edge's response spreads up to p.reach_px towards it,
 * and the discrete derivative one sample more, so a window reaching
 * further sums the far edge's response (of the opposite sign, with the
 * lobes of a camera's sharpening) into the near edge's and moves it by a
 * share of that. Both edges take the same reach, so that a symmetric blur
 * moves them alike and the band's midline cancels it. At least 2 samples
 * (where p.reach_px allows): the peak's neighbours carry most of a blurred
 * edge's response. */
int bandReach(double frame_px, const SubpixelParams& p)
{
	const int clear = static_cast<int>(std::floor(frame_px)) - p.reach_px - 1;
	return std::min(p.reach_px, std::max(2, clear));
}

/** Whether the bands read wider or narrower than printed beyond their
 * own scatter: \a excess holds each profile's measured minus predicted
 * band width [px]; its median must lie at least kMinZ of its standard
 * errors from 0 (medianWithError()). A camera's
 * response, or a clipped fill, moves both edges of a band outwards (each
 * edge's dark side is outside the band), printers' dot gain inwards; in
 * linear light, unclipped, neither edge moves, the single-edge locators
 * read the whole side exactly, and the band's fewer, two-edge profiles
 * would only add their scatter. */
bool bandsShowBend(std::vector<double> excess)
{
	if (static_cast<int>(excess.size()) < kMinProfiles) return false;
	const MedianWithError m = medianWithError(std::move(excess));
	return std::abs(m.median) >= kMinZ * m.se;
}

/** The factor of a median's variance over neighbouring profiles whose
 * errors are correlated: (1 + r) / (1 - r), r the lag-1 correlation of
 * \a v between profiles of one run (\a run) one pixel apart (\a pos),
 * taken in [0, 0.9]. A camera's denoising, its demosaicing and its
 * compression's blocks spread an error along an edge over several
 * profiles, which then average out less than independent ones would (the
 * standard error of a mean of AR(1) samples); 1 with fewer than 8 pairs. */
double correlationInflation(
	const std::vector<double>& v, const std::vector<int>& run, const std::vector<int>& pos)
{
	constexpr int kMinPairs = 8;
	constexpr double kMaxCorrelation = 0.9;
	double mean = 0;
	for (const double x : v) mean += x;
	mean /= std::max<size_t>(1, v.size());
	double cross = 0, square = 0;
	int pairs = 0;
	for (size_t k = 0; k < v.size(); ++k)
	{
		square += (v[k] - mean) * (v[k] - mean);
		if (k > 0 && run[k] == run[k - 1] && std::abs(pos[k] - pos[k - 1]) == 1)
		{
			cross += (v[k] - mean) * (v[k - 1] - mean);
			++pairs;
		}
	}
	if (pairs < kMinPairs || !(square > 0)) return 1;
	// Lag-1 pairs against all the samples' variance.
	const double r = std::clamp(cross / pairs / (square / v.size()), 0.0, kMaxCorrelation);
	return (1 + r) / (1 - r);
}

/** Across coordinate at along coordinate \a s of the segment \a p0 - \a p1
 * (raw px); nullopt outside it. */
std::optional<double> acrossOn(
	const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, int along, double s)
{
	const int across = 1 - along;
	const double a0 = p0(along), a1 = p1(along);
	if (s < std::min(a0, a1) || s > std::max(a0, a1) || a0 == a1) return std::nullopt;
	const double t = (s - a0) / (a1 - a0);
	return p0(across) + t * (p1(across) - p0(across));
}

/** One pass of centreOnBand() on \a q's square; false (and \a q as it
 * is) where no corners follow, or, when \a decide, where the bands show
 * no bend (bandsShowBend()). */
bool centreOnBandOnce(
	const cv::Mat& bgr, RefinedQuad& q, const CameraModel& cam, double min_rise, double frame_ratio,
	double fill_ratio, const SubpixelParams& p, bool decide)
{
	const bool distorted = cam.hasDistortion();
	const FaceMap map{faceToImage(q.corners_ideal), cam, distorted};
	const double cell = codeCellRatio(fill_ratio);
	const int W = bgr.cols, H = bgr.rows;
	RefinedQuad next = q;
	std::vector<double> residuals, excess;
	// Per excess: the profile's side, cell and position along the side, to
	// pair neighbouring profiles (correlationInflation()).
	std::vector<int> run_of, pos_of;
	std::vector<int> v, vr;
	// The band edges' locator settings: p with its reach (bandReach()) set
	// per profile.
	SubpixelParams pb = p;
	const auto g_at = [&](const Eigen::Vector2d& f)
	{
		const Eigen::Vector2d px = map(f);
		return sampleG(bgr, px.x(), px.y());
	};
	for (int side = 0; side < 4; ++side)
	{
		const Eigen::Vector2d &f0 = kFaceCorners[side], &f1 = kFaceCorners[(side + 1) % 4];
		const Eigen::Vector2d out = 0.5 * (f0 + f1);  // outward normal, face units
		const Eigen::Vector2d ab = q.corners_raw[(side + 1) % 4] - q.corners_raw[side];
		const int along = std::abs(ab.y()) >= std::abs(ab.x()) ? 1 : 0;
		residuals.clear();
		for (int c = 0; c < 3; ++c)
		{
			// The cell's span along the side, in [0, 1] of the side.
			const double u0 = (fill_ratio + (c + kCellGuard) * cell),
						 u1 = (fill_ratio + (c + 1 - kCellGuard) * cell);
			const Eigen::Vector2d fa = f0 + u0 * (f1 - f0), fb = f0 + u1 * (f1 - f0);
			const Eigen::Vector2d mid = 0.5 * (fa + fb);
			// Face units are half the side: a depth d (fraction of the side)
			// is 2 d inwards.
			const auto g_cell = g_at(mid - out * 2 * (fill_ratio + 0.5 * cell)),
					   g_band = g_at(mid - out * fill_ratio),
					   g_frame = g_at(mid + out * frame_ratio);
			if (!g_cell || !g_band || !g_frame) continue;
			double depth = fill_ratio;	// the black cell's edge
			if (*g_cell >= 0.5 * (*g_band + *g_frame))
			{
				if (c != 1) continue;
				depth = fill_ratio + cell;	// the centre cell's edge
			}
			// Beyond the dark cell: the next cell. Where it is green, the
			// dark cell's far edge is the band edge's neighbour.
			const auto g_next = g_at(mid - out * 2 * (depth + 1.5 * cell));
			const bool next_green = g_next && *g_next >= 0.5 * (*g_band + *g_frame);
			const Eigen::Vector2d i0 = map(fa), i1 = map(fb), k0 = map(fa - out * 2 * depth),
								  k1 = map(fb - out * 2 * depth);
			const int s0 = static_cast<int>(std::ceil(std::max(
						  std::min(i0(along), i1(along)), std::min(k0(along), k1(along))))),
					  s1 = static_cast<int>(std::floor(std::min(
						  std::max(i0(along), i1(along)), std::max(k0(along), k1(along)))));
			for (int s = s0; s <= s1; ++s)
			{
				const auto c_in = acrossOn(i0, i1, along, s), c_cell = acrossOn(k0, k1, along, s);
				if (!c_in || !c_cell) continue;
				const int inward = *c_cell > *c_in ? 1 : -1;
				const double width = inward * (*c_cell - *c_in);
				const double frame_px = width * frame_ratio / depth;
				if (frame_px < kMinFramePx) continue;
				const int base = static_cast<int>(std::lround(*c_in)) - inward * (kReach + kSearch);
				const int n = static_cast<int>(std::ceil(width)) + 2 * (kReach + kSearch) + 1;
				const int c_first = std::min(base, base + inward * (n - 1)),
						  c_last = std::max(base, base + inward * (n - 1));
				if (s < 0 || s >= (along == 1 ? H : W) || c_first < 0 ||
					c_last >= (along == 1 ? W : H))
					continue;
				const EdgeMode mode = bandLocator(frame_px, p);
				pb.reach_px = bandReach(frame_px, p);
				// The side's channel (lumaIsSharper()) where the centroid
				// reads the band.
				const bool luma =
					mode == EdgeMode::Centroid && q.channel[side] == EdgeChannel::Luma;
				v.resize(n);
				for (int i = 0; i < n; ++i)
				{
					const int x = base + inward * i;
					const uint8_t* px =
						along == 1 ? bgr.ptr<uint8_t>(s) + 3 * x : bgr.ptr<uint8_t>(x) + 3 * s;
					v[i] = luma ? lumaLevel(px) : px[1];
				}
				const double t_in = inward * (*c_in - base), t_cell = inward * (*c_cell - base);
				const int ki = static_cast<int>(std::lround(t_in)),
						  kc = n - 1 - static_cast<int>(std::lround(t_cell));
				// Each edge's dark side is a bar (the frame; the cell) whose
				// far edge, a few pixels away on a small landmark, pulls the
				// derivative's peak away from it, more from the narrower
				// frame: the peak locator removes a model of that lobe.
				const double cell_px = next_green ? width * cell / depth : 0;
				const auto e_in = locateRisingEdge(
					v.data(), n, std::max(1, ki - kSearch), std::min(n - 2, ki + kSearch), min_rise,
					pb, mode, frame_px);
				vr.assign(v.rbegin(), v.rend());
				const auto e_cell_r = locateRisingEdge(
					vr.data(), n, std::max(1, kc - kSearch), std::min(n - 2, kc + kSearch),
					min_rise, pb, mode, cell_px);
				if (!e_in || !e_cell_r) continue;
				const double e_cell = n - 1 - *e_cell_r;
				const double measured = e_cell - *e_in;
				if (measured < 0.5 * width || measured > 1.5 * width) continue;
				excess.push_back(measured - width);
				run_of.push_back(3 * side + c);
				pos_of.push_back(s);
				// The inner edge: half the band's predicted width outside
				// its measured midline.
				const double e = 0.5 * (*e_in + e_cell) - 0.5 * (t_cell - t_in);
				const double a = base + inward * e;
				Eigen::Vector2d pt = along == 1 ? Eigen::Vector2d(a, s) : Eigen::Vector2d(s, a);
				if (distorted) pt = cam.undistortPixel(pt);
				const LineFit& l = q.sides[side];
				residuals.push_back(l.normal.dot(pt) + l.c);
			}
		}
		if (static_cast<int>(residuals.size()) < kMinProfiles) continue;
		// The profiles' residuals fall into populations along a side (the
		// mosaic's alternate rows, the codec's blocks): their midmean.
		const double move = midmeanOf(residuals);
		if (std::abs(move) <= kMaxMovePx) next.sides[side].c -= move;
	}
	if (decide && static_cast<int>(excess.size()) >= kMinProfiles)
	{
		const MedianWithError m = medianWithError(excess);
		q.bend_px = next.bend_px = 0.5 * m.median;
		q.bend_se_px = next.bend_se_px =
			0.5 * m.se * std::sqrt(correlationInflation(excess, run_of, pos_of));
	}
	if (decide && !bandsShowBend(excess)) return false;
	if (!cornersFromSides(next, cam)) return false;
	q = std::move(next);
	return true;
}
}  // namespace

void centreOnBand(
	const cv::Mat& bgr, RefinedQuad& q, const CameraModel& cam, double min_rise, double frame_ratio,
	double fill_ratio, const SubpixelParams& p)
{
	// The band's predicted width scales with the square: a square read a
	// few tenths of a pixel too large on a side predicts the band wider by
	// the band's share of the growth (35 of 160 on each side), and so its
	// inner edge outwards by about a fifth of the error. Each pass from the
	// previous one's square leaves a fifth of it: three leave under 1%.
	for (int pass = 0; pass < 3; ++pass)
		if (!centreOnBandOnce(bgr, q, cam, min_rise, frame_ratio, fill_ratio, p, pass == 0)) return;
}

}  // namespace codemark::detect
