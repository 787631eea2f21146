// Stage 7c: the square's perspective from the frame's inner and outer edges.
//
// Near face-on the landmark's relative orientation (phi2) is read from the
// difference of the left and right sides' heights, that is from the tilt
// of the top and bottom lines, a fraction of a pixel across the square. A
// camera's processing moves each edge point by an amount that depends on
// where the edge falls in the pixel grid (the mosaic's period, the codec's
// 8-px blocks) and on the content around it; along a side that follows a
// row or a column those errors stay alike over long stretches and tilt the
// fitted line by as much as they move it. The frame's outer edge (black
// against the sheet, 20 mm outside the inner one) runs parallel in the
// face at other phases and next to other content: each outer side's
// direction is a second reading of the perspective, independent of the
// inner side's. One homography is fitted to both, the inner sides with
// their positions (after the bands' centring) and the outer sides with
// their directions only (the outer edge's own response shift, the sheet's
// margin and printers' dot gain move it across, not round), each side
// weighted by its points' scatter about its own line.
#include "stages.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

namespace codemark::detect
{
namespace
{
/** Profiles keep clear of each outer corner by the frame's width (20 of
 * 200 mm: a tenth of the outer side), where the perpendicular side's edge
 * crosses them. */
constexpr double kFrameWidthsGuard = 1.0;
/** Search around the predicted outer edge [+- px]: the inner square's
 * error and a printer's dot gain (up to 0.3 mm). */
constexpr int kSearch = 2;
/** The outer side's points may lie this far from the predicted edge on
 * average [px]; farther, they belong to another edge (a sheet cut at the
 * frame, a wall's edge). */
constexpr double kMaxOffsetPx = 1.5;
/** Narrowest frame read [px]: under it the inner edge lies within the
 * outer edge's response. */
constexpr double kMinFramePx = 3;
/** Straight pieces each outer side is split into for the profiles'
 * placement (a lens's distortion bends the side). */
constexpr int kPieces = 8;
/** A side's scatter is floored at this [px] for its weight: a noise-free
 * render's edges scatter by the rounding of their levels only. */
constexpr double kMinScatterPx = 0.005;
/** The fit may move a corner by at most this much [px]: the perspective's
 * share of a corner's error is a few tenths of a pixel. */
constexpr double kMaxCornerMovePx = 1.0;

/** A side's points summarised for a line's squared distances: the count,
 * the centroid and the scatter's principal axes (sqrt of eigenvalue x
 * eigenvector), so that sum_i (a . x_i + c)^2 = n (a . m + c)^2 +
 * sum_j (a . e_j)^2 for a unit normal a. */
struct SideMoments
{
	double n = 0;
	Eigen::Vector2d mean = Eigen::Vector2d::Zero();
	std::array<Eigen::Vector2d, 2> axes{};
	double scatter2 = 0;  //!< per-point variance about the side's own line
};

SideMoments momentsOf(const std::vector<Eigen::Vector2d>& pts)
{
	SideMoments m;
	m.n = static_cast<double>(pts.size());
	for (const auto& x : pts) m.mean += x;
	m.mean /= m.n;
	Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
	for (const auto& x : pts) S += (x - m.mean) * (x - m.mean).transpose();
	const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(S);
	for (int j = 0; j < 2; ++j)
		m.axes[j] = std::sqrt(std::max(0.0, es.eigenvalues()(j))) * es.eigenvectors().col(j);
	m.scatter2 = std::max(kMinScatterPx * kMinScatterPx, es.eigenvalues()(0) / m.n);
	return m;
}

/** The points of \a pts within the line fit's outlier limit of \a line
 * (fitLine()'s rule). */
std::vector<Eigen::Vector2d> inliers(
	const std::vector<Eigen::Vector2d>& pts, const LineFit& line, const SubpixelParams& p)
{
	std::vector<double> r;
	r.reserve(pts.size());
	for (const auto& x : pts) r.push_back(std::abs(line.normal.dot(x) + line.c));
	std::vector<double> sorted = r;
	const double limit = std::max(p.outlier_sigmas * 1.4826 * medianOf(sorted), p.min_outlier_px);
	std::vector<Eigen::Vector2d> kept;
	for (size_t i = 0; i < pts.size(); ++i)
		if (r[i] <= limit) kept.push_back(pts[i]);
	return kept;
}

/** The outer edge's points of side \a side [ideal px], located on
 * profiles along rows or columns from the frame outwards, in luma (the
 * edge is black against white: every channel carries it). */
std::vector<Eigen::Vector2d> outerEdgePoints(
	const cv::Mat& bgr, const FaceMap& map, const CameraModel& cam, int side, double frame_ratio,
	double min_rise, const SubpixelParams& p)
{
	std::vector<Eigen::Vector2d> pts;
	const double scale = 1 + 2 * frame_ratio;  // outer over inner half-side
	const Eigen::Vector2d f0 = kFaceCorners[side] * scale,
						  f1 = kFaceCorners[(side + 1) % 4] * scale;
	const Eigen::Vector2d out(kSideNormals[side][0], kSideNormals[side][1]);
	// Face units are half the inner side: the frame is 2 frame_ratio wide.
	const double guard = kFrameWidthsGuard * frame_ratio / scale;
	const Eigen::Vector2d mid = 0.5 * (f0 + f1);
	const Eigen::Vector2d i_mid = map(mid), i_in = map(mid - out * 2 * frame_ratio);
	const double frame_px = (i_mid - i_in).norm();
	if (frame_px < kMinFramePx) return pts;
	const EdgeMode mode = frame_px >= p.min_frame_px_centroid ? EdgeMode::Centroid : EdgeMode::Peak;
	SubpixelParams pr = p;
	// Short of the inner edge on the dark side (bandReach()'s rule).
	pr.reach_px =
		std::min(p.reach_px, std::max(2, static_cast<int>(std::floor(frame_px)) - p.reach_px - 1));
	const int along =
		std::abs(map(f1).y() - map(f0).y()) >= std::abs(map(f1).x() - map(f0).x()) ? 1 : 0;
	const int across = 1 - along;
	// Rising from the frame outwards.
	const int dir = map(mid + out * 0.1)(across) > i_mid(across) ? 1 : -1;
	const int W = bgr.cols, H = bgr.rows;
	const int n = 2 * (pr.reach_px + kSearch) + 1, centre = pr.reach_px + kSearch;
	std::vector<int> v(n);
	for (int piece = 0; piece < kPieces; ++piece)
	{
		const double t0 = guard + (1 - 2 * guard) * piece / kPieces,
					 t1 = guard + (1 - 2 * guard) * (piece + 1) / kPieces;
		const Eigen::Vector2d a = map(f0 + t0 * (f1 - f0)), b = map(f0 + t1 * (f1 - f0));
		if (a(along) == b(along)) continue;
		const int s0 = static_cast<int>(std::ceil(std::min(a(along), b(along)))),
				  s1 = static_cast<int>(std::floor(std::max(a(along), b(along))));
		// One profile per row or column: the pieces share their ends.
		for (int s = s0; s <= s1 - (piece + 1 < kPieces ? 1 : 0); ++s)
		{
			const double c =
				a(across) + (s - a(along)) / (b(along) - a(along)) * (b(across) - a(across));
			const int base = static_cast<int>(std::lround(c)) - dir * centre;
			const int c_first = std::min(base, base + dir * (n - 1)),
					  c_last = std::max(base, base + dir * (n - 1));
			if (s < 0 || s >= (along == 1 ? H : W) || c_first < 0 || c_last >= (along == 1 ? W : H))
				continue;
			for (int i = 0; i < n; ++i)
			{
				const int x = base + dir * i;
				const uint8_t* px =
					along == 1 ? bgr.ptr<uint8_t>(s) + 3 * x : bgr.ptr<uint8_t>(x) + 3 * s;
				v[i] = lumaLevel(px);
			}
			const double t_pred = dir * (c - base);
			const int k = static_cast<int>(std::lround(t_pred));
			const auto e = locateRisingEdge(
				v.data(), n, std::max(1, k - kSearch), std::min(n - 2, k + kSearch), min_rise, pr,
				mode, mode == EdgeMode::Peak ? frame_px : 0.0);
			if (!e) continue;
			const double pos = base + dir * *e;
			Eigen::Vector2d pt = along == 1 ? Eigen::Vector2d(pos, s) : Eigen::Vector2d(s, pos);
			if (map.distorted) pt = cam.undistortPixel(pt);
			pts.push_back(pt);
		}
	}
	return pts;
}

/** The face line through \a f0 and \a f1 (homogeneous). */
Eigen::Vector3d faceLine(const Eigen::Vector2d& f0, const Eigen::Vector2d& f1)
{
	return Eigen::Vector3d(f0.x(), f0.y(), 1).cross(Eigen::Vector3d(f1.x(), f1.y(), 1));
}

/** The image line of the face line \a l_face under the line map \a G (the
 * face-to-image homography's inverse transpose), scaled to a unit normal. */
Eigen::Vector3d imageLine(const Eigen::Matrix3d& G, const Eigen::Vector3d& l_face)
{
	const Eigen::Vector3d l = G * l_face;
	return l / l.head<2>().norm();
}
}  // namespace

void fitFramePerspective(
	const cv::Mat& bgr, RefinedQuad& q, const CameraModel& cam, double min_rise, double frame_ratio,
	const SubpixelParams& p)
{
	if (!q.bands_bent ||
		std::any_of(q.levels_rounded.begin(), q.levels_rounded.end(), [](bool r) { return r; }))
		return;
	const Eigen::Matrix3d H0 = faceToImage(q.corners_ideal);
	const FaceMap map{H0, cam, cam.hasDistortion()};
	// Lines map through the homography's inverse transpose: the fit works
	// on that map directly, so that no evaluation inverts a matrix.
	const Eigen::Matrix3d G0 = H0.inverse().transpose();
	const double scale = 1 + 2 * frame_ratio;
	std::array<Eigen::Vector3d, 4> face_inner, face_outer;
	for (int side = 0; side < 4; ++side)
	{
		const Eigen::Vector2d &f0 = kFaceCorners[side], &f1 = kFaceCorners[(side + 1) % 4];
		face_inner[side] = faceLine(f0, f1);
		face_outer[side] = faceLine(f0 * scale, f1 * scale);
	}
	// The data: per inner side its points moved onto its line (the bands'
	// centring moved the line, not the points); per outer side its inliers.
	std::array<std::optional<SideMoments>, 4> inner, outer;
	int outer_sides = 0;
	for (int side = 0; side < 4; ++side)
	{
		const LineFit& l = q.sides[side];
		std::vector<Eigen::Vector2d> pts = inliers(l.points, l, p);
		if (pts.size() < 2) return;
		SideMoments m = momentsOf(pts);
		m.mean -= (l.normal.dot(m.mean) + l.c) * l.normal;
		inner[side] = m;
		auto opts = outerEdgePoints(bgr, map, cam, side, frame_ratio, min_rise, p);
		const auto f = fitLine(opts, p);
		if (!f) continue;
		opts = inliers(opts, *f, p);
		if (static_cast<int>(opts.size()) < p.min_support) continue;
		// Where the predicted outer edge lies.
		const Eigen::Vector3d pred = imageLine(G0, face_outer[side]);
		double offset = 0;
		for (const auto& x : opts) offset += pred.head<2>().dot(x) + pred[2];
		if (std::abs(offset / static_cast<double>(opts.size())) > kMaxOffsetPx) continue;
		outer[side] = momentsOf(opts);
		++outer_sides;
	}
	if (outer_sides == 0) return;

	// Levenberg-Marquardt on the line map's eight free entries (G(2, 2)
	// held), from the inner square's; three residuals per inner side (its
	// offset and its scatter's two axes), two per outer side (its
	// direction only).
	const double g22 = G0(2, 2);
	using Vec8 = Eigen::Matrix<double, 8, 1>;
	using Res = Eigen::Matrix<double, 20, 1>;
	const auto mapOf = [&](const Vec8& g)
	{
		Eigen::Matrix3d G;
		G << g[0], g[1], g[2], g[3], g[4], g[5], g[6], g[7], g22;
		return G;
	};
	const auto residuals = [&](const Vec8& g)
	{
		const Eigen::Matrix3d G = mapOf(g);
		Res r = Res::Zero();
		int i = 0;
		for (int side = 0; side < 4; ++side)
		{
			const SideMoments& m = *inner[side];
			const Eigen::Vector3d l = imageLine(G, face_inner[side]);
			const double w = 1 / std::sqrt(m.scatter2);
			r[i++] = w * std::sqrt(m.n) * (l.head<2>().dot(m.mean) + l[2]);
			for (const auto& e : m.axes) r[i++] = w * l.head<2>().dot(e);
			if (!outer[side]) continue;
			const SideMoments& o = *outer[side];
			const Eigen::Vector3d lo = imageLine(G, face_outer[side]);
			const double wo = 1 / std::sqrt(o.scatter2);
			for (const auto& e : o.axes) r[i++] = wo * lo.head<2>().dot(e);
		}
		return r;
	};
	Vec8 g;
	g << G0(0, 0), G0(0, 1), G0(0, 2), G0(1, 0), G0(1, 1), G0(1, 2), G0(2, 0), G0(2, 1);
	Res r = residuals(g);
	double cost = r.squaredNorm(), mu = 1e-3;
	for (int it = 0; it < 10; ++it)
	{
		Eigen::Matrix<double, 20, 8> J;
		for (int k = 0; k < 8; ++k)
		{
			Vec8 gk = g;
			const double step = 1e-7 * std::max(1e-3, std::abs(g[k]));
			gk[k] += step;
			J.col(k) = (residuals(gk) - r) / step;
		}
		Eigen::Matrix<double, 8, 8> A = J.transpose() * J;
		A.diagonal() += mu * A.diagonal().cwiseMax(1e-12);
		const Vec8 dg = -A.ldlt().solve(J.transpose() * r);
		if (!dg.allFinite()) return;
		const Res rc = residuals(g + dg);
		if (rc.squaredNorm() < cost)
		{
			const bool done = cost - rc.squaredNorm() < 1e-8 * cost;
			g += dg;
			r = rc;
			cost = rc.squaredNorm();
			mu = std::max(1e-9, mu * 0.3);
			if (done) break;
		}
		else if ((mu *= 10) > 1e6)
			break;
	}
	const Eigen::Matrix3d G = mapOf(g);
	RefinedQuad next = q;
	for (int side = 0; side < 4; ++side)
	{
		const Eigen::Vector3d l = imageLine(G, face_inner[side]);
		LineFit& s = next.sides[side];
		const double sign = l.head<2>().dot(s.normal) < 0 ? -1 : 1;
		s.normal = sign * l.head<2>();
		s.c = sign * l[2];
	}
	if (!cornersFromSides(next, cam)) return;
	for (int k = 0; k < 4; ++k)
		if ((next.corners_ideal[k] - q.corners_ideal[k]).norm() > kMaxCornerMovePx) return;
	q = std::move(next);
}

}  // namespace codemark::detect
