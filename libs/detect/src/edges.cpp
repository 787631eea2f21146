// Stages 4-6: edgels and their domains, side selection, quadrangle linking.
#include <codemark/detect/colour.h>

#include "stages.h"

#include <opencv2/imgproc.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace codemark::detect
{
double gradientThreshold(double fill_g, const EdgelParams& p)
{
	return std::max(p.min_gradient, p.rel_gradient * fill_g);
}

namespace
{
/** reducedGreen() by a factor known at compile time (the common ones), so
 * that the block's loops unroll and the rounding division becomes a
 * multiplication. */
template <int K>
void reduceGreenBy(const cv::Mat& bgr, const cv::Rect& roi, cv::Mat& g)
{
	constexpr int kArea = K * K;
	for (int y = 0; y < g.rows; ++y)
	{
		const uint8_t* rows[K];
		for (int r = 0; r < K; ++r) rows[r] = bgr.ptr<uint8_t>(roi.y + y * K + r) + 3 * roi.x + 1;
		uint8_t* out = g.ptr<uint8_t>(y);
		for (int x = 0; x < g.cols; ++x)
		{
			int acc = 0;
			for (int r = 0; r < K; ++r)
				for (int c = 0; c < K; ++c) acc += rows[r][3 * (x * K + c)];
			out[x] = static_cast<uint8_t>((acc + kArea / 2) / kArea);
		}
	}
}
}  // namespace

cv::Mat reducedGreen(const cv::Mat& bgr, const cv::Rect& roi, int k)
{
	cv::Mat g(roi.height / k, roi.width / k, CV_8UC1);
	switch (k)
	{
		case 2:
			reduceGreenBy<2>(bgr, roi, g);
			return g;
		case 3:
			reduceGreenBy<3>(bgr, roi, g);
			return g;
		case 4:
			reduceGreenBy<4>(bgr, roi, g);
			return g;
		default:
			break;
	}
	std::vector<int> acc(g.cols);
	const int area = k * k;
	for (int y = 0; y < g.rows; ++y)
	{
		std::fill(acc.begin(), acc.end(), 0);
		for (int r = 0; r < k; ++r)
		{
			const uint8_t* px = bgr.ptr<uint8_t>(roi.y + y * k + r) + 3 * roi.x + 1;
			for (int x = 0; x < g.cols; ++x, px += 3 * k)
				for (int c = 0; c < k; ++c) acc[x] += px[3 * c];
		}
		uint8_t* out = g.ptr<uint8_t>(y);
		for (int x = 0; x < g.cols; ++x) out[x] = static_cast<uint8_t>((acc[x] + area / 2) / area);
	}
	return g;
}

EdgelMap findEdgels(
	const cv::Mat& bgr, const cv::Rect& roi_in, double threshold, const EdgelParams& p)
{
	EdgelMap m;
	m.roi = roi_in & cv::Rect(0, 0, bgr.cols, bgr.rows);
	m.threshold = threshold;
	// Large ROIs (near landmarks) are reduced by an integer factor: this
	// stage only finds the sides to about a pixel, the sub-pixel stage works
	// at full resolution, and the cost stays bounded.
	const int k = std::max(
		1, static_cast<int>(std::ceil(std::max(m.roi.width, m.roi.height) / p.max_roi_px)));
	m.scale = k;
	m.roi.width -= m.roi.width % k;
	m.roi.height -= m.roi.height % k;
	if (m.roi.width < 3 * k || m.roi.height < 3 * k) return m;
	cv::Mat g, gx, gy;
	if (k > 1)
		g = reducedGreen(bgr, m.roi, k);
	else
		cv::extractChannel(bgr(m.roi), g, 1);
	// Both 3x3 Sobel derivatives in one pass (the same values as two
	// cv::Sobel calls, about half their time).
	cv::spatialGradient(g, gx, gy, 3, cv::BORDER_REPLICATE);
	// The 3x3 Sobel answers 8 per grey level per pixel of slope.
	const int t = static_cast<int>(std::ceil(8 * threshold));
	const int t2 = t * t;
	const int W = g.cols, H = g.rows;
	m.polarity = cv::Mat::zeros(H, W, CV_8UC1);
	// Per row: which pixels' gradients reach the threshold, in a loop the
	// compiler vectorises; most of a ROI is flat, and the suppression
	// below then visits only the few that do.
	std::vector<uint8_t> strong(W, 0);
	for (int y = 1; y < H - 1; ++y)
	{
		const short* ax = gx.ptr<short>(y);
		const short* ay = gy.ptr<short>(y);
		const short* ay_up = gy.ptr<short>(y - 1);
		const short* ay_dn = gy.ptr<short>(y + 1);
		uint8_t* pol = m.polarity.ptr<uint8_t>(y);
		int any = 0;
		for (int x = 0; x < W; ++x)
		{
			const int m2 = int(ax[x]) * ax[x] + int(ay[x]) * ay[x];
			strong[x] = m2 >= t2;
			any |= strong[x];
		}
		if (!any) continue;
		for (int x = 1; x < W - 1; ++x)
		{
			if (!strong[x]) continue;
			const int dx = ax[x], dy = ay[x];
			// Non-maximum suppression along the dominant gradient axis, on
			// the signed component (keeps the two edges of a thin bar apart).
			if (std::abs(dx) >= std::abs(dy))
			{
				const int s = dx > 0 ? 1 : -1;
				if (s * dx < s * ax[x - 1] || s * dx <= s * ax[x + 1]) continue;
				pol[x] = static_cast<uint8_t>(dx > 0 ? Polarity::Left : Polarity::Right);
			}
			else
			{
				const int s = dy > 0 ? 1 : -1;
				if (s * dy < s * ay_up[x] || s * dy <= s * ay_dn[x]) continue;
				pol[x] = static_cast<uint8_t>(dy > 0 ? Polarity::Top : Polarity::Bottom);
			}
		}
	}
	// Edgel domains: 8-connected flood fill over edgels of one polarity
	// (hand-written: cv::connectedComponents would need one pass per
	// polarity and still no second-order moments). The fill clears the
	// edgels it takes in a copy of the map; the map's outermost rows and
	// columns hold no edgels, so every neighbour of an edgel lies inside it.
	cv::Mat unvisited = m.polarity.clone();
	uint8_t* const base = unvisited.ptr<uint8_t>(0);
	const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(unvisited.step[0]);
	// The 8 neighbours in the order the fill visits them (row by row).
	const int offset_x[8] = {-1, 0, 1, -1, 1, -1, 0, 1}, offset_y[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
	std::ptrdiff_t neighbours[8];
	for (int j = 0; j < 8; ++j) neighbours[j] = offset_y[j] * stride + offset_x[j];
	std::vector<cv::Point> pts;
	pts.reserve(256);
	for (int y = 1; y < H - 1; ++y)
	{
		const uint8_t* pol = unvisited.ptr<uint8_t>(y);
		// From one edgel not yet taken to the next.
		for (int x = firstByteFrom(pol, 1, W - 1, false); x < W - 1;
			 x = firstByteFrom(pol, x + 1, W - 1, false))
		{
			const uint8_t cls = pol[x];
			pts.clear();
			pts.emplace_back(x, y);
			base[y * stride + x] = 0;
			for (size_t k = 0; k < pts.size(); ++k)
			{
				const cv::Point q = pts[k];
				uint8_t* const at = base + q.y * stride + q.x;
				for (int j = 0; j < 8; ++j)
				{
					if (at[neighbours[j]] != cls) continue;
					at[neighbours[j]] = 0;
					pts.emplace_back(q.x + offset_x[j], q.y + offset_y[j]);
				}
			}
			if (static_cast<int>(pts.size()) < p.min_edgels) continue;
			EdgelDomain d;
			d.polarity = static_cast<Polarity>(cls);
			d.count = static_cast<int>(pts.size());
			Eigen::Vector2d mean = Eigen::Vector2d::Zero();
			for (const auto& q : pts) mean += Eigen::Vector2d(q.x, q.y);
			mean /= d.count;
			Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
			for (const auto& q : pts)
			{
				const Eigen::Vector2d e = Eigen::Vector2d(q.x, q.y) - mean;
				cov += e * e.transpose();
			}
			cov /= d.count;
			Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es;
			es.computeDirect(cov);
			d.dir = es.eigenvectors().col(1);
			d.width_px = std::sqrt(std::max(0.0, es.eigenvalues()(0)));
			double tmin = std::numeric_limits<double>::max(), tmax = -tmin;
			for (const auto& q : pts)
			{
				const double tt = d.dir.dot(Eigen::Vector2d(q.x, q.y) - mean);
				tmin = std::min(tmin, tt);
				tmax = std::max(tmax, tt);
			}
			// Back to full-image pixels: reduced pixel x covers full pixels
			// k x .. k x + k - 1.
			const Eigen::Vector2d off(m.roi.x + 0.5 * (k - 1), m.roi.y + 0.5 * (k - 1));
			d.mean = k * mean + off;
			d.end0 = d.mean + k * tmin * d.dir;
			d.end1 = d.mean + k * tmax * d.dir;
			d.length_px = k * (tmax - tmin + 1);
			d.width_px *= k;
			d.pixel_px = k;
			m.domains.push_back(d);
		}
	}
	return m;
}

std::optional<SideSegments> selectSegments(
	const std::vector<EdgelDomain>& domains, const Candidate& c, const cv::Mat& mask, int step,
	const SegmentParams& p, const cv::Mat* bgr, double fill_band_rel,
	const SegmentationParams& colour)
{
	// The fill's colour in the image just inside a domain, at two of three
	// points along it: 1.5 px inwards, 1 px beyond the edgel's rounding,
	// keeps a blurred edge (sigma <= 1.5 px) on the fill side and a point
	// 1.5 px inside the sheet's edge on the frame.
	const auto fillInImage = [&](const EdgelDomain& d, const Eigen::Vector2d& inward)
	{
		if (!bgr) return true;
		int hits = 0;
		const double reach = 1.5 + 0.5 * (d.pixel_px - 1);
		for (const double t : {-0.25, 0.0, 0.25})
		{
			const Eigen::Vector2d q = d.mean + t * d.length_px * d.dir + reach * inward;
			const int x = static_cast<int>(std::lround(q.x())),
					  y = static_cast<int>(std::lround(q.y()));
			if (x < 0 || y < 0 || x >= bgr->cols || y >= bgr->rows) continue;
			const uint8_t* px = bgr->ptr<uint8_t>(y) + 3 * x;
			// Green and saturated: at least half the fill's saturation floor
			// (a codec's chroma, averaged over 2 px next to the achromatic
			// frame, keeps half of it), which a grey wall tinted green by the
			// white balance does not reach.
			if (px[1] >= 0.5 * c.fill_g && px[1] > px[0] && px[1] > px[2] &&
				hsiOf(px[2], px[1], px[0]).saturation >= 0.5 * colour.min_saturation)
				++hits;
		}
		return hits >= 2;
	};
	// Is the fill colour found just inside a domain (towards the fill) at
	// two of three points along it? Rejects edges outside the frame (the
	// sheet against the wall), which the fill's bounding box may come near
	// when the codec smears the green over the thin frame.
	const auto fillInside = [&](const EdgelDomain& d, const Eigen::Vector2d& inward, double band_px)
	{
		int hits = 0;
		// The domain's position is known to half a pixel of its gradient
		// image. A grid cell and more inwards, but within the green band
		// before the code board (2.8 px wide at 5 m and 60 deg, where a
		// black code cell 3 px inwards would hide the fill).
		const double reach = std::min(std::max(2.0, step + 1.0), std::max(1.5, 0.6 * band_px)) +
							 0.5 * (d.pixel_px - 1);
		for (const double t : {-0.25, 0.0, 0.25})
		{
			const Eigen::Vector2d q = d.mean + t * d.length_px * d.dir + reach * inward;
			const int x = static_cast<int>(std::floor(q.x() / step)),
					  y = static_cast<int>(std::floor(q.y() / step));
			if (x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<uint8_t>(y, x))
				++hits;
		}
		return hits >= 2;
	};
	SideSegments out;
	const Polarity order[4] = {Polarity::Top, Polarity::Right, Polarity::Bottom, Polarity::Left};
	for (int k = 0; k < 4; ++k)
	{
		const Polarity pol = order[k];
		const bool vertical_side = pol == Polarity::Left || pol == Polarity::Right;
		const double extent = vertical_side ? c.bbox.height : c.bbox.width;
		// The side lies beyond the centroid along the gradient (left of it
		// for the left edge, etc.), and the inner edge bounds the fill: of
		// the qualifying domains, the one nearest the fill's bounding box
		// side (code-cell edges lie 35/160 of a side inside it, edges
		// outside the frame a frame width and more outside it).
		const int axis = vertical_side ? 0 : 1;
		const bool low_side = pol == Polarity::Left || pol == Polarity::Top;
		const double bbox_side =
			low_side ? (axis == 0 ? c.bbox.x : c.bbox.y) - 0.5
					 : (axis == 0 ? c.bbox.x + c.bbox.width : c.bbox.y + c.bbox.height) - 0.5;
		std::vector<std::pair<const EdgelDomain*, double>> qualified;  // with its distance
		for (const auto& d : domains)
		{
			if (d.polarity != pol) continue;
			if (d.width_px > p.max_width_px * d.pixel_px) continue;
			if (d.length_px < p.min_rel_length * extent) continue;
			// Along the side: a vertical side's direction is mostly vertical.
			if (std::abs(d.dir(1 - axis)) < std::abs(d.dir(axis))) continue;
			if (low_side ? d.mean(axis) >= c.centroid(axis) : d.mean(axis) <= c.centroid(axis))
				continue;
			Eigen::Vector2d inward = Eigen::Vector2d::Zero();
			inward(axis) = low_side ? 1 : -1;
			// The fill's extent across this side: the bounding box's other size.
			const double across = vertical_side ? c.bbox.width : c.bbox.height;
			if (!mask.empty() && !fillInside(d, inward, fill_band_rel * across)) continue;
			if (!fillInImage(d, inward)) continue;
			qualified.emplace_back(&d, std::abs(d.mean(axis) - bbox_side));
		}
		if (qualified.empty()) return std::nullopt;
		// The nearest, unless a longer one lies within a tenth of the side
		// behind it (half the way to the code cells' edges): a dim or
		// sharpened side can leave a short piece of ghost edge a pixel or
		// two beside the inner edge, whose domain spans the whole side.
		double nearest = std::numeric_limits<double>::max();
		for (const auto& q : qualified) nearest = std::min(nearest, q.second);
		const double window = nearest + std::max(1.0, 0.1 * extent);
		const EdgelDomain* best = nullptr;
		for (const auto& [d, dist] : qualified)
			if (dist <= window && (!best || d->length_px > best->length_px)) best = d;
		out[k] = *best;
	}
	return out;
}

namespace
{
std::optional<Eigen::Vector2d> intersect(const EdgelDomain& a, const EdgelDomain& b)
{
	// a.mean + s a.dir = b.mean + t b.dir
	Eigen::Matrix2d A;
	A << a.dir, -b.dir;
	if (std::abs(A.determinant()) < 1e-3) return std::nullopt;
	const Eigen::Vector2d st = A.inverse() * (b.mean - a.mean);
	return a.mean + st(0) * a.dir;
}

double nearestEnd(const EdgelDomain& d, const Eigen::Vector2d& q)
{
	return std::min((d.end0 - q).norm(), (d.end1 - q).norm());
}
}  // namespace

std::optional<Quad> linkQuadrangle(const SideSegments& s, const QuadParams& p)
{
	// Sides: 0 top, 1 right, 2 bottom, 3 left; corner k joins sides k-1 and k
	// (TL = left x top, TR = top x right, ...).
	Quad q;
	const int prev[4] = {3, 0, 1, 2};
	for (int k = 0; k < 4; ++k)
	{
		const auto c = intersect(s[prev[k]], s[k]);
		if (!c) return std::nullopt;
		q[k] = *c;
	}
	double perimeter = 0;
	for (int k = 0; k < 4; ++k)
	{
		const double side = (q[(k + 1) % 4] - q[k]).norm();
		if (side < p.min_side_px) return std::nullopt;
		perimeter += side;
	}
	const double gap = std::max(p.max_gap_px, p.max_gap_rel * perimeter / 4);
	for (int k = 0; k < 4; ++k)
		if (nearestEnd(s[prev[k]], q[k]) > gap || nearestEnd(s[k], q[k]) > gap) return std::nullopt;
	// Convex and clockwise in the image (v down): TL -> TR -> BR -> BL.
	for (int k = 0; k < 4; ++k)
	{
		const Eigen::Vector2d a = q[(k + 1) % 4] - q[k], b = q[(k + 2) % 4] - q[(k + 1) % 4];
		if (a.x() * b.y() - a.y() * b.x() <= 0) return std::nullopt;
	}
	return q;
}

}  // namespace codemark::detect
