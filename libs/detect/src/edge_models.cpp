// Stage 7's parts: a side's profiles, the edge locators and their policy.
#include "edge_models.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace codemark::detect
{
Eigen::Vector2d SideProfiles::point(size_t j, double e) const
{
	const double c = origin[j] + inward * (e - half);
	return along == 1 ? Eigen::Vector2d(c, pos[j]) : Eigen::Vector2d(pos[j], c);
}

SideProfiles readSideProfiles(
	const cv::Mat& bgr, const Quad& coarse, int side, double frame_ratio, double fill_ratio,
	const SubpixelParams& p)
{
	SideProfiles out;
	out.side = side;
	const Eigen::Vector2d centre = 0.25 * (coarse[0] + coarse[1] + coarse[2] + coarse[3]);
	const int W = bgr.cols, H = bgr.rows;
	// Side k runs from corner k to corner k+1 (top: TL-TR, right: TR-BR,
	// bottom: BR-BL, left: BL-TL).
	const Eigen::Vector2d &a = coarse[side], &b = coarse[(side + 1) % 4];
	const Eigen::Vector2d ab = b - a;
	// Scan rows for a mostly vertical side, columns otherwise; the profile
	// runs across the side along the other axis.
	const int along = std::abs(ab.y()) >= std::abs(ab.x()) ? 1 : 0;
	const int across = 1 - along;
	out.along = along;
	out.across = across;
	// Profiles point into the fill, where G rises.
	const Eigen::Vector2d mid = 0.5 * (a + b);
	const int inward = centre(across) > mid(across) ? 1 : -1;
	out.inward = inward;
	// Width of the black frame across this side [px], from the extent of
	// the neighbouring sides; perspective makes the frame next to this side
	// wider or narrower than the average in the ratio of this side's length
	// (its local scale) to the mean of it and the opposite side's.
	const Eigen::Vector2d prev_side = coarse[side] - coarse[(side + 3) % 4];
	const Eigen::Vector2d next_side = coarse[(side + 2) % 4] - coarse[(side + 1) % 4];
	const double own = ab.norm(),
				 opposite = (coarse[(side + 3) % 4] - coarse[(side + 2) % 4]).norm();
	out.frame_px = frame_ratio * 0.5 * (std::abs(prev_side(across)) + std::abs(next_side(across))) *
				   (own + opposite > 0 ? 2 * own / (own + opposite) : 1.0);
	out.fill_px = out.frame_px * fill_ratio / frame_ratio;
	const double s0 = std::min(a(along), b(along)) + p.corner_margin_px;
	const double s1 = std::max(a(along), b(along)) - p.corner_margin_px;
	const int half = p.search_px + p.reach_px + 2;
	const int n = 2 * half + 1;
	out.half = half;
	out.n = n;
	out.lo = half - p.search_px;
	out.hi = half + p.search_px;
	const size_t max_profiles = static_cast<size_t>(std::max(0.0, s1 - s0 + 1));
	out.g.reserve(max_profiles * n);
	out.rb.reserve(max_profiles * n);
	for (int s = static_cast<int>(std::ceil(s0)); s <= static_cast<int>(std::floor(s1)); ++s)
	{
		const double cpred = a(across) + (s - a(along)) * ab(across) / ab(along);
		const int c0 = static_cast<int>(std::lround(cpred));
		const int c_first = c0 - half, c_last = c0 + half;
		if (s < 0 || s >= (along == 1 ? H : W) || c_first < 0 || c_last >= (along == 1 ? W : H))
			continue;
		// Sample i at pixel c0 + inward * (i - half) across: a step of 3
		// bytes along a row, a row's bytes down a column.
		const std::ptrdiff_t stride =
			inward * (along == 1 ? 3 : static_cast<std::ptrdiff_t>(bgr.step[0]));
		const uint8_t* px = along == 1 ? bgr.ptr<uint8_t>(s) + 3 * (c0 - inward * half)
									   : bgr.ptr<uint8_t>(c0 - inward * half) + 3 * s;
		const size_t at = out.g.size();
		out.g.resize(at + n);
		out.rb.resize(at + n);
		int fill_sum = 0;
		for (int i = 0; i < n; ++i, px += stride)
		{
			out.g[at + i] = px[1];
			out.rb[at + i] = -(px[0] + px[2]);
			if (i >= out.hi + 2) fill_sum += px[1];
		}
		if (fill_sum >= p.saturation_level * (n - out.hi - 2))
		{
			++out.saturated;
			// Clipped: G reaches the sensor's top within two samples of its
			// steepest point, where the peak fit reads it.
			const int* gp = out.g.data() + at;
			const int k = steepestRise(gp, out.lo, out.hi);
			out.clipped += gp[std::min(n - 1, k + 2)] >= 254;
		}
		out.pos.push_back(s);
		out.origin.push_back(c0);
	}
	return out;
}

void readLumaProfiles(const cv::Mat& bgr, SideProfiles& side)
{
	for (size_t j = 0; j < side.count(); ++j)
		for (int i = 0; i < side.n; ++i)
		{
			const int c = side.origin[j] + side.inward * (i - side.half);
			const uint8_t* px = side.along == 1 ? bgr.ptr<uint8_t>(side.pos[j]) + 3 * c
												: bgr.ptr<uint8_t>(c) + 3 * side.pos[j];
			side.g[j * side.n + i] = lumaLevel(px);
		}
}

namespace
{
/** Response widths compared within this many samples of the edge. */
constexpr int kWidthReach = 3;
/** lumaIsSharper(): the width difference's least significance [standard
 * errors] and the fewest profiles. */
constexpr double kMinSharperZ = 3;
constexpr int kMinSharperProfiles = 5;
/** lumaIsSharper(): the least widening of G's response that counts, as a
 * fraction of its second moment. Chroma at half resolution adds about
 * 0.41 x 4/12 px^2 to it (G carries 41% of a green fill's step through
 * the chroma, whose 2-px cells add 4/12 px^2): 15-30% of a focused edge's.
 * Less is what the sensor's clip at black does to luma's R and B tails
 * where the fill's R and B are black (up to about 10% on a dim, blurred
 * edge), not the camera's chroma. */
constexpr double kMinWiden = 0.15;

/** The second moment [px^2] about the edge \a e of \a v's central
 * differences on its fill side, up to kWidthReach samples beyond it: the
 * frame's outer edge lies on the other side, and the differences are
 * summed as they are (not clipped at 0), so that noise cancels rather
 * than widens. */
double responseWidth2(const int* v, int n, double e)
{
	double s0 = 0, s2 = 0;
	const int k0 = static_cast<int>(std::ceil(e));
	for (int k = std::max(1, k0); k <= std::min(n - 2, k0 + kWidthReach); ++k)
	{
		const double d = v[k + 1] - v[k - 1];
		s0 += d;
		s2 += d * (k - e) * (k - e);
	}
	return s0 > 0 ? s2 / s0 : 0.0;
}
}  // namespace

bool lumaIsSharper(
	const SideProfiles& green, const std::vector<std::optional<double>>& green_edges,
	const SideProfiles& luma, const std::vector<std::optional<double>>& luma_edges)
{
	std::vector<double> narrower, green_width;
	for (size_t j = 0; j < std::min(green_edges.size(), luma_edges.size()); ++j)
		if (green_edges[j] && luma_edges[j])
		{
			green_width.push_back(responseWidth2(green.gAt(j), green.n, *green_edges[j]));
			narrower.push_back(
				green_width.back() - responseWidth2(luma.gAt(j), luma.n, *luma_edges[j]));
		}
	if (static_cast<int>(narrower.size()) < kMinSharperProfiles) return false;
	const MedianWithError m = medianWithError(std::move(narrower));
	return m.median > kMinSharperZ * m.se && m.median >= kMinWiden * medianOf(green_width);
}

double edgeSlope(const SideProfiles& side, const std::vector<std::optional<double>>& edges)
{
	std::vector<double> slopes;
	for (size_t j = 0; j < edges.size(); ++j)
		if (edges[j])
		{
			const int k = static_cast<int>(std::lround(*edges[j]));
			if (k >= 1 && k + 1 < side.n)
				slopes.push_back(0.5 * std::abs(side.gAt(j)[k + 1] - side.gAt(j)[k - 1]));
		}
	return slopes.empty() ? 0.0 : medianOf(slopes);
}

SideProperties measureSide(const SideProfiles& side)
{
	const int half_count = static_cast<int>(side.count()) / 2;
	SideProperties s;
	s.frame_px = side.frame_px;
	s.saturated = side.saturated > half_count;
	s.clipped = side.clipped > half_count;
	return s;
}

const char* locatorName(LocatorKind kind)
{
	switch (kind)
	{
		case LocatorKind::Centroid:
			return "centroid";
		case LocatorKind::Peak:
			return "peak";
		case LocatorKind::Channels:
			return "channels";
	}
	return "?";
}

LocatorChoice chooseLocator(
	const SideProperties& s, const SubpixelParams& p, const SubpixelModels& models)
{
	const bool thin = s.frame_px < p.min_frame_px_centroid;
	const double outer = models.outer_edge ? s.frame_px : 0.0;
	// An unsaturated fill: the centroid, unless the frame's outer edge
	// overlaps the response.
	if (!s.saturated)
		return thin ? LocatorChoice{LocatorKind::Peak, outer}
					: LocatorChoice{
						  LocatorKind::Centroid, 0.0,
						  models.luma_edges ? EdgeChannel::Luma : EdgeChannel::Green};
	// A saturated fill cuts the response's bright side, which pulls its
	// centroid towards the frame; the peak barely moves until the clip
	// comes within a sample of it (0.2-0.4 px at gain 1.2-1.5). Then R + B
	// tells, except on a thin frame where its outer edge is too close. (R +
	// B alone would suffer from JPEG's chroma subsampling.)
	if (s.clipped && !thin) return {LocatorKind::Channels, 0.0};
	// A clip in the peak's samples breaks the outer lobe's model.
	return {LocatorKind::Peak, s.clipped ? 0.0 : outer};
}

namespace
{
/** The farthest R + B's edge may lie from G's clipped peak [px]
 * (ChannelsLocator). */
constexpr double kMaxChannelOffsetPx = 0.75;

class CentroidLocator : public EdgeLocator
{
   public:
	CentroidLocator(double min_rise, const SubpixelParams& p) : min_rise_(min_rise), p_(p) {}
	std::optional<double> locate(const int* g, const int*, int n, int lo, int hi) const override
	{
		return locateRisingEdge(g, n, lo, hi, min_rise_, p_, EdgeMode::Centroid);
	}

   private:
	double min_rise_;
	SubpixelParams p_;
};

class PeakLocator : public EdgeLocator
{
   public:
	PeakLocator(double min_rise, const SubpixelParams& p, EdgeMode mode, double outer_px)
		: min_rise_(min_rise), p_(p), mode_(mode), outer_px_(outer_px)
	{
	}
	std::optional<double> locate(const int* g, const int*, int n, int lo, int hi) const override
	{
		return locateRisingEdge(g, n, lo, hi, min_rise_, p_, mode_, outer_px_);
	}

   private:
	double min_rise_;
	SubpixelParams p_;
	EdgeMode mode_;
	double outer_px_;
};

class ChannelsLocator : public EdgeLocator
{
   public:
	ChannelsLocator(double min_rise, const SubpixelParams& p) : min_rise_(min_rise), p_(p) {}
	std::optional<double> locate(const int* g, const int* rb, int n, int lo, int hi) const override
	{
		// G's peak only centres the search (no step model): in R + B the
		// frame's outer edge (white to black) rises too, a frame width
		// away, so the response is read next to G's peak and stopped where
		// it stops falling.
		const auto g_peak = locateRisingEdge(g, n, lo, hi, min_rise_, p_, EdgeMode::PeakGaussian);
		if (!g_peak) return std::nullopt;
		const int k = static_cast<int>(std::lround(*g_peak));
		const auto r =
			locateRisingEdge(rb, n, k - 1, k + 1, p_.min_rise_rb, p_, EdgeMode::IsolatedCentroid);
		// The clip pulls G's peak towards the frame by up to about 0.6 px
		// (a fill at 1.4 times the sensor's top, blur 0.8 px): R + B
		// farther from it than that is not the fill's edge (lateral
		// chromatic aberration, a demosaicing's fringes, a transfer curve
		// that bent it into the fill).
		return r && std::abs(*r - *g_peak) <= kMaxChannelOffsetPx ? r : g_peak;
	}

   private:
	double min_rise_;
	SubpixelParams p_;
};
}  // namespace

std::unique_ptr<EdgeLocator> makeLocator(
	const LocatorChoice& choice, double min_rise, const SubpixelParams& p,
	const SubpixelModels& models)
{
	switch (choice.kind)
	{
		case LocatorKind::Peak:
			return std::make_unique<PeakLocator>(
				min_rise, p, models.step_peak ? EdgeMode::Peak : EdgeMode::PeakGaussian,
				choice.outer_edge_px);
		case LocatorKind::Channels:
			return std::make_unique<ChannelsLocator>(min_rise, p);
		case LocatorKind::Centroid:
			break;
	}
	return std::make_unique<CentroidLocator>(min_rise, p);
}

std::vector<std::optional<double>> locateEdges(const SideProfiles& side, const EdgeLocator& locator)
{
	const int n = side.n;
	std::vector<std::optional<double>> edges(side.count());
	for (size_t j = 0; j < side.count(); ++j)
	{
		const int* gp = side.gAt(j);
		const int* rbp = side.rbAt(j);
		const auto greenInside = [&](double e)
		{
			const int i = std::min(n - 1, static_cast<int>(std::lround(e)) + 2);
			return 3 * gp[i] > -2 * rbp[i];
		};
		std::optional<double> e = locator.locate(gp, rbp, n, side.lo, side.hi);
		if (e && !greenInside(*e))
		{
			// Retry inwards of the rejected edge.
			e = locator.locate(gp, rbp, n, static_cast<int>(std::lround(*e)) + 1, side.hi);
			if (e && !greenInside(*e)) e.reset();
		}
		edges[j] = e;
	}
	return edges;
}

std::vector<Eigen::Vector2d> edgePoints(
	const SideProfiles& side, const std::vector<std::optional<double>>& edges,
	const CameraModel& camera)
{
	const bool distorted = camera.hasDistortion();
	std::vector<Eigen::Vector2d> pts;
	pts.reserve(side.count());
	for (size_t j = 0; j < side.count(); ++j)
	{
		if (!edges[j]) continue;
		const Eigen::Vector2d pt = side.point(j, *edges[j]);
		// Lines are straight only without distortion: fit undistorted.
		pts.push_back(distorted ? camera.undistortPixel(pt) : pt);
	}
	return pts;
}

}  // namespace codemark::detect
