// Stage 7b: the reference square from the black frame's midline.
//
// A camera's transfer curve (sRGB, gamma, a phone's filmic curve) applied
// after the optics' blur bends every edge's encoded profile towards its
// dark side: the frame's inner edge moves outwards, its outer edge inwards,
// by a few tenths of a pixel each, and no edge locator that reads one edge
// can tell that shift from the edge's position without knowing the curve.
// The frame's two edges have the same dark side, so the midline between
// them is unmoved (exactly when the fill and the sheet are equally bright;
// otherwise the missing width is shared in the ratio of their bends), and
// so is it under printers' dot gain, which widens the black on both sides.
// With the frame's width known from the square's homography, the inner
// edge is the midline plus half of it.
#include "stages.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace codemark::detect
{
namespace
{
/** The narrowest quiet margin next to which the outer edge is read [px]. */
constexpr double kMinMarginPx = 1.0;
/** ... and the narrowest in units of the edge's blur sigma: the half width
 * at half maximum of its derivative, sqrt(2 ln 2). */
const double kMarginBlurs = std::sqrt(2 * std::log(2.0));
/** The smallest shift of every side of a landmark [px] for which the
 * midline replaces the single-edge lines: the frame read 0.2 px narrower
 * than the homography's width on all four sides, beyond what a clip in
 * linear light and the peak locator's own scatter do to one; a transfer
 * curve does more to each. */
constexpr double kMinShiftPx = 0.1;
/** Profiles read a side at most: for the decision and the first square
 * (the second pass's frame widths), and for the final line. The midline's
 * scatter per profile is under a tenth of a pixel on a noisy frame: 64
 * profiles fix a line to about a hundredth. */
constexpr int kDecisionProfiles = 24, kLineProfiles = 64;

/** Across coordinate [raw px] of a polyline (points ordered along) at
 * along coordinate \a s; nullopt outside it. \a from: the segment to
 * start from, advanced to the one found (the profiles come in order). */
std::optional<double> acrossAt(
	const std::vector<Eigen::Vector2d>& poly, int along, double s, size_t& from)
{
	const int across = 1 - along;
	for (size_t i = std::max<size_t>(from, 1); i < poly.size(); ++i)
	{
		const double a0 = poly[i - 1](along), a1 = poly[i](along);
		if (s > std::max(a0, a1)) continue;
		if (s < std::min(a0, a1) || a0 == a1) return std::nullopt;
		from = i;
		const double t = (s - a0) / (a1 - a0);
		return poly[i - 1](across) + t * (poly[i](across) - poly[i - 1](across));
	}
	return std::nullopt;
}

/** The side from face corner \a f0 to \a f1 pushed outwards by \a out (in
 * face units), sampled about every pixel in raw pixels, ordered along. */
std::vector<Eigen::Vector2d> sidePolyline(
	const FaceMap& map, const Eigen::Vector2d& f0, const Eigen::Vector2d& f1, double out, int along)
{
	// The face corners are (+-1, +-1): the side's outward normal is their
	// mean's direction.
	const Eigen::Vector2d shift = out * 0.5 * (f0 + f1);
	const Eigen::Vector2d p0 = map(f0 + shift), p1 = map(f1 + shift);
	const int n = std::max(2, static_cast<int>(std::ceil((p1 - p0).norm())) + 1);
	std::vector<Eigen::Vector2d> poly;
	poly.reserve(n + 1);
	for (int i = 0; i <= n; ++i)
	{
		const double t = double(i) / n;
		poly.push_back(map(f0 + t * (f1 - f0) + shift));
	}
	if (poly.front()(along) > poly.back()(along)) std::reverse(poly.begin(), poly.end());
	return poly;
}
}  // namespace

std::optional<FrameSide> readFrameSide(
	const cv::Mat& bgr, const RefinedQuad& q, int side, const CameraModel& cam, double min_rise,
	double frame_ratio, double margin_ratio, const SubpixelParams& p, int max_profiles,
	double offset)
{
	const bool distorted = cam.hasDistortion();
	const FaceMap map{faceToImage(q.corners_ideal), cam, distorted};
	const Eigen::Vector2d a = q.corners_raw[side], b = q.corners_raw[(side + 1) % 4];
	const Eigen::Vector2d ab = b - a;
	FrameSide out;
	out.side = side;
	const int along = out.along = std::abs(ab.y()) >= std::abs(ab.x()) ? 1 : 0;
	const int across = 1 - along;
	const Eigen::Vector2d centre =
		0.25 * (q.corners_raw[0] + q.corners_raw[1] + q.corners_raw[2] + q.corners_raw[3]);
	const int inward = out.inward = centre(across) > 0.5 * (a(across) + b(across)) ? 1 : -1;
	const Eigen::Vector2d &f0 = kFaceCorners[side], &f1 = kFaceCorners[(side + 1) % 4];
	const auto inner = sidePolyline(map, f0, f1, 0, along);
	const auto outer = sidePolyline(map, f0, f1, 2 * frame_ratio, along);
	const auto sheet = sidePolyline(map, f0, f1, 2 * (frame_ratio + margin_ratio), along);
	// The search around each predicted edge: the response's shift (a few
	// tenths of a pixel) and the square's error, short of the margin's edge
	// a quarter of a frame width outside.
	constexpr int kSearch = 2;
	const int reach = kSearch + p.reach_px + 2;
	const int W = bgr.cols, H = bgr.rows;
	const double s0 = std::min(a(along), b(along)) + p.corner_margin_px;
	const double s1 = std::max(a(along), b(along)) - p.corner_margin_px;
	double min_margin = std::numeric_limits<double>::infinity();
	auto& reads = out.reads;
	std::vector<int> v, vr;
	const int first = static_cast<int>(std::ceil(s0)), last = static_cast<int>(std::floor(s1));
	// An odd stride, so that the profiles take every phase of a Bayer
	// mosaic's rows and of a JPEG's blocks.
	const int stride = std::max(1, (last - first + 1) / std::max(1, max_profiles)) | 1;
	size_t at_inner = 0, at_outer = 0, at_sheet = 0;
	for (int s = first + static_cast<int>(offset * stride); s <= last; s += stride)
	{
		const auto c_in = acrossAt(inner, along, s, at_inner),
				   c_out = acrossAt(outer, along, s, at_outer),
				   c_sheet = acrossAt(sheet, along, s, at_sheet);
		if (!c_in || !c_out || !c_sheet) continue;
		const double margin = inward * (*c_out - *c_sheet);
		const double width = inward * (*c_in - *c_out);
		// The margin's edge within a pixel of the frame's: its lobe merges
		// with the outer edge's and cannot be removed (far or steep views;
		// the spec's 5 mm margin is a quarter of the frame).
		if (margin < kMinMarginPx) return std::nullopt;
		min_margin = std::min(min_margin, margin);
		// Profile index i <-> across coordinate base + inward * i, pointing
		// into the fill.
		const int base = static_cast<int>(std::lround(*c_out)) - inward * reach;
		const int n = static_cast<int>(std::ceil(width)) + 2 * reach + 1;
		const int c_first = std::min(base, base + inward * (n - 1)),
				  c_last = std::max(base, base + inward * (n - 1));
		if (s < 0 || s >= (along == 1 ? H : W) || c_first < 0 || c_last >= (along == 1 ? W : H))
			continue;
		v.resize(n);
		for (int i = 0; i < n; ++i)
		{
			const int c = base + inward * i;
			v[i] = along == 1 ? bgr.at<cv::Vec3b>(s, c)[1] : bgr.at<cv::Vec3b>(c, s)[1];
		}
		// Both edges at the derivative's peak, which a neighbouring edge of
		// opposite sign moves far less than the response's centroid: the
		// frame's other edge (alike for both, so it cancels on the
		// midline), and for the outer edge the margin's edge to the wall,
		// a quarter of a frame width outside (its lobe removed: a wall
		// darker than the sheet would pull the outer edge inwards). A
		// clipped fill or sheet is a hard knee of the transfer curve: on
		// both edges it moves the estimate towards the frame, and cancels
		// alike.
		const int ki = static_cast<int>(std::lround(inward * (*c_in - base))),
				  ko = static_cast<int>(std::lround(inward * (*c_out - base)));
		const auto e_in =
			locateRisingEdge(v.data(), n, ki - kSearch, ki + kSearch, min_rise, p, EdgeMode::Peak);
		vr.assign(v.rbegin(), v.rend());
		const auto e_out_r = locateRisingEdge(
			vr.data(), n, n - 1 - ko - kSearch, n - 1 - ko + kSearch, min_rise, p, EdgeMode::Peak,
			-margin);
		if (!e_in || !e_out_r) continue;
		const double e_out = n - 1 - *e_out_r;
		const double measured = *e_in - e_out;
		if (measured < 0.5 * width || measured > 1.5 * width) continue;
		FrameReading r{s, base, *e_in, e_out, width, 255, 0, 0, 0};
		{
			// The inner edge's blur: the spread of its central differences
			// (positive ones, within a frame width), less the difference's
			// 2-px box (1/3 px^2) and the pixel's (1/12).
			double s0 = 0, s1 = 0, s2 = 0;
			const int k0 = std::max(1, static_cast<int>(*e_in - 0.5 * width)),
					  k1 = std::min(n - 2, static_cast<int>(*e_in + 0.5 * width) + 1);
			for (int k = k0; k <= k1; ++k)
			{
				const double d = std::max(0, v[k + 1] - v[k - 1]);
				s0 += d;
				s1 += d * k;
				s2 += d * k * k;
			}
			if (s0 > 0) r.blur_var = s2 / s0 - (s1 / s0) * (s1 / s0) - 1.0 / 3 - 1.0 / 12;
		}
		for (int i = std::max(0, ko); i <= std::min(n - 1, ki); ++i)
			r.dark = std::min(r.dark, v[i]);
		for (int i = ki + 2; i <= std::min(n - 1, ki + 4); ++i) r.fill = std::max(r.fill, v[i]);
		for (int i = std::max(0, ko - static_cast<int>(margin)); i < ko; ++i)
			r.sheet = std::max(r.sheet, v[i]);
		reads.push_back(r);
	}
	if (reads.empty()) return std::nullopt;
	// The margin must be resolved: where its edge lies within the half
	// maximum of the frame's outer edge's response, the two merge and the
	// lobe model leaves part of the wall's pull.
	{
		std::vector<double> var;
		var.reserve(reads.size());
		for (const auto& r : reads) var.push_back(r.blur_var);
		std::nth_element(var.begin(), var.begin() + var.size() / 2, var.end());
		const double blur = std::sqrt(std::max(0.0, var[var.size() / 2]));
		if (min_margin < kMarginBlurs * blur) return std::nullopt;
	}
	return out;
}

std::optional<FrameMidline> midlineOfSide(
	const FrameSide& f, const RefinedQuad& q, const CameraModel& cam, double frame_ratio,
	const SubpixelParams& p)
{
	// The bend of an edge grows with its contrast: through sRGB or a gamma
	// of 1.8-2.6, as the square root of the encoded step from the same
	// black within 5% (fill and sheet levels from 0.3 to 1 in linear
	// light). The frame's missing width is shared in that ratio.
	const auto median = [&](auto level)
	{
		std::vector<int> x;
		x.reserve(f.reads.size());
		for (const auto& r : f.reads) x.push_back(level(r));
		std::nth_element(x.begin(), x.begin() + x.size() / 2, x.end());
		return std::max(1, x[x.size() / 2]);
	};
	const double root_in = std::sqrt(median([](const FrameReading&r) { return r.fill - r.dark; })),
				 root_out =
					 std::sqrt(median([](const FrameReading&r) { return r.sheet - r.dark; }));
	const double share_in = root_in / (root_in + root_out);
	// The frame's width at each reading from q's homography.
	const bool distorted = cam.hasDistortion();
	const FaceMap map{faceToImage(q.corners_ideal), cam, distorted};
	const Eigen::Vector2d &f0 = kFaceCorners[f.side], &f1 = kFaceCorners[(f.side + 1) % 4];
	const auto inner = sidePolyline(map, f0, f1, 0, f.along);
	const auto outer = sidePolyline(map, f0, f1, 2 * frame_ratio, f.along);
	size_t at_inner = 0, at_outer = 0;
	std::vector<Eigen::Vector2d> pts;
	std::vector<double> shifts;
	pts.reserve(f.reads.size());
	shifts.reserve(f.reads.size());
	for (const auto& r : f.reads)
	{
		const auto c_in = acrossAt(inner, f.along, r.s, at_inner),
				   c_out = acrossAt(outer, f.along, r.s, at_outer);
		if (!c_in || !c_out) continue;
		const double width = f.inward * (*c_in - *c_out);
		const double shift = share_in * (width - (r.e_in - r.e_out));
		shifts.push_back(shift);
		const double c = r.base + f.inward * (r.e_in + shift);
		Eigen::Vector2d pt = f.along == 1 ? Eigen::Vector2d(c, r.s) : Eigen::Vector2d(r.s, c);
		if (distorted) pt = cam.undistortPixel(pt);
		pts.push_back(pt);
	}
	if (shifts.empty()) return std::nullopt;
	auto line = fitLine(std::move(pts), p);
	if (!line) return std::nullopt;
	std::nth_element(shifts.begin(), shifts.begin() + shifts.size() / 2, shifts.end());
	return FrameMidline{std::move(*line), shifts[shifts.size() / 2]};
}

std::optional<FrameMidline> frameMidlineSide(
	const cv::Mat& bgr, const RefinedQuad& q, int side, const CameraModel& cam, double min_rise,
	double frame_ratio, double margin_ratio, const SubpixelParams& p, int max_profiles)
{
	const auto f =
		readFrameSide(bgr, q, side, cam, min_rise, frame_ratio, margin_ratio, p, max_profiles);
	if (!f) return std::nullopt;
	return midlineOfSide(*f, q, cam, frame_ratio, p);
}

void centreOnFrame(
	const cv::Mat& bgr, RefinedQuad& q, const CameraModel& cam, double min_rise, double frame_ratio,
	double margin_ratio, const SubpixelParams& p)
{
	// The first pass decides on a few profiles a side (kDecisionProfiles):
	// where one side's frame reads as wide as the homography says, within
	// the midline's own scatter, or wider (printers' dot gain widens it),
	// there is no bend to undo, and the single-edge models (exact in
	// linear light, with their restoration of a clipped fill) stay. A
	// transfer curve bends every side of the landmark alike.
	std::array<std::optional<FrameSide>, 4> read;
	RefinedQuad next = q;
	int count = 0;
	for (int side = 0; side < 4; ++side)
	{
		read[side] = readFrameSide(
			bgr, q, side, cam, min_rise, frame_ratio, margin_ratio, p, kDecisionProfiles);
		if (!read[side]) continue;
		auto m = midlineOfSide(*read[side], q, cam, frame_ratio, p);
		if (!m) continue;
		if (m->shift_px < kMinShiftPx) return;
		next.sides[side] = std::move(m->line);
		++count;
	}
	if (count == 0 || !cornersFromSides(next, cam)) return;
	// The second pass reads each such side on more profiles between the
	// first's, around the first pass's square, and places every reading's
	// midline with that square's frame widths: the widths, not the edges,
	// depend on the square.
	const RefinedQuad first = next;
	count = 0;
	for (int side = 0; side < 4; ++side)
	{
		if (!read[side]) continue;
		if (const auto more = readFrameSide(
				bgr, first, side, cam, min_rise, frame_ratio, margin_ratio, p,
				kLineProfiles - kDecisionProfiles, 0.5))
		{
			auto& r = read[side]->reads;
			r.insert(r.end(), more->reads.begin(), more->reads.end());
			std::sort(
				r.begin(), r.end(),
				[](const FrameReading& x, const FrameReading& y) { return x.s < y.s; });
			r.erase(
				std::unique(
					r.begin(), r.end(),
					[](const FrameReading& x, const FrameReading& y) { return x.s == y.s; }),
				r.end());
		}
		auto m = midlineOfSide(*read[side], first, cam, frame_ratio, p);
		if (!m) continue;
		next.sides[side] = std::move(m->line);
		++count;
	}
	if (count == 0 || !cornersFromSides(next, cam)) return;
	q = std::move(next);
}

}  // namespace codemark::detect
