// Stages 1-3: smoothing, colour segmentation, connected components.
#include "segment_kernel.h"
#include "stages.h"

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#define CODEMARK_STEP2_KERNEL segmentStep2Baseline
#include "segment_step2.inl.h"

namespace codemark::detect
{
namespace
{
FillPredicate makePredicate(const SegmentationParams& p)
{
	return {
		static_cast<int>(std::ceil(3.0 * p.min_intensity)),
		static_cast<int>(std::lround(64.0 * (1.0 - p.min_saturation))),
		static_cast<int>(std::lround(2.0 * (p.hue_min_deg - 120.0))),
		static_cast<int>(std::lround(2.0 * (p.hue_max_deg - 120.0)))};
}

/** The predicate on one colour, as the SIMD kernels evaluate it. */
bool isFill(const FillPredicate& pred, int r, int g, int b)
{
	// HSI hue in [60, 180] deg (hexcone form) needs G to be the largest
	// channel.
	const int sum = r + g + b;
	const int mn = std::min(r, b);
	const int chroma = g - mn;
	const int hue = 120 * (b - r);
	return (sum >= pred.min_sum) & (g > r) & (g > b) & (3 * 64 * mn <= pred.sat64 * sum) &
		   (hue >= pred.hue_lo * chroma) & (hue <= pred.hue_hi * chroma);
}

template <int S, bool Box>
void segmentGrid(const cv::Mat& bgr, cv::Mat& mask, const FillPredicate& pred, int j_first)
{
	// Box: mean of the S x S block, as a fixed-point multiply.
	constexpr int kInv = 65536 / (S * S);
	for (int i = 0; i < mask.rows; ++i)
	{
		uint8_t* out = mask.ptr<uint8_t>(i);
		const uint8_t* rows[S];
		for (int k = 0; k < S; ++k) rows[k] = bgr.ptr<uint8_t>(i * S + k);
		for (int j = j_first; j < mask.cols; ++j)
		{
			int b = 0, g = 0, r = 0;
			if constexpr (Box)
			{
				for (int k = 0; k < S; ++k)
					for (int l = 0; l < S; ++l)
					{
						const uint8_t* px = rows[k] + 3 * (j * S + l);
						b += px[0];
						g += px[1];
						r += px[2];
					}
				b = (b * kInv) >> 16;
				g = (g * kInv) >> 16;
				r = (r * kInv) >> 16;
			}
			else
			{
				const uint8_t* px = rows[0] + 3 * j * S;
				b = px[0];
				g = px[1];
				r = px[2];
			}
			out[j] = isFill(pred, r, g, b) ? 255 : 0;
		}
	}
}

/** Step 2 without smoothing (the default): the predicate on every other
 * pixel of every other row, a SIMD block of cells at a time (AVX2 where the
 * CPU has it). Returns the first column left to the scalar loop. */
int segmentStep2Simd(const cv::Mat& bgr, cv::Mat& mask, const FillPredicate& pred, SimdPath path)
{
	const Step2Rows rows{bgr.ptr<uint8_t>(), bgr.step[0], bgr.cols, mask.ptr<uint8_t>(),
						 mask.step[0],		 mask.rows,	  mask.cols};
#ifdef CODEMARK_DETECT_AVX2
	static const bool avx2 = cv::checkHardwareSupport(CV_CPU_AVX2);
	if (path == SimdPath::Best && avx2) return segmentStep2Avx2(rows, pred);
#endif
	return path == SimdPath::Scalar ? 0 : segmentStep2Baseline(rows, pred);
}
}  // namespace

bool isFillColour(double r, double g, double b, const SegmentationParams& p)
{
	// The integer predicate the segmentation uses, so that tests see the
	// same answer.
	const auto q = [](double v) { return std::clamp(static_cast<int>(std::lround(v)), 0, 255); };
	return isFill(makePredicate(p), q(r), q(g), q(b));
}

cv::Mat segmentColour(const cv::Mat& bgr, const SegmentationParams& p, SimdPath path)
{
	if (bgr.type() != CV_8UC3)
		throw std::invalid_argument("segmentColour: expected a CV_8UC3 image");
	const int s = p.step_px;
	if (s < 1 || s > 4) throw std::invalid_argument("segmentColour: step_px must be 1..4");
	cv::Mat mask(bgr.rows / s, bgr.cols / s, CV_8UC1);
	if (mask.empty()) return mask;
	const FillPredicate pred = makePredicate(p);
	// Dispatch to a loop specialised for the step, so the block sums unroll.
	switch (s * 2 + (p.box_smoothing ? 1 : 0))
	{
		case 2:
		case 3:
			segmentGrid<1, false>(bgr, mask, pred, 0);
			break;
		case 4:
			segmentGrid<2, false>(bgr, mask, pred, segmentStep2Simd(bgr, mask, pred, path));
			break;
		case 5:
			segmentGrid<2, true>(bgr, mask, pred, 0);
			break;
		case 6:
			segmentGrid<3, false>(bgr, mask, pred, 0);
			break;
		case 7:
			segmentGrid<3, true>(bgr, mask, pred, 0);
			break;
		case 8:
			segmentGrid<4, false>(bgr, mask, pred, 0);
			break;
		default:
			segmentGrid<4, true>(bgr, mask, pred, 0);
			break;
	}
	return mask;
}

namespace
{
/** A horizontal run of mask cells [x0, x1) in row y. */
struct Run
{
	int y, x0, x1;
	int parent;	 // union-find
};

int findRoot(std::vector<Run>& runs, int i)
{
	while (runs[i].parent != i)
	{
		runs[i].parent = runs[runs[i].parent].parent;  // path halving
		i = runs[i].parent;
	}
	return i;
}

struct Moments
{
	double m0 = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, sg = 0;
	int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;  // inclusive bbox
};

/** Along a ray of \a n pixels from (x, y) in direction (dx, dy): the darkest
 * G (the frame) and the brightest G beyond it (the sheet, or whatever lies
 * next to the frame); dark < 0 when the ray leaves the image at once. */
struct RayLevels
{
	int dark = -1, beyond = -1;
};
RayLevels darkestAlong(const cv::Mat& bgr, int x, int y, int dx, int dy, int n)
{
	RayLevels r;
	for (int i = 0; i < n; ++i, x += dx, y += dy)
	{
		if (x < 0 || y < 0 || x >= bgr.cols || y >= bgr.rows) break;
		const int g = bgr.ptr<uint8_t>(y)[3 * x + 1];
		if (r.dark < 0 || g < r.dark)
		{
			r.dark = g;
			r.beyond = g;
		}
		r.beyond = std::max(r.beyond, g);
	}
	return r;
}

bool frameEvidence(
	const cv::Mat& bgr, const Candidate& c, int step, double frame_rel, const ComponentParams& p)
{
	if (p.max_frame_ratio >= 1) return true;
	std::array<double, 4> side{};
	const int x0 = c.bbox.x, y0 = c.bbox.y, x1 = c.bbox.x + c.bbox.width - 1,
			  y1 = c.bbox.y + c.bbox.height - 1;
	// Rays start a grid step inside the box (its sides are a step coarse) and
	// reach a frame width (1/8 of the side) plus margins beyond it.
	const int nx = step + 3 + c.bbox.width / 6, ny = step + 3 + c.bbox.height / 6;
	// The frame's width across the top and bottom sides, and across the left
	// and right ones.
	const double share_tb = frameNeighbourShare(frame_rel * c.bbox.height, p.frame_blur_px),
				 share_lr = frameNeighbourShare(frame_rel * c.bbox.width, p.frame_blur_px);
	for (int k = 0; k < 4; ++k)
	{
		std::array<double, 3> m{};
		for (int j = 0; j < 3; ++j)
		{
			const double t = 0.25 * (j + 1);
			const int xm = x0 + static_cast<int>(t * (x1 - x0)),
					  ym = y0 + static_cast<int>(t * (y1 - y0));
			RayLevels r;
			switch (k)
			{
				case 0:
					r = darkestAlong(bgr, xm, y0 + step, 0, -1, ny);
					break;	// top
				case 1:
					r = darkestAlong(bgr, x1 - step, ym, 1, 0, nx);
					break;	// right
				case 2:
					r = darkestAlong(bgr, xm, y1 - step, 0, 1, ny);
					break;	// bottom
				default:
					r = darkestAlong(bgr, x0 + step, ym, -1, 0, nx);
					break;	// left
			}
			if (r.dark < 0) return false;
			m[j] = unblurredFrameLevel(r.dark, c.fill_g, r.beyond, k % 2 ? share_lr : share_tb);
		}
		std::sort(m.begin(), m.end());
		side[k] = m[1];
	}
	std::array<double, 4> sorted = side;
	std::sort(sorted.begin(), sorted.end());
	if (0.5 * (sorted[0] + sorted[1]) > p.max_frame_ratio * c.fill_g) return false;
	return sorted[3] <= p.max_side_frame_ratio * c.fill_g;
}

bool centreEvidence(
	const cv::Mat& mask, const Candidate& c, int step, double cell_rel, const ComponentParams& p)
{
	// The smallest the centre cell can be for this box: the box of a square
	// turned 45 deg in the image is sqrt(2) times its side.
	const double extent = std::min(c.bbox.width, c.bbox.height);
	if (p.min_centre_cell_px <= 0 || cell_rel * extent / std::sqrt(2.0) < p.min_centre_cell_px)
		return true;
	// The box's centre lies within the centre cell: perspective moves it off
	// the square's centre by a s / (2 Z) of the width (a: half side, s: sine
	// of the angle, Z: distance; 7% at 0.5 m and 60 deg), less than half a
	// cell (9.4%).
	const double cx = c.bbox.x + 0.5 * c.bbox.width, cy = c.bbox.y + 0.5 * c.bbox.height;
	const double rx = 0.5 * cell_rel * c.bbox.width, ry = 0.5 * cell_rel * c.bbox.height;
	const int x0 = std::max(0, static_cast<int>(std::floor((cx - rx) / step)));
	const int x1 = std::min(mask.cols - 1, static_cast<int>(std::floor((cx + rx) / step)));
	const int y0 = std::max(0, static_cast<int>(std::floor((cy - ry) / step)));
	const int y1 = std::min(mask.rows - 1, static_cast<int>(std::floor((cy + ry) / step)));
	for (int y = y0; y <= y1; ++y)
	{
		const uint8_t* m = mask.ptr<uint8_t>(y);
		for (int x = x0; x <= x1; ++x)
			if (!m[x]) return true;
	}
	return false;
}

inline double sumSquares(double k) { return k * (k + 1) * (2 * k + 1) / 6; }  // 0^2 + ... + k^2
}  // namespace

std::vector<Candidate> findCandidates(
	const cv::Mat& mask, int step, const cv::Mat& bgr, const ComponentParams& p,
	cv::Mat* labels_out, int* num_components, double centre_cell_rel, double frame_rel)
{
	// N4-connected components by runs and union-find, hand-written because
	// the moments up to second order then come per run in closed form, and a
	// mostly empty mask costs one word-wise scan (cv::connectedComponentsWithStats
	// gives no second moments and labels every cell).
	std::vector<Candidate> out;
	std::vector<Run> runs;
	runs.reserve(1024);
	size_t prev_begin = 0, prev_end = 0;
	for (int y = 0; y < mask.rows; ++y)
	{
		const uint8_t* m = mask.ptr<uint8_t>(y);
		const size_t cur_begin = runs.size();
		int x = 0;
		while (x < mask.cols)
		{
			x = firstByteFrom(m, x, mask.cols, false);
			if (x >= mask.cols) break;
			const int x0 = x;
			x = firstByteFrom(m, x, mask.cols, true);
			runs.push_back({y, x0, x, static_cast<int>(runs.size())});
		}
		// Union with overlapping runs of the previous row (N4: shared columns).
		size_t j = prev_begin;
		for (size_t i = cur_begin; i < runs.size(); ++i)
		{
			while (j < prev_end && runs[j].x1 <= runs[i].x0) ++j;
			for (size_t k = j; k < prev_end && runs[k].x0 < runs[i].x1; ++k)
			{
				const int a = findRoot(runs, static_cast<int>(i)),
						  b = findRoot(runs, static_cast<int>(k));
				if (a != b) runs[std::max(a, b)].parent = std::min(a, b);
			}
		}
		prev_begin = cur_begin;
		prev_end = runs.size();
	}
	// Moments per component.
	std::vector<int> comp_of_root(runs.size(), -1);
	std::vector<Moments> comps;
	std::vector<int> run_comp(runs.size());
	for (size_t i = 0; i < runs.size(); ++i)
	{
		const int r = findRoot(runs, static_cast<int>(i));
		if (comp_of_root[r] < 0)
		{
			comp_of_root[r] = static_cast<int>(comps.size());
			comps.emplace_back();
		}
		run_comp[i] = comp_of_root[r];
		Moments& mo = comps[comp_of_root[r]];
		const Run& u = runs[i];
		const double n = u.x1 - u.x0, y = u.y;
		const double sx = n * (u.x0 + u.x1 - 1) / 2;
		mo.m0 += n;
		mo.sx += sx;
		mo.sy += n * y;
		mo.sxx += sumSquares(u.x1 - 1) - sumSquares(u.x0 - 1);
		mo.sxy += sx * y;
		mo.syy += n * y * y;
		mo.x0 = std::min(mo.x0, u.x0);
		mo.x1 = std::max(mo.x1, u.x1 - 1);
		mo.y0 = std::min(mo.y0, u.y);
		mo.y1 = std::max(mo.y1, u.y);
	}
	if (num_components) *num_components = static_cast<int>(comps.size());
	if (labels_out)
	{
		*labels_out = cv::Mat::zeros(mask.size(), CV_32S);
		for (size_t i = 0; i < runs.size(); ++i)
			labels_out->row(runs[i].y).colRange(runs[i].x0, runs[i].x1).setTo(run_comp[i] + 1);
	}
	const double cell_area = double(step) * step;
	const double max_area = p.max_area_fraction * double(bgr.rows) * bgr.cols;
	std::vector<char> keep(comps.size(), 0);
	for (size_t l = 0; l < comps.size(); ++l)
	{
		const Moments& mo = comps[l];
		const double area = mo.m0 * cell_area;
		if (area < p.min_area_px || area > max_area) continue;
		const double m0 = mo.m0, mx = mo.sx / m0, my = mo.sy / m0;
		// Central moments per unit mass, with the 1/12 of each unit cell (a
		// cell is a square, not a point).
		const double mu20 = mo.sxx / m0 - mx * mx + 1.0 / 12,
					 mu02 = mo.syy / m0 - my * my + 1.0 / 12;
		const double mu11 = mo.sxy / m0 - mx * my;
		Candidate c;
		c.label = static_cast<int>(l) + 1;
		c.compactness = (mu20 + mu02) / m0;	 // (mu20 + mu02) / m00^2 for raw sums
		const double tr = mu20 + mu02, det = mu20 * mu02 - mu11 * mu11;
		const double disc = std::sqrt(std::max(0.0, tr * tr / 4 - det));
		const double l1 = tr / 2 + disc, l2 = std::max(tr / 2 - disc, 1e-9);
		c.elongation = std::sqrt(l1 / l2);
		if (c.compactness > p.max_compactness || c.elongation > p.max_elongation) continue;
		c.area_px = area;
		c.bbox = cv::Rect(
			mo.x0 * step, mo.y0 * step, (mo.x1 - mo.x0 + 1) * step, (mo.y1 - mo.y0 + 1) * step);
		c.centroid = {mx * step + 0.5 * (step - 1), my * step + 0.5 * (step - 1)};
		const int gx =
			static_cast<int>(std::ceil(p.roi_grow_fraction * c.bbox.width)) + p.roi_grow_px;
		const int gy =
			static_cast<int>(std::ceil(p.roi_grow_fraction * c.bbox.height)) + p.roi_grow_px;
		c.roi =
			cv::Rect(c.bbox.x - gx, c.bbox.y - gy, c.bbox.width + 2 * gx, c.bbox.height + 2 * gy) &
			cv::Rect(0, 0, bgr.cols, bgr.rows);
		// The code's centre cell: a hole in the fill near the box's centre.
		// It reads the mask only, so it comes before the fill's mean G (a
		// pass over every cell of the component in the image) and spares it
		// to the green shapes without one (posters, shapes on a wall).
		if (!centreEvidence(mask, c, step, centre_cell_rel, p)) continue;
		out.push_back(c);
		keep[l] = 1;
	}
	// Mean G of each survivor's fill (for the gradient threshold).
	if (!out.empty())
	{
		std::vector<double> sg(comps.size(), 0);
		for (size_t i = 0; i < runs.size(); ++i)
		{
			if (!keep[run_comp[i]]) continue;
			const uint8_t* px = bgr.ptr<uint8_t>(runs[i].y * step) + 1;
			// An integer sum per run (exact, and kept in a register).
			int run_sum = 0;
			for (int x = runs[i].x0; x < runs[i].x1; ++x) run_sum += px[3 * x * step];
			sg[run_comp[i]] += run_sum;
		}
		for (auto& c : out) c.fill_g = sg[c.label - 1] / comps[c.label - 1].m0;
		// Frame evidence: a landmark's fill is surrounded by the dark frame.
		// Along short rays outwards from each side of the bounding box, the
		// darkest G must be dark: cheap, and it spares the later stages most
		// green things of a scene.
		out.erase(
			std::remove_if(
				out.begin(), out.end(),
				[&](const Candidate& c) { return !frameEvidence(bgr, c, step, frame_rel, p); }),
			out.end());
	}
	std::sort(
		out.begin(), out.end(),
		[](const Candidate& a, const Candidate& b) { return a.area_px > b.area_px; });
	if (static_cast<int>(out.size()) > p.max_candidates) out.resize(p.max_candidates);
	return out;
}

}  // namespace codemark::detect
