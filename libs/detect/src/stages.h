#pragma once
/** \file stages.h
 * Internal: one function per stage of the detector (docs/design.md, "The
 * recognition"), declared here so that tests can run a single stage on a
 * crafted input. detect() in detector.cpp calls them in this order.
 */
#include <codemark/detect/detector.h>
#include <codemark/detect/options.h>
#include <codemark/landmark/camera.h>
#include <codemark/landmark/codebook.h>
#include <codemark/landmark/geometry.h>

#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

namespace codemark::detect
{
// ---------------------------------------------------------------- stage 1+2
/** Smoothing and colour segmentation: a CV_8UC1 mask (255 = green fill) of
 * floor(rows / step) x floor(cols / step) cells; cell (i, j) stands for the
 * step x step block with top-left pixel (j*step, i*step). Empty for an image
 * smaller than one block. \a bgr must be CV_8UC3. */
/** Which code computes the step-2 mask: the widest SIMD the CPU runs, the
 * baseline's (SSE2 on x86-64), or scalar code only (for tests: all three
 * must give the same mask). */
enum class SimdPath
{
	Best,
	Baseline,
	Scalar
};
cv::Mat segmentColour(
	const cv::Mat& bgr, const SegmentationParams& p, SimdPath path = SimdPath::Best);

/** The segmentation predicate on one (smoothed) colour [0..255 each]. */
bool isFillColour(double r, double g, double b, const SegmentationParams& p);

// ------------------------------------------------------------------ stage 3
/** A connected component of the mask that passed the area and shape tests:
 * one candidate green fill. Coordinates in full-image pixels. */
struct Candidate
{
	int label = 0;	//!< label in the components image
	cv::Rect bbox;	//!< bounding box of the component's blocks [px]
	cv::Rect roi;  //!< bbox grown to include the black frame, clipped [px]
	Eigen::Vector2d centroid = Eigen::Vector2d::Zero();	 //!< [px]
	double area_px = 0;	 //!< number of blocks x step^2 [px^2]
	double compactness = 0;	 //!< eta20 + eta02 (Hu's first invariant)
	double elongation = 0;	//!< ratio of principal standard deviations
	double fill_g = 0;	//!< mean G of the component's blocks [grey levels]
};

/** N4-connected components of \a mask (from segmentColour with grid step
 * \a step), filtered by cardinality and compactness, largest first. The
 * labels image is returned through \a labels and the number of components
 * (before filtering) through \a num_components when given. \a centre_cell_rel
 * is the code cell's size over the reference square's side (the centre
 * evidence test, ComponentParams::min_centre_cell_px). */
std::vector<Candidate> findCandidates(
	const cv::Mat& mask, int step, const cv::Mat& bgr, const ComponentParams& p,
	cv::Mat* labels = nullptr, int* num_components = nullptr, double centre_cell_rel = 30.0 / 160,
	double frame_rel = 20.0 / 160);

/** The black frame's darkness, whatever its width in pixels. A frame of
 * width \a width_px between two brighter neighbours reads lighter than its
 * ink: a blur of \a blur_px (Gaussian sigma) spreads each neighbour over it.
 * At an offset x from the frame's middle, each neighbour contributes the
 * share Phi(-(w/2 + x) / sigma) and Phi(-(w/2 - x) / sigma) of its level.
 * frameNeighbourShare() is that share averaged over the offsets
 * \a half_band x w x {-1, -1/2, 0, 1/2, 1} (the frame's samples; 0: its
 * middle alone); 0 for a frame under two blur widths, whose depth depends
 * on the actual blur more than on its ink.
 * unblurredFrameLevel() undoes it: the ink's level from the level
 * \a measured between neighbours \a inner and \a outer. */
double frameNeighbourShare(double width_px, double blur_px, double half_band = 0);
inline double unblurredFrameLevel(double measured, double inner, double outer, double share)
{
	return (measured - share * (inner + outer)) / (1 - 2 * share);
}

// ------------------------------------------------------------------ stage 4
/** Polarity of an edgel, named after the inner frame edge that has it: the
 * gradient of G points into the green fill. */
enum class Polarity : uint8_t
{
	None = 0,
	Top = 1,  //!< G rises downwards (+v): the top inner edge
	Right = 2,	//!< G falls rightwards (-u): the right inner edge
	Bottom = 3,	 //!< G falls downwards (-v): the bottom inner edge
	Left = 4  //!< G rises rightwards (+u): the left inner edge
};

/** An 8-connected set of edgels of one polarity. */
struct EdgelDomain
{
	Polarity polarity = Polarity::None;
	int count = 0;	//!< number of edgels
	Eigen::Vector2d mean = Eigen::Vector2d::Zero();	 //!< centroid [px]
	Eigen::Vector2d dir = Eigen::Vector2d::UnitX();	 //!< principal direction (unit)
	double length_px = 0;  //!< extent along dir (max - min projection) [px]
	double width_px = 0;  //!< sqrt of the smaller eigenvalue (slimness) [px]
	/** Size of a pixel of the gradient image the domain was found in [px]
	 * (EdgelMap::scale): a straight edge's edgels there form a staircase
	 * whose width is a fraction of that pixel. */
	double pixel_px = 1;
	Eigen::Vector2d end0 = Eigen::Vector2d::Zero(),
					end1 = Eigen::Vector2d::Zero();	 //!< extreme edgels along dir
};

/** Edgels of one ROI. */
struct EdgelMap
{
	cv::Rect roi;  //!< in full-image pixels
	int scale = 1;	//!< reduction factor of the gradient image (large ROIs)
	cv::Mat polarity;  //!< CV_8UC1 of roi size / scale, Polarity values
	std::vector<EdgelDomain> domains;  //!< with at least min_edgels edgels
	double threshold = 0;  //!< gradient threshold used [grey levels / px]
};

/** Gradient threshold for a candidate whose fill has mean G \a fill_g. */
double gradientThreshold(double fill_g, const EdgelParams& p);

/** G of \a roi (within \a bgr, its size a multiple of \a k >= 2) reduced
 * by \a k: each k x k block's mean rounded half up (cv::resize(INTER_AREA)
 * gives it to a grey level: it rounds some ties down). Written by hand:
 * cv::extractChannel and then cv::resize read and wrote the ROI twice, a
 * third of the edgel stage on near landmarks. */
cv::Mat reducedGreen(const cv::Mat& bgr, const cv::Rect& roi, int k);

/** Gradients of G (3x3 Sobel) in \a roi, non-maximum suppressed edgels
 * with polarity, grouped into domains. At full resolution unless the ROI is
 * larger than max_roi_px, then reduced by an integer factor (domains are
 * still given in full-image pixels). */
EdgelMap findEdgels(
	const cv::Mat& bgr, const cv::Rect& roi, double threshold, const EdgelParams& p);

// ------------------------------------------------------------------ stage 5
/** The four inner-edge segments in the order top, right, bottom, left. */
using SideSegments = std::array<EdgelDomain, 4>;

/** Picks, for each side, the domain of that polarity on that side of the
 * fill's centroid, long and slim enough, with the fill colour just inside
 * it in \a mask (grid step \a step; an empty mask skips that test),
 * nearest the fill's bounding box side. With \a bgr given, the fill must
 * also be seen in the image right inside the domain (G at least half the
 * fill's, above R and B, and at least half of \a colour's saturation floor:
 * a grey wall with a tint of green is not the fill), 1.5 px plus half a
 * gradient-image pixel inwards:
 * the grid mask is coarser, and the sheet's edge against a darker wall lies
 * only a thin frame (1.6-3.2 px at 5 m) outside the inner edge.
 * \a fill_band_rel is the green band between the inner edge and the code
 * board over the reference square's side ((160 - 90) / 2 / 160 for the
 * spec's landmark): the mask test looks no deeper than about half of it, so
 * that a small or oblique landmark's black code cells next to the band do
 * not hide the fill. */
std::optional<SideSegments> selectSegments(
	const std::vector<EdgelDomain>& domains, const Candidate& c, const cv::Mat& mask, int step,
	const SegmentParams& p, const cv::Mat* bgr = nullptr, double fill_band_rel = 35.0 / 160,
	const SegmentationParams& colour = SegmentationParams());

// ------------------------------------------------------------------ stage 6
/** Coarse corners TL, TR, BR, BL [raw px]. */
using Quad = std::array<Eigen::Vector2d, 4>;

/** Intersects neighbouring segments' lines; fails unless every segment end
 * lies near its corner and the quadrangle is convex, in image order, with
 * sides of at least min_side_px. */
std::optional<Quad> linkQuadrangle(const SideSegments& s, const QuadParams& p);

// ------------------------------------------------------------------ stage 7
/** Switches for the sub-pixel stage's models and its gate, for the tests
 * and benchmarks that measure what each one does. Not detector options: the
 * detector runs them all. */
struct SubpixelModels
{
	/** Stage 6b: refuse a linked quadrangle whose centre cell reads green
	 * before its sub-pixel work (centreMayBeBlack()). */
	bool centre_gate = true;
	/** Restore clipped G samples before the edges are read (imputeFillLevel(),
	 * imputeClippedSide()). */
	bool clipping = true;
	/** Remove the frame's outer edge's lobe in the Peak locator. */
	bool outer_edge = true;
	/** Shift thin sides by their print model's offset (thinFrameOffset()). */
	bool thin_frame = true;
	/** Stage 7b: centreOnBand(). */
	bool band_midline = true;
	/** The Peak locator's step model (EdgeMode::Peak rather than
	 * EdgeMode::PeakGaussian). */
	bool step_peak = true;
	/** correctLevelRounding() on noise-free sharp sides. */
	bool level_rounding = true;
	/** Read the sides the centroid places, and their bands, in luma where
	 * luma's edges are the sharper (lumaIsSharper()); false: all in G. */
	bool luma_edges = true;
};

/** The median of \a x (reordered; not empty). */
double medianOf(std::vector<double>& x);

/** The mean of the middle half of \a x (reordered; not empty): the
 * interquartile mean. Where a sample falls into populations, as a side's
 * profiles do under a camera's processing (a Bayer mosaic's rows
 * alternate, JPEG's blocks repeat every 8 pixels), the median of a
 * noise-free sample lies on one of them and the midmean between them;
 * like the median it ignores the wildest quarter either side. */
double midmeanOf(std::vector<double>& x);

/** A sample's median and its standard error. */
struct MedianWithError
{
	double median = 0, se = 0;
};
/** The median of \a x (not empty) and its standard error as a normal
 * sample's (1.4826 median absolute deviations x sqrt(pi / 2 / n)): robust
 * to the few wild profiles of a noisy side. */
MedianWithError medianWithError(std::vector<double> x);

/** The channel an edge is read in. */
enum class EdgeChannel
{
	Green,
	/** lumaLevel(): free of the chroma planes. */
	Luma
};

/** BT.601 luma of a BGR pixel scaled to G's weight (Y / 0.587, rounded),
 * so that on a pure green fill it reads G's levels and the gradient
 * thresholds keep their meaning; up to 434 on white. Luma is the one
 * combination of the decoded channels free of the chroma planes: a
 * camera's chroma subsampling (4:2:2, 4:2:0) and JPEG's coarser chroma
 * reach a colour edge's G through them (decoded G = Y - 0.344 Cb - 0.714
 * Cr carries about 41% of a green fill's step against black at the
 * chroma's resolution), and so does a Bayer mosaic's interpolated colour. */
inline int lumaLevel(const uint8_t* bgr)
{
	return (114 * bgr[0] + 587 * bgr[1] + 299 * bgr[2] + 293) / 587;
}

/** The first index in [\a x, \a end) of \a row whose byte is non-zero
 * (\a end if none), or, with \a zero, whose byte is zero: eight bytes at
 * a time (the masks and maps the detector scans are mostly empty, and
 * their runs long). In a word w, the lowest byte flagged by
 * (w - 0x01..01) & ~w & 0x80..80 is its first zero byte (a borrow only
 * flags bytes above a zero one), and the lowest set bit of w lies in its
 * first non-zero byte: on a little-endian machine the trailing zero bits
 * over eight give the byte's index. */
inline int firstByteFrom(const uint8_t* row, int x, int end, bool zero)
{
	constexpr uint64_t kOnes = 0x0101010101010101ull, kHighs = 0x8080808080808080ull;
	for (; x + 8 <= end; x += 8)
	{
		uint64_t w;
		std::memcpy(&w, row + x, 8);
		const uint64_t hit = zero ? (w - kOnes) & ~w & kHighs : w;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
		if (hit != 0) return x + (__builtin_ctzll(hit) >> 3);
#else
		if (hit != 0) break;
#endif
	}
	while (x < end && (row[x] == 0) != zero) ++x;
	return x;
}

/** How locateRisingEdge() places the edge. */
enum class EdgeMode
{
	Centroid,  //!< centroid of the derivative response around its peak
	IsolatedCentroid,  //!< the same, stopping where the response rises again (a neighbouring edge)
	/** The derivative's peak: the pixel-integrated Gaussian step whose
	 * response fits the three samples around it exactly. */
	Peak,
	/** The same peak from a Gaussian through the three samples (a
	 * log-parabola): errs with the edge's phase in its pixel on sharp
	 * edges, but needs no blur to centre a search. */
	PeakGaussian
};

/** A Gaussian-blurred unit step (blur \a sigma [px]) at 0, averaged over
 * the pixel [x - 1/2, x + 1/2] that samples it, and its derivatives with
 * respect to x and sigma: the profile a camera's pixels take of an edge
 * under a Gaussian point-spread function (an erf of a wider sigma misfits
 * the steep part by about 1% of the step). */
struct PixelStep
{
	double value, d_x, d_sigma;
};
PixelStep pixelStep(double x, double sigma);
/** pixelStep() at x0, x0 + 1, ..., x0 + count - 1 into \a out, sharing the
 * pixels' common boundaries (count + 1 evaluations of the normal's CDF
 * and density instead of 2 count). */
void pixelSteps(double x0, double sigma, int count, PixelStep* out);
/** pixelStep() at each of \a count positions \a x (one blur), into \a out. */
void pixelStepsAt(const double* x, int count, double sigma, PixelStep* out);

/** The index in lo..hi (1 <= lo, hi <= n - 2) of the largest central
 * difference v[i + 1] - v[i - 1], the first of equals: an edge's steepest
 * rise. */
int steepestRise(const int* v, int lo, int hi);

/** Sub-pixel position of a step edge on a 1D profile, from the derivative
 * (values[k+1] - values[k-1]) around its largest value within [lo, hi]
 * (indices), the edge rising in the direction of increasing index. Nullopt
 * when the peak derivative is below \a min_rise (grey levels per px). In
 * Peak mode with \a neighbour_px > 0, the lobe of a falling edge that far
 * before this one (a thin frame's outer edge) is modelled and removed; with
 * \a neighbour_px < 0, that of one -neighbour_px after it (the quiet
 * margin's edge, read from the frame outwards). */
std::optional<double> locateRisingEdge(
	const int* values, int n, int lo, int hi, double min_rise, const SubpixelParams& p,
	EdgeMode mode = EdgeMode::Centroid, double neighbour_px = 0);

/** A noise-free side's edges corrected for the rounding of its levels.
 * Where the sensor is quiet and the edge sharp, each profile holds one
 * mixed sample v between the frame's level L and the fill's H, and the
 * edge sits at its pixel's boundary less f = (v - L) / (H - L). L and H
 * are rounded once for the whole side (a fill rendered or lit at 229.5
 * reads 230 in every profile), so the contrast's rounding c (within +-1
 * level) moves each edge by f c / (H - L): a sawtooth along a side whose
 * edge crosses a pixel boundary, which tilts its line (0.0045 px across a
 * side at 2 m: 1.2e-3 rad of phi2). This fits c with the side's line
 * (least squares, each mixed sample's own rounding the noise, c's prior,
 * the difference of two roundings, a Gaussian of variance 1/6), and sets
 * each such profile's edge in \a edges [profile index] to the pixel's
 * boundary less f (1 - c / (H - L)): the exact reading of a sharp edge,
 * which the three-sample step fit approaches to 0.001 px only. Profile
 * j's across coordinate is \a origin[j] + \a inward x (edge - \a half),
 * along \a along[j]. Applies only where at least 10 profiles and 80% of those
 * with an edge are sharp (L twice before the mixed sample, H twice after)
 * with one L and one H at least 20 levels apart: noise breaks that
 * pattern, and there each profile's rounding is its own. Returns c [grey
 * levels] or nullopt (edges unchanged). Written by hand: the model is
 * this detector's. */
std::optional<double> correctLevelRounding(
	const std::vector<int>& g_profiles, int n, const std::vector<int>& along,
	const std::vector<int>& origin, int half, int inward,
	std::vector<std::optional<double>>& edges);

/** The mean offset [px] of a thin frame's inner edges from where the
 * peak model put them (\a edges, profile index; \a g_profiles of \a n
 * samples each): the side's profiles, aligned on those edges, fitted
 * together (least squares, 0.25 px bins) with a model of the print across
 * the side, wall | quiet margin | black frame | fill: levels W, M, K, G,
 * one Gaussian blur, the frame's width (started at \a frame_px) and the
 * margin's, and the inner edge's offset. The peak model knows the frame's
 * outer edge but not the margin's: on a margin under a pixel (the spec's
 * 5 mm beyond 3 m or at 60 deg) the wall's edge to it cancels part of the
 * outer edge's lobe, and the peak's edges lie 0.05-0.1 px inwards on 2-3
 * px frames. Nullopt without convergence, with under 8 edges, or where
 * the offset would exceed half a pixel. Written by hand: one small fit per
 * thin side, where cv::LMSolver's set-up would cost more. */
std::optional<double> thinFrameOffset(
	const std::vector<int>& g_profiles, int n, const std::vector<std::optional<double>>& edges,
	double frame_px, double fixed_sigma = 0, double* sigma_out = nullptr);

/** The profiles of one side, for imputeClippedSide(): sample i of profile
 * j lies at across coordinate base[j] + inward * i (i grows into the fill)
 * and along coordinate along[j] of \a image (rows: along is the row,
 * across the column; otherwise the reverse). */
struct ClippedSideProfiles
{
	const cv::Mat* image = nullptr;	 //!< CV_8UC3, BGR
	bool rows = true;
	int n = 0;	//!< samples per profile
	int inward = 1;	 //!< +1 or -1
	std::vector<int> along;	 //!< per profile [px]
	std::vector<int> base;	//!< per profile [px]
	/** Channel c (0 B, 1 G, 2 R) of sample i of profile j. */
	int sample(int j, int i, int c) const
	{
		const int a = base[j] + inward * i;
		return rows ? image->ptr<uint8_t>(along[j])[3 * a + c]
					: image->ptr<uint8_t>(a)[3 * along[j] + c];
	}
};

/** Restores the G profiles of a side whose green fill clips at the
 * sensor's top, so that the usual edge estimators can read them. The clip
 * cuts the bright half of the edge's response, which moves the derivative's
 * peak and centroid outwards (the square looks larger): by 0.012 px where
 * only the noise of a fill at exactly 255 clips, 0.05 px at gains of
 * 1.1-1.6 within 2 m and up to 0.5 px on 4-5 px frames.
 * Where part of the fill band is unclipped, imputeFillLevel() does it
 * before the edges are first located. Where all of it clips: a Gaussian-blurred, pixel-integrated
 * step (with the frame's outer edge below 7 px) in B, G and R, the side's blur and levels shared
 * and the edge a quadratic along the side, is fitted by maximum likelihood with the samples at 255
 * or 0 censored (Tobit); G's fill level comes from the unclipped channels' ratio; each clipped G
 * sample on the fill side (and outside a thin frame) gets its expectation under that model and the
 * clip. About 0.5 ms a side. \a initial: each profile's edge estimate [profile index] (nullopt:
 * none); \a frame_px, \a fill_px: the black frame's and the green band's widths across the side
 * [px]; \a noise: the sensor's noise in G [grey levels] (centreCellNoise(); 0: unknown); \a
 * g_profiles: side.along.size() x side.n G samples, modified in place. Returns false, leaving them
 * as they were, when the side has too few edge points or fill samples, its frame is under 3.5 px,
 * the fit does not converge near them, the edge is too sharp (one mixed sample a profile) to say
 * where a clipped edge lies, or the fit explains the samples worse than the noise (JPEG chroma). */
bool imputeClippedSide(
	const ClippedSideProfiles& side, const std::vector<std::optional<double>>& initial,
	double frame_px, double fill_px, double noise, std::vector<int>& g_profiles);

/** The G samples of a side's fill band (profile indices i0..i1 of each
 * profile): how many are at the sensor's top, how many below. */
struct ClippedFill
{
	int clipped = 0;  //!< samples at 255
	int unclipped = 0;	//!< the others
	std::array<int, 255> histogram{};  //!< of the others' values
	int count() const { return clipped + unclipped; }
	double fraction() const { return count() > 0 ? double(clipped) / count() : 0; }
};
ClippedFill clippedFill(const std::vector<int>& g_profiles, int n, int i0, int i1);

/** The G level of a side's fill band where part of it is unclipped: linear
 * along and across the side (a light gradient), beta . (1, along, across)
 * with both coordinates normalised to [-1, 1] over the band's profiles and
 * sample indices i0..i1, and the noise sigma [grey levels]. */
struct FillLevel
{
	Eigen::Vector3d beta = Eigen::Vector3d::Zero();
	double sigma = 0;
	int profiles = 0, i0 = 0, i1 = 0;
	/** (1, along, across) of sample i of profile j (across clamped to the band). */
	Eigen::Vector3d design(int j, int i) const;
	/** The level lies above the clip by more than the noise and 2% somewhere
	 * in the band: its edges' transitions clip too (their top 2% and more),
	 * whose samples lie below the fill's level, imputeClippedSide()'s case.
	 * Less cuts too little of a transition to move an edge. */
	bool aboveClip() const;
};

/** The fill level of a band (profile indices i0..i1 of each \a n-sample
 * profile of \a g_profiles, \a fill their tally) where only part of it
 * clips. Flat where the clipped fraction is even over the band (or the
 * level's slopes stay under the noise): then from \a fill's median and
 * clipped fraction (a censored normal, robust to the band's few samples of
 * neighbouring blur); else by censored (Tobit) regression. Nullopt with
 * under 10 samples on either side of the clip, or without convergence. */
std::optional<FillLevel> fitFillLevel(
	const std::vector<int>& g_profiles, int n, int i0, int i1, const ClippedFill& fill);

/** G's fill level on a side whose fill band clips throughout, read from
 * the unclipped channels instead: across the inner edge, B + R falls from
 * the frame's level to the fill's in proportion to the share f of the
 * fill in each pixel, so each unclipped transition pixel gives G's step
 * through G - G_frame = (level - G_frame) f (least squares through the
 * origin over pixels with f in [0.05, 0.95] and G at most 250, clear of
 * the clip; the standard error counts the rounding of B + R, shared by
 * pixels of one level). \a g_profiles and \a rb_profiles (-(B + R)) hold n samples a
 * profile, the edge searched within lo..hi, the fill band i0..i1. Nullopt
 * where B + R has under 12 levels of contrast; with under 10 such pixels
 * (a sharp edge on a pixel boundary has none) the level is unknown: NaN,
 * with an infinite standard error. */
struct ChannelFillLevel
{
	double level = 0;  //!< G's fill level [grey levels], may exceed 255
	double se = 0;	//!< its standard error [grey levels]
	double rb_step = 0;	 //!< B + R's fall from the frame to the fill [grey levels]
	/** The largest error [px] that rounding gives an edge located in B + R
	 * (B and R rounded alike: half of two levels of their sum's step). */
	double rbRoundingPx() const { return rb_step > 0 ? 1.0 / rb_step : 0; }
	/** At the clip within two standard errors or 0.5% of it (a level 0.5%
	 * above the clip moves a sharp edge's G centroid by under 0.006 px), or
	 * unknown. */
	bool consistentWithTop() const;
	/** The same, conclusively: the standard error under 1% of the clip. */
	bool atTop() const;
};
std::optional<ChannelFillLevel> fillLevelFromChannels(
	const std::vector<int>& g_profiles, const std::vector<int>& rb_profiles, int n, int lo, int hi,
	int i0, int i1);

/** Every sample at 255 of \a g_profiles gets the expectation of a sample of
 * \a level above the clip at its place (only the fill's noise clips). */
void imputeFillLevel(std::vector<int>& g_profiles, int n, const FillLevel& level);

/** The noise of G [grey levels] in the always-black centre code cell of the
 * quadrangle \a coarse (around its diagonals' intersection, the projected
 * centre), \a cell_rel the cell's side over the reference square's: robust
 * spread of neighbouring pixels' differences (0 under about half a grey
 * level, where most differences are 0). Nullopt when the cell is under
 * 3 x 3 px in the image. */
std::optional<double> centreCellNoise(const cv::Mat& bgr, const Quad& q, double cell_rel);
/** A code cell's side over the inner square's (centreCellNoise()'s
 * cell_rel): the code board fills what the green band of \a fill_ratio
 * leaves, in three cells. */
inline double codeCellRatio(double fill_ratio) { return (1 - 2 * fill_ratio) / 3; }
/** The same cell's noise as the RMS of the neighbours' differences within 4
 * robust sigmas, over sqrt(2): not quantised to the grey levels as the
 * median is (DetectionQuality::image_noise_grey). Farther from the cell's
 * sides (3.5 px) and over at least 5 x 5 px; nullopt otherwise. */
std::optional<double> centreCellNoiseRms(const cv::Mat& bgr, const Quad& q, double cell_rel);
/** The noise of G [grey levels] in flat 8 x 8 px blocks of a window three
 * times the size of the quadrangle \a q around it (at least 64 px, within
 * the image; blocks with a clipped pixel left out): the mean over the
 * blocks without edge or texture of their horizontal differences' variance
 * about its mean, over 2. Nullopt under 8 such blocks. For a landmark whose
 * centre cell is too small for centreCellNoiseRms(). */
std::optional<double> surroundNoiseRms(const cv::Mat& bgr, const Quad& q);
/** DetectionQuality::image_noise_grey: centreCellNoiseRms() where the cell
 * is large enough, else surroundNoiseRms(); 0 when neither can tell. */
double landmarkNoiseRms(const cv::Mat& bgr, const Quad& q, double cell_rel);

/** A straight line n . x + c = 0 (|n| = 1) fitted by total least squares. */
struct LineFit
{
	Eigen::Vector2d normal = Eigen::Vector2d::UnitX();
	double c = 0;
	double rms_px = 0;	//!< RMS distance of the kept points [px]
	int support = 0;  //!< number of kept points
	std::vector<Eigen::Vector2d> points;  //!< all edge points given (debug)
};

/** The edge response the points of a line fit were read on: its median
 * slope across the profiles [grey levels per px] and the image axis the
 * profiles run along (0 u, 1 v). */
struct EdgeResponse
{
	double slope = 0;
	int across = 0;
};

/** TLS fit with iterative outlier rejection (robust sigma from the median
 * absolute residual). Nullopt with fewer than min_support points kept or an
 * RMS residual above SubpixelParams::max_rms_px, or, given the \a response
 * the points were read on, above the larger of that and
 * SubpixelParams::max_rms_grey over the response's slope along the line's
 * normal. */
std::optional<LineFit> fitLine(
	std::vector<Eigen::Vector2d> points, const SubpixelParams& p,
	const std::optional<EdgeResponse>& response = std::nullopt);

/** The refined quadrangle. */
struct RefinedQuad
{
	Quad corners_raw;  //!< TL, TR, BR, BL in raw (distorted) pixels
	Quad corners_ideal;	 //!< the same undistorted
	std::array<LineFit, 4> sides;  //!< top, right, bottom, left, in undistorted px
	/** Per side: its fill clipped throughout (DetectionQuality::fill_clipped). */
	std::array<bool, 4> fill_clipped{{false, false, false, false}};
	/** Per side: the channel its edges were read in. */
	std::array<EdgeChannel, 4> channel{
		{EdgeChannel::Green, EdgeChannel::Green, EdgeChannel::Green, EdgeChannel::Green}};
	/** The bands' bend (DetectionQuality::edge_bend_px) and its standard
	 * error [px]; 0 when not measured. */
	double bend_px = 0, bend_se_px = 0;
};

/** Edge profiles along each side of \a coarse (one per row or column), the
 * sub-pixel edge points undistorted, a line per side, corners from
 * neighbouring intersections distorted back to raw pixels. \a min_rise is
 * the smallest G slope of an edge [grey levels / px]; \a frame_ratio the
 * black frame's width over the inner side (0.125 for the spec's landmark),
 * \a fill_ratio the green band's between the inner edge and the code board
 * (35 / 160). */
std::optional<RefinedQuad> refineQuadrangle(
	const cv::Mat& bgr, const Quad& coarse, const CameraModel& camera, double min_rise,
	double frame_ratio, const SubpixelParams& p, double fill_ratio = 35.0 / 160,
	const SubpixelModels& models = {});

/** Corner k (TL, TR, BR, BL) of four sides' lines (top, right, bottom,
 * left): side k-1 x side k; nullopt where they are parallel. */
std::optional<Eigen::Vector2d> cornerOfSides(const std::array<LineFit, 4>& sides, int k);

/** Corners from the four sides' lines (ideal px), distorted back to raw
 * pixels; false where neighbouring sides are parallel. */
bool cornersFromSides(RefinedQuad& q, const CameraModel& camera);

/** Stage 7b: each side's line moved onto the inner edge that the green
 * band's midline gives (the band between the frame's inner edge and a
 * black code cell, or the centre cell behind a green middle cell: two
 * mirror-image edges of one ink and one fill, which a camera's response
 * moves alike), the median over the side's profiles; the corners follow.
 * Only where the bands' width differs from the printed one beyond its
 * scatter (a bend: a transfer curve, a clip, dot gain); otherwise \a q
 * stays as it is. \a fill_ratio: the band's width over the inner side.
 * A side read in luma (RefinedQuad::channel) reads its bands in luma where
 * the centroid reads them (a frame at least
 * SubpixelParams::min_frame_px_centroid wide). */
void centreOnBand(
	const cv::Mat& bgr, RefinedQuad& q, const CameraModel& camera, double min_rise,
	double frame_ratio, double fill_ratio, const SubpixelParams& p);

// ------------------------------------------------------------------ stage 8
/** The code of one landmark. */
struct CodeReading
{
	int id = -1;
	CodeCells cells{};	//!< true = black
	std::array<double, 9> cell_g{};	 //!< mean G of each cell, row by row
	double black_g = 0;	 //!< G of the black frame
	double green_g = 0;	 //!< G of the green fill
	double margin = 0;	//!< smallest |cell - threshold| [grey levels]
};

/** The reference square's corners TL, TR, BR, BL in normalised face
 * coordinates (s/h right, t/h up; the square is [-1, 1]^2). */
inline const std::array<Eigen::Vector2d, 4> kFaceCorners{
	Eigen::Vector2d(-1, 1), Eigen::Vector2d(1, 1), Eigen::Vector2d(1, -1), Eigen::Vector2d(-1, -1)};

/** Homography from normalised face coordinates to ideal pixels, from
 * corners TL, TR, BR, BL (kFaceCorners' images). */
Eigen::Matrix3d faceToImage(const Quad& corners_ideal);

/** Maps normalised face coordinates to raw pixels (ideal ones when not
 * \a distorted) through faceToImage()'s \a H. */
struct FaceMap
{
	Eigen::Matrix3d H;
	const CameraModel& cam;
	bool distorted;

