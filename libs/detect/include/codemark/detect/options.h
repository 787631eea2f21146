#pragma once
/** \file options.h
 * Parameters of the landmark detector (docs/design.md, "The detector"),
 * one small block per stage, loadable from an MRPT ini section
 * (share/codemark/detector.ini). Every default works, untouched, over the
 * target ranges (0.5-5 m, 0-60 deg, gain 0.3-2, noise <= 5, blur <= 1.5,
 * JPEG >= 70) for the 640x480, fx = 800 camera of the paper.
 */
#include <mrpt/config/CLoadableOptions.h>

#include <string>

namespace codemark::detect
{
/** Stages 1 (smoothing) and 2 (colour segmentation): the HSI predicate of
 * the paper, I > t_I and hue_min < H < hue_max, plus a saturation floor,
 * evaluated on a grid of every step_px-th pixel. */
struct SegmentationParams
{
	/** Grid step of the colour mask [px], 1..4. The mask cell (i, j) stands
	 * for the step x step block whose top-left pixel is (j*step, i*step). */
	int step_px = 2;
	/** Smoothing: average the step x step block before the predicate (a box
	 * filter of the grid's own size: every pixel is read once). When false,
	 * only the block's top-left pixel is read. */
	bool box_smoothing = false;
	/** t_I: minimum HSI intensity I = (R + G + B) / 3 of a pixel [grey
	 * levels, 0..255]. A little under the dimmest fill the code reads
	 * (CodeParams::min_contrast: an office green at I ~ 12), so that the fill
	 * pixels next to the black frame, which the blur darkens, and the dim
	 * half of a noisy fill still reach the frame, where the side selection
	 * looks for the fill just inside each inner edge. */
	double min_intensity = 10;
	/** Green hue band [deg], HSI hue (hexcone approximation), green = 120.
	 * Must lie within [60, 180] (green must be the largest channel). */
	double hue_min_deg = 80;
	double hue_max_deg = 160;
	/** Saturation floor S = 1 - min(R,G,B) / I, 0..1: rejects greys, whites
	 * and pastel greenish surfaces. Office inkjet and laser greens read
	 * S = 0.4-0.6 under daylight, a white balance off by 25% takes up to
	 * 0.12 of that, and a camera's transfer curve lowers it further. */
	double min_saturation = 0.25;
};

/** Stage 3 of the paper: N4-connected components of the mask, compactness
 * and cardinality bounds, one region of interest (ROI) per survivor. */
struct ComponentParams
{
	/** Smallest component [px of the full image] (cardinality lower bound;
	 * bounds the range: the fill of the A4 landmark at 5 m and 60 deg
	 * covers ~220 px). */
	double min_area_px = 48;
	/** Largest component as a fraction of the image area. */
	double max_area_fraction = 0.6;
	/** Upper bound of Hu's first invariant eta20 + eta02 (normalised central
	 * second-order moments; 1/6 for a filled square, ~0.32 for the fill
	 * around an all-black code board seen frontally, ~0.4 at 60 deg).
	 * Thin or ragged shapes score higher. */
	double max_compactness = 0.75;
	/** Largest ratio of the principal standard deviations (elongation);
	 * 2 for a square seen at 60 deg. */
	double max_elongation = 4.0;
	/** The ROI is the component's bounding box grown on each side by this
	 * fraction of its size (the black frame is 12.5% of the inner size
	 * wide)... */
	double roi_grow_fraction = 0.3;
	/** ... plus this many pixels (blur, grid step) [px]. */
	int roi_grow_px = 4;
	/** Frame evidence: along three short rays out of each side of the
	 * component's box, the darkest G (median of the three) must be dark. The
	 * mean of the two darkest sides must stay below max_frame_ratio times the
	 * fill's G, and every side below max_side_frame_ratio times it (a side
	 * under 2 px wide at 5 m and 60 deg does not reach black). The ratios
	 * are of encoded grey levels: printed black against a printed green is
	 * about 0.2 in linear light, which an sRGB or gamma 2.6 curve lifts to
	 * 0.5-0.55. 1 disables. */
	double max_frame_ratio = 0.7;
	double max_side_frame_ratio = 0.9;
	/** Both frame checks (this one and CodeParams::max_black_ratio) compare
	 * the frame's ink, not its blurred image: a frame a few pixels wide
	 * reads lighter than its ink because the blur spreads the fill and the
	 * sheet next to it over it. The level read is corrected for the largest
	 * blur the detector is built for (Gaussian sigma, the target ranges'
	 * 1.5 px) at the frame's width in pixels: a frame of 4 px (a 32 px
	 * square) has about a tenth of each neighbour's level added, one of 10
	 * px none; one under two blur widths (3 px) is read as it is, its
	 * depth depending on the actual blur more than on its ink. A sharper
	 * image is corrected more than it was lifted, which the checks'
	 * margins absorb [px]. 0 reads every level as it is. */
	double frame_blur_px = 1.5;
	/** Centre evidence: the code board's centre cell is always black, so a
	 * landmark's fill component has a hole at its centre. When the centre
	 * cell is surely large enough to open that hole in the mask (its
	 * smallest size estimate, cell / inner side x the box's smaller extent
	 * / sqrt(2), at least this many pixels: a black cell 8 px wide stays
	 * below 1% green at its middle under a 1.5 px blur), a component with
	 * no non-fill cell within half a cell (plus a grid step) of its box's
	 * centre is rejected before the gradients [px]. Solid green shapes cost
	 * the edgel stage most; smaller components skip the test. 0 disables. */
	double min_centre_cell_px = 8;
	/** At most this many candidates are examined per image (largest first). */
	int max_candidates = 64;
};

/** Stage 4: gradients of the G channel inside the ROI (3x3 Sobel, full
 * resolution up to max_roi_px), edgels (non-maximum suppressed along the dominant gradient
 * axis) with their polarity, grouped into 8-connected edgel domains of one
 * polarity. */
struct EdgelParams
{
	/** Absolute floor of the gradient magnitude [grey levels / px]. */
	double min_gradient = 5;
	/** Gradient threshold relative to the mean G of the component's fill
	 * (a blurred green-to-black step of contrast C and blur sigma s peaks at
	 * C / (2.5 s) per px). */
	double rel_gradient = 0.06;
	/** Domains with fewer edgels are dropped. */
	int min_edgels = 5;
	/** ROIs larger than this [px] are reduced by the smallest integer factor
	 * that brings them under it before the gradients (near landmarks: this
	 * stage needs the sides to a pixel, the sub-pixel stage works at full
	 * resolution). */
	double max_roi_px = 96;
};

/** Stage 5: selection of the four inner frame edges among the domains. */
struct SegmentParams
{
	/** Minimum length of a side's domain relative to the component's extent
	 * across that side (height for left/right, width for top/bottom). A code
	 * cell edge is at most 3/16 of the side. */
	double min_rel_length = 0.4;
	/** Largest width of a domain: sqrt of the smaller eigenvalue of its
	 * second-order moments (slimness), in pixels of the gradient image the
	 * domain was found in (reduced for ROIs above edgels.max_roi_px: there a
	 * straight but slanted edge is a staircase a fraction of that pixel
	 * wide) [px]. */
	double max_width_px = 1.5;
};

/** Stage 6: linking four segments into a quadrangle. */
struct QuadParams
{
	/** A segment's end may be this far from its corner (intersection of the
	 * neighbouring segments' lines): the larger of max_gap_px [px] and
	 * max_gap_rel times the mean side length. */
	double max_gap_px = 4;
	double max_gap_rel = 0.3;
	/** Shortest side of the quadrangle [px]. */
	double min_side_px = 8;
};

/** Stage 7: sub-pixel edges, line fits and corners. Along each side, one
 * profile per image row (left/right sides) or column (top/bottom sides)
 * across the edge; the edge is located at the centroid of the G-derivative
 * response (exact for any symmetric blur of a step). */
struct SubpixelParams
{
	/** Profiles within this distance of a corner are skipped (the corner
	 * blurs the step) [px]. */
	double corner_margin_px = 3;
	/** Search window for the derivative peak around the coarse line [px]. */
	int search_px = 3;
	/** The derivative response is summed while it stays above this fraction
	 * of its peak, at most reach_px from the peak. */
	double response_floor = 0.0;
	int reach_px = 4;
	/** A G profile whose fill side (beyond the search window) averages at
	 * least this level [grey levels] is saturated: its response is cut on the
	 * bright side, which would pull the centroid towards the frame. The edge
	 * is then located on R + B (dark in the fill, unsaturated in the black
	 * frame) and, failing that, at the G derivative's peak. Noise on a fill of
	 * exactly 255 averages below 254.5. */
	double saturation_level = 254.5;
	/** On sides where more than this fraction of the fill band's samples
	 * (from the coarse line, beyond the edge's blur and short of the code
	 * board) are at 255, the clipped samples are restored (from the fill's
	 * censored noise distribution, or where all of the fill clips from an
	 * edge model of B, G and R fitted with them censored) before the edges
	 * are read: the clip cuts the bright half of the response, which moves
	 * each edge outwards, further as more of the fill clips and as the frame
	 * thins. A fill at exactly the top clips half of them through its noise;
	 * a JPEG's ringing next to an unclipped fill a few. */
	double clipped_fraction = 0.25;
	/** Where the black frame is narrower than this across a side [px], its
	 * outer edge overlaps the inner edge's response: the edge is then taken
	 * at the derivative's peak, with a model of the outer edge's lobe
	 * removed, which the neighbour shifts far less than the centroid. */
	double min_frame_px_centroid = 6;
	/** Smallest slope of R + B accepted on a saturated profile [grey levels
	 * per px]. */
	double min_rise_rb = 4;
	/** Edge points farther than max(outlier_sigmas x robust sigma,
	 * min_outlier_px) from the line are dropped before the refit. */
	double outlier_sigmas = 3;
	double min_outlier_px = 0.25;
	/** Fewest edge points per side. */
	int min_support = 5;
	/** Largest RMS distance of the kept points to their line [px]. */
	double max_rms_px = 0.6;
	/** Largest RMS distance of the kept points to their line, as an error of
	 * the edge's response [grey levels]: an error e on a response rising s
	 * grey levels per px moves the edge by e / s, so a dim, low-contrast
	 * side scatters beyond max_rms_px under the camera's coding alone
	 * (JPEG's 8 x 8 blocks move its edge points block by block). A side's
	 * limit is the larger of max_rms_px and max_rms_grey / its slope. 8: a
	 * step of JPEG's luma quantiser at its lowest frequencies at quality 75
	 * (16 x 0.5). */
	double max_rms_grey = 8;
};

/** Stage 8: the code. Cells sampled through the homography of the corners,
 * thresholded halfway between the measured black of the frame and the green
 * of the fill. */
struct CodeParams
{
	/** Each cell is averaged over a patch of this fraction of the cell size
	 * (centred), sampled on a 5 x 5 grid. */
	double patch_fraction = 0.4;
	/** Smallest contrast G(green) - G(black) [grey levels]. No more than the
	 * dimmest print the code reads: an office green (sRGB (40, 170, 80)) at
	 * I = 12, just above SegmentationParams::min_intensity, reads G ~ 21, and
	 * its black at up to 0.55 of that through a transfer curve leaves about
	 * 10.
	 * The cells' margins (min_margin) and the black ratios judge the read
	 * above it. */
	double min_contrast = 10;
	/** The frame's G (mean of its two darkest sides; each side's ink, the
	 * blur's share of the fill and sheet removed as
	 * ComponentParams::frame_blur_px says) must stay below this fraction of
	 * the fill's: a black frame, not a grey or coloured one.
	 * Encoded grey levels: printed black against a printed green is about
	 * 0.1-0.2 in linear light and up to 0.55 through a camera's transfer
	 * curve (ComponentParams::max_frame_ratio). */
	double max_black_ratio = 0.7;
	/** Each side of the frame must stay below this fraction of the fill's G
	 * next to it (looser: at 60 deg and 5 m a side is under 2 px wide and
	 * blurs towards its neighbours). */
	double max_side_black_ratio = 0.9;
	/** The frame and the black code cells are one ink: the frame's G (two
	 * darkest sides) may exceed the black cells' mean G by at most this
	 * fraction of the fill's G above that mean. Independent of the
	 * camera's transfer curve, which maps equal levels to equal levels.
	 * A thin frame that blurs towards the fill raises it a little; a grey
	 * surround, another ink than the cells', raises it far more. */
	double max_frame_cell_ratio = 0.35;
	/** Each cell's distance to the threshold must be at least this fraction
	 * of the contrast (else ambiguous: rejected). */
	double min_margin = 0.15;
	/** The outer frame must lie inside the image by this much [px]; a
	 * landmark cut by the image border is not reported. */
	double border_px = 0.5;
};

/** All parameters of the detector. */
struct DetectorOptions : public mrpt::config::CLoadableOptions
{
	SegmentationParams segmentation;
	ComponentParams components;
	EdgelParams edgels;
	SegmentParams segments;
	QuadParams quads;
	SubpixelParams subpixel;
	CodeParams code;

	/** Throws std::invalid_argument naming the first bad parameter. */
	void validate() const;

	/** Reads every parameter present in \a section (absent keys keep their
	 * value) as `<block>.<field>` names, e.g. `segmentation.step_px`, then
	 * validates. */
	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;

	/** Loads \a section (default "DETECTOR") of an ini file; throws
	 * std::runtime_error naming the file when it cannot be read. */
	static DetectorOptions load(const std::string& path, const std::string& section = "DETECTOR");
};

}  // namespace codemark::detect