	Eigen::Vector2d operator()(double x, double y) const
	{
		const Eigen::Vector3d q = H * Eigen::Vector3d(x, y, 1);
		Eigen::Vector2d ideal = q.head<2>() / q.z();
		if (!distorted) return ideal;
		return cam.distortNormalized(
			{(ideal.x() - cam.cx()) / cam.fx(), (ideal.y() - cam.cy()) / cam.fy()});
	}
	Eigen::Vector2d operator()(const Eigen::Vector2d& f) const { return (*this)(f.x(), f.y()); }
};

/** Mean G at a raw pixel position (bilinear); nullopt outside the image. */
std::optional<double> sampleG(const cv::Mat& bgr, double u, double v);

/** Outward normals of the reference square's sides top, right, bottom,
 * left in normalised face coordinates. */
inline constexpr double kSideNormals[4][2] = {{0, 1}, {1, 0}, {0, -1}, {-1, 0}};

/** What surrounds one side of the frame (\a side: top, right, bottom,
 * left): its width in pixels across the side's middle, the sheet's G
 * beyond it and the share of each neighbour that a blur of \a blur_px
 * spreads over the frame's middle half (frameNeighbourShare(); 0 when the
 * sheet lies outside the image). */
struct FrameSurround
{
	double width_px = 0, sheet_g = 0, share = 0;
	/** The frame's ink from the level \a frame_g read over its middle half
	 * next to the fill's \a fill_g. */
	double ink(double frame_g, double fill_g) const
	{
		return unblurredFrameLevel(frame_g, fill_g, sheet_g, share);
	}
};
FrameSurround frameSurround(
	const cv::Mat& bgr, const FaceMap& map, const LandmarkGeometry& geo, int side, double blur_px);

/** What each patch of readCode() reads of each part of the code board
 * under a blur: rows 0-8 the cells' patches (row by row), rows 9-12 the
 * green ring's patches along the top, right, bottom and left sides (each
 * side's three averaged); columns 0-8 the cells, column 9 the ring between
 * the board and the frame (the frame is black, the sheet beyond it out of
 * reach). */
using BoardShares = Eigen::Matrix<double, 13, 10>;

/** The patches' mean shares of each part of the board (BoardShares) under
 * a Gaussian blur of \a sigma_px [px, raw image], mapped into face
 * coordinates through the local Jacobian of \a map at each patch (its
 * skew ignored). */
BoardShares blurredCellShares(
	const FaceMap& map, const LandmarkGeometry& geo, double patch_fraction, double sigma_px);

/** The cells read through the blur, where a thin or distant code board's
 * cells blur into their neighbours (readCellsThroughBlur()). */
struct BlurredCells
{
	CodeCells cells{};	//!< true = black
	/** Smallest distance of the cell means to a decision boundary between
	 * the code read and another [grey levels]; with no blur, the thresholded
	 * read's margin. */
	double margin = 0;
};

/** Reads the cells by comparing the cells' mean G (\a cell_g, row by row)
 * and the ring's (\a ring_g, top, right, bottom, left) with every code's
 * under a Gaussian blur of \a sigma_px (blurredCellShares(); black and
 * green levels fitted by least squares): the code with the least squared
 * residual wins. nullopt unless the black level is neither lighter than the
 * frame's G (\a frame_g) nor darker than the frame's ink (\a frame_ink,
 * the blur's share of fill and sheet removed) by more than \a min_margin
 * of the contrast, each patch lies within (0.5 - \a min_margin) of the
 * contrast of its prediction and each other code lies at least \a
 * min_margin of its distance away from the read one: the thresholded
 * read's rules, which this is when the blur vanishes and the cells' black
 * is the frame's. */
std::optional<BlurredCells> readCellsThroughBlur(
	const std::array<double, 9>& cell_g, const std::array<double, 4>& ring_g, double frame_g,
	double frame_ink, const FaceMap& map, const LandmarkGeometry& geo, double patch_fraction,
	double min_margin, double sigma_px);

/** Checks the frame (inside the image, black on every side, green ring) and
 * reads the 3x3 cells; nullopt when any check fails, the centre cell is
 * green or a cell is ambiguous. A cell too near the threshold is read again
 * through the blur of \a frame_blur_px (readCellsThroughBlur()). */
std::optional<CodeReading> readCode(
	const cv::Mat& bgr, const RefinedQuad& q, const CameraModel& camera, const LandmarkGeometry& g,
	const CodeParams& p, double frame_blur_px = ComponentParams().frame_blur_px);

/** The gate before the sub-pixel stage: false when, read through the linked
 * quadrangle's pixel-accurate corners \a corners_ideal (undistorted), the
 * frame is not darker than the green ring, or the centre cell is not darker
 * than the ring by CodeParams::min_margin of that contrast (readCode()'s
 * patches; the frame and the ring at each side's middle only). The code's
 * centre is always black and its patch lies farthest from every edge that
 * a corner's pixel error moves; the green surfaces that link a quadrangle
 * without a code board read green there. True when a patch leaves the
 * image (readCode() decides). */
bool centreMayBeBlack(
	const cv::Mat& bgr, const Quad& corners_ideal, const CameraModel& camera,
	const LandmarkGeometry& geometry, const CodeParams& p);

// ---------------------------------------------------------------- detector
/** detect() with the sub-pixel stage's models switched by \a models (the
 * tests and benchmarks that measure a model's effect). */
DetectionResult detectWithModels(
	const cv::Mat& bgr, const CameraModel& camera, const LandmarkGeometry& geometry,
	const DetectorOptions& options, const SubpixelModels& models,
	const std::string& debug_dir = {});

}  // namespace codemark::detect
