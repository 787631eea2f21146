#pragma once
/** \file measurement.h
 * The measurement of one sighted landmark (docs/design.md: "Measurement
 * {P, C_P, L, C_L, pose_in_landmark, C_R, method}"; docs/spec.md
 * section 4), its options, and measure(), the single entry point that runs
 * either the paper's closed form or the general 6-DoF path.
 */
#include <codemark/landmark/camera.h>
#include <codemark/landmark/detection.h>
#include <codemark/landmark/geometry.h>
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>
#include <vector>

namespace codemark::pose
{
/** Which computation turns the corners into L and the pose. */
enum class PoseMethod
{
	/** The paper's closed form P -> L -> pose (section 2.3), first-order
	 * covariances with analytic Jacobians. Assumes a level camera (optical
	 * axis horizontal) and uses P only. */
	ClosedForm,
	/** Full 6-DoF pose from the four corners (planar PnP, both IPPE
	 * solutions refined by Levenberg-Marquardt on the reprojection error),
	 * reduced to the planar L and pose; any camera orientation, lens
	 * distortion. */
	General6Dof
};

/** Where the corner noise comes from. */
enum class SigmaSource
{
	/** PoseOptions::sigma_px for every measurement. */
	Fixed,
	/** The detector's own per-detection estimate
	 * (DetectionQuality::corner_sigma_px, per corner coordinate; each
	 * component of P then has corner_sigma_px / sqrt(2)), floored at
	 * PoseOptions::min_sigma_px, in place of sigma_px, the growth terms and
	 * the sigma tables; sigma_px where the detector gives none. */
	Detector
};

/** "Fixed" / "Detector" (case-insensitive on read). */
std::string toString(SigmaSource s);
/** Throws std::invalid_argument naming the accepted values. */
SigmaSource sigmaSourceFromString(const std::string& name);

/** "ClosedForm" / "General6Dof" (case-insensitive on read). */
std::string toString(PoseMethod m);
/** Throws std::invalid_argument naming the accepted values. */
PoseMethod poseMethodFromString(const std::string& name);

/** Default standard deviation of each component of P [px] of the pose
 * library alone (the spec's constant diagonal C_P): a placeholder for code
 * that sets no noise model. The tools measure with a calibration file's
 * size-dependent C_P instead (calibration.h, docs/calibration.md). */
constexpr double kDefaultSigmaPx = 0.05;

/** A standard deviation tabulated against an apparent size: (size [px],
 * sigma [px]) pairs, sizes increasing. */
using SigmaTable = std::vector<std::pair<double, double>>;

/** sigma at \a size_px: linear in log(size) - log(sigma) between the
 * entries, the end values beyond them. \a table must not be empty. */
double interpolateSigma(const SigmaTable& table, double size_px);

/** "size:sigma size:sigma ..." (the ini form); throws std::invalid_argument
 * naming the bad entry on anything else, on sizes not increasing or on
 * values that are not finite and > 0. An empty text is an empty table. */
SigmaTable sigmaTableFromString(const std::string& text);
std::string toString(const SigmaTable& table);

/** Options of measure(). Loadable from an ini section. */
struct PoseOptions : public mrpt::config::CLoadableOptions
{
	PoseMethod method = PoseMethod::ClosedForm;	 //!< ini key `method` = ClosedForm | General6Dof
	/** Standard deviation of each component of P = [x1 y1 x2 y2] [px]
	 * (C_P = diag(s^2, s^2, s^2, s^2)). Each corner coordinate then has
	 * sqrt(2) * sigma_px, which the general path uses. */
	double sigma_px = kDefaultSigmaPx;
	/** Standard deviation of y1 and y2 (the half-lengths of the vertical
	 * edges) [px] when it differs from that of x1 and x2: then C_P =
	 * diag(sigma_px^2, sigma_y_px^2, sigma_px^2, sigma_y_px^2) (spec section
	 * 4 allows sx != sy). 0: the same as sigma_px. x1, x2 come from whole-edge
	 * line fits; y1, y2 from where the top and bottom lines cut them, which
	 * the detector locates less well. */
	double sigma_y_px = 0;
	/** sigma_y_px, or sigma_px when it is 0. */
	double sigmaY() const { return sigma_y_px > 0 ? sigma_y_px : sigma_px; }
	/** Growth of the noise of x1, x2 as the landmark shrinks in the image
	 * [px]: sigma_x(w) = sqrt(sigma_px^2 + (growth_x_px (size_reference_px /
	 * w)^size_exponent_x)^2), w = x2 - x1 the apparent (foreshortened) width
	 * [px]. Default 0: sigma_px at every size (the spec's constant C_P). A small
	 * landmark's black frame is a few pixels wide and its two edges blur
	 * into each other, which moves the inner edges. */
	double growth_x_px = 0;
	/** The same for y1, y2 with h = y1 + y2 the apparent height [px]. Default 0. */
	double growth_y_px = 0;
	/** When not empty: sigma(x1) = sigma(x2) tabulated against the apparent
	 * width w = x2 - x1 (interpolateSigma()), in place of sigma_px and the
	 * growth term, and corr(x1, x2) = corr_growth_x12 throughout. A
	 * detector's error against size need not follow one power law (a thin
	 * frame's edges pull on each other below about 7 px, noise alone
	 * falls as 1 / sqrt(edge length)): codemark-bench-pose-calib measures the
	 * table. Default empty. ini key `sigma_x_table` = "size:sigma size:sigma ...". */
	SigmaTable sigma_x_table;
	/** The same for y1, y2 against the apparent height h = y1 + y2, with
	 * corr_growth_y12. ini key `sigma_y_table`. */
	SigmaTable sigma_y_table;
	double size_exponent_x = 2;	 //!< exponent of the growth of x1, x2 (see growth_x_px)
	double size_exponent_y = 2;	 //!< exponent of the growth of y1, y2 (see growth_x_px)
	double size_reference_px =
		30;	 //!< apparent size at which the growth term equals growth_*_px [px]
	/** Correlation coefficient, in (-1, 1), of the errors of x1 and x2 in the
	 * constant (sigma_px) part of their noise. Negative: the two inner
	 * vertical edges move apart or together (the square's apparent width,
	 * which phi2 uses at oblique views, is then worse than independent
	 * errors say). 0: the spec's diagonal C_P. */
	double corr_x12 = 0;
	/** The same for the size-dependent (growth_x_px) part. */
	double corr_growth_x12 = 0;
	/** Correlation coefficient, in (-1, 1), of the errors of y1 and y2 in the
	 * constant (sigma_y_px) part; positive: both half-lengths grow or shrink
	 * together (a range error, not a phi2 error). */
	double corr_y12 = 0;
	/** The same for the size-dependent (growth_y_px) part; negative: the top
	 * and bottom lines tilt (line fits over few edge points), a phi2 error. */
	double corr_growth_y12 = 0;
	/** General path: the standard deviation of each vertical edge's
	 * midpoint height in the image over that of its half-length y_i, and of
	 * the edge's tilt (half the x difference of its ends) over that of its
	 * x_i: the corners' four numbers that P does not hold
	 * (cornerCovarianceFromPrimary()). 1: independent corners of equal
	 * noise. ini keys `corner_midpoint_ratio`, `corner_tilt_ratio`. */
	double corner_midpoint_ratio = 1.0;
	double corner_tilt_ratio = 1.0;	 //!< see corner_midpoint_ratio
	/** corner_tilt_ratio tabulated against the apparent height y1 + y2 (the
	 * vertical edges' length) [px], interpolated as the sigma tables; when
	 * not empty, in place of corner_tilt_ratio. The detector's tilt ratio
	 * depends on the edges' length: on short edges its line fits err mostly
	 * by shifts of whole lines (a small ratio), on long ones the ratio nears
	 * 1, so one constant ratio cannot fit every distance. Default empty. ini
	 * key `corner_tilt_ratio_table` = "size:ratio size:ratio ...". */
	SigmaTable corner_tilt_ratio_table;
	/** corner_tilt_ratio, or its table's value at apparent height \a height_px. */
	double cornerTiltRatio(double height_px) const;
	/** General path, an image noisier than reference_noise_grey: the
	 * standard deviation of the edges' tilt gained with the noise over the
	 * one x_i gains (noiseScale()); the tilt's variance is then r^2
	 * var_ref(x_i) + corner_tilt_noise_ratio^2 (var(x_i) - var_ref(x_i)), r
	 * the tilt ratio (cornerTiltRatio()). A tilt gains more from the noise
	 * than from the detector's bias, which shifts whole lines (a line fit's
	 * slope takes 3x the variance of its offset at the ends). Default 0: r
	 * for both parts. ini key `corner_tilt_noise_ratio`. */
	double corner_tilt_noise_ratio = 0;
	/** Standard deviation added to the edge of each side whose green fill
	 * clipped throughout (DetectionQuality::fill_clipped) [px]: its edge
	 * rests on the dark half of the transition alone and is less certain than
	 * an unclipped one (see docs/benchmarks/pose.md). A left or right
	 * side adds it to x1 or x2; a top or bottom side moves both half-lengths
	 * by half its shift (y1, y2 fully correlated). Applied by
	 * measure(const Detection&, ...) only (a prediction cannot know the
	 * light). Default 0: off. ini key `clipped_side_sigma_px`. */
	double clipped_side_sigma_px = 0;
	/** Correlation, in [0, 1), of the outward shifts of two clipped sides: the
	 * edge model's fill level, which places every clipped edge, errs for all
	 * of them at once, so a landmark clipped all round looks larger or
	 * smaller as a whole (a range error). Default 0. ini key
	 * `clipped_side_correlation`. */
	double clipped_side_correlation = 0;
	/** The part of C_P that clipped sides add (see clipped_side_sigma_px),
	 * sides in the order top, right, bottom, left. */
	Eigen::Matrix4d clippedSidesCovariance(const std::array<bool, 4>& clipped) const;
	/** A top or bottom edge that runs along a pixel row (its ends less than
	 * a row apart in the image: a level camera at the landmark's height)
	 * keeps one sub-pixel phase over its length, so the edge estimator's
	 * phase-dependent bias does not average out along it; tilted by a row or
	 * more, it does. Such an edge's offset gets the extra standard deviation
	 * aligned_edge_ratio sigma_y(h) (1 - rows), rows the ends' difference
	 * [px] (0 beyond one row), shared by y1 and y2 as a clipped side's.
	 * (Vertical edges of a level camera always run along a pixel column:
	 * the calibration's x model holds that.) Default 0: off. ini key
	 * `aligned_edge_ratio`. */
	double aligned_edge_ratio = 0;
	/** The part of C_P that aligned top and bottom edges add (see
	 * aligned_edge_ratio), from the ends' row differences [px] of the top
	 * and bottom edges; \a band_se_px as in primaryCovariance(). */
	Eigen::Matrix4d alignedEdgesCovariance(
		const Eigen::Vector4d& P, double top_rows_px, double bottom_rows_px,
		double band_se_px = 0) const;
	/** C_P of a measured or predicted P under these options (without the
	 * detector's own sigma), the sum of a constant and a size-dependent part,
	 * each with its correlation of the two edges:
	 *   var(x1) = var(x2) = sigma_px^2 + gx^2,  cov(x1, x2) = corr_x12 sigma_px^2 + corr_growth_x12
	 * gx^2, var(y1) = var(y2) = sigma_y^2 + gy^2,   cov(y1, y2) = corr_y12 sigma_y^2 +
	 * corr_growth_y12 gy^2, gx = growth_x_px (size_reference_px / (x2 - x1))^size_exponent_x, gy =
	 * growth_y_px (size_reference_px / (y1 + y2))^size_exponent_y, no x-y terms. With the growth
	 * terms and correlations at 0 this is the spec's C_P = diag(sigma_px^2, sigma_y^2, sigma_px^2,
	 * sigma_y^2). With reference_noise_grey > 0 and \a image_noise_grey > 0
	 * each axis's block is then scaled to the image's noise
	 * (noiseScale()). */
	Eigen::Matrix4d primaryCovariance(
		const Eigen::Vector4d& P, double image_noise_grey = 0, double band_se_px = 0) const;
	/** The scatter model of a detection: where band_ratio_x (band_ratio_y)
	 * is > 0 and the detector measured the scatter of the landmark's green
	 * bands (\a band_se_px = DetectionQuality::edge_bend_se_px > 0),
	 * primaryCovariance() gives x1 and x2 (y1 and y2) the variance
	 * (band_ratio_x band_se_px)^2 + band_floor_x(w)^2 in place of the
	 * models above, with corr_growth_x12 (corr_growth_y12) between the two
	 * edges, and no noise scaling (the scatter already holds the image's
	 * noise). The bands' edges see what the frame's inner edges see (the
	 * image's noise, demosaicing, sharpening, compression, a chromatic
	 * fringe), so their scatter over the landmark follows the corners'
	 * error from camera to camera, where the constant and tabulated models
	 * hold for one camera only (docs/calibration.md). A prediction (no
	 * image) and a detection without bands keep the models above.
	 * Default 0: off. ini keys `band_ratio_x`, `band_ratio_y`. */
	double band_ratio_x = 0;
	double band_ratio_y = 0;  //!< see band_ratio_x
	/** The part of the scatter model's sigma that the bands do not see
	 * (a thin frame's edges pulling on each other, the bend that remains),
	 * tabulated against the apparent width w = x2 - x1 [px] as the sigma
	 * tables; empty: 0. ini key `band_floor_x_table`. */
	SigmaTable band_floor_x_table;
	/** The same for y1, y2 against y1 + y2. ini key `band_floor_y_table`. */
	SigmaTable band_floor_y_table;
	/** The noise at which the sigmas above were measured [grey levels], as
	 * the detector measures it (the mean DetectionQuality::image_noise_grey
	 * on the calibration renders, so that its estimator's bias cancels).
	 * When > 0 and the detector reports
	 * its image's noise n (DetectionQuality::image_noise_grey), the part of
	 * each variance that grows with the noise (noise_sigma_x_table,
	 * noise_sigma_y_table, at this noise) is scaled by (n / reference)^2:
	 * var(s, n) = var(s) + ((n / reference)^2 - 1) noise_sigma(s)^2. The
	 * rest is the detector's bias at that size, which the noise does not
	 * change. A quieter image keeps the reference's C_P (n is taken at
	 * least the reference: below it the detector's error need not fall).
	 * 0: C_P does not depend on the image (the library default).
	 * ini key `reference_noise_grey`. */
	double reference_noise_grey = 0;
	/** sigma of the noise-driven part of the error of x1, x2 at
	 * reference_noise_grey against the apparent width x2 - x1
	 * (codemark-bench-pose-calib --noise-split). ini key
	 * `noise_sigma_x_table`. */
	SigmaTable noise_sigma_x_table;
	/** The same for y1, y2 against y1 + y2. ini key `noise_sigma_y_table`. */
	SigmaTable noise_sigma_y_table;
	/** The factor of the variances of the x (\a x true) or y components at
	 * the image noise \a image_noise_grey, given their variance \a var at
	 * the reference noise and the apparent size \a size_px: 1 + ((n / ref)^2
	 * - 1) min(1, noise_sigma(size)^2 / var) with n at least ref; 1 when the
	 * model is off or the noise unknown (0). */
	double noiseScale(bool x, double size_px, double var, double image_noise_grey) const;
	/** ini key `sigma_source` = Fixed | Detector (the latter only through
	 * measure(const Detection&, ...)). */
	SigmaSource sigma_source = SigmaSource::Fixed;
	/** With SigmaSource::Detector: the smallest sigma of a component of P
	 * accepted from the detector [px] (a line fit can be over-confident). */
	double min_sigma_px = 0.01;
	/** C_R to second order in C_L (poseCovarianceSecondOrder()) instead of
	 * the spec's first order J_L C_L J_L^T; on both paths (the general one
	 * reduces its 6-DoF pose to the same planar pose of L). ini key
	 * `second_order_pose_covariance`. */
	bool second_order_pose_covariance = false;
	/** Closed form: refine L by weighted least squares on P with C_P
	 * (refineLandmarkOnPrimary(): the paper's formulas use P's four numbers
	 * unweighted for three unknowns and waste the foreshortened width, which
	 * carries most of phi2 at oblique views; see docs/benchmarks/pose.md),
	 * C_L from the Fisher information. Still P alone. Default on. ini key
	 * `refine_on_primary`. */
	bool refine_on_primary = true;
	/** Weigh the measurement's second local optimum, the landmark's mirror
	 * image about the line of sight (view angle phi1 + phi2 -> -(phi1 +
	 * phi2), IPPE's second solution on the general path), against the first
	 * and report the better fit (the lower chi2 on the closed form, IPPE's
	 * lower reprojection error on the general path) with the mean squared
	 * error over both as C_L and C_R (foldModes(), ambiguity.h). Far and
	 * near-frontal the two fit the corners almost equally, and the local
	 * covariance of one alone can exclude the true phi2 by far more than its
	 * width. Closed form refined on P (refine_on_primary) and general path.
	 * On by default: one sighting's C_L and C_R are then honest on their own.
	 * The shipped EKF configs turn it off: a filter fuses the same far
	 * landmark frame after frame, whose mirror image wins or loses by the same
	 * detector bias each time, so the widening of every frame adds up to a
	 * pessimistic filter (ekf.ini). ini key `fold_ambiguity`. */
	bool fold_ambiguity = true;
	/** General path: the most Levenberg-Marquardt iterations of each
	 * refinement. ini key `lm_max_iterations`. */
	int lm_max_iterations = 30;

	/** Throws std::invalid_argument on a non-positive sigma or iteration count. */
	void validate() const;
	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;
};

/** One landmark measurement (docs/spec.md section 4). */
struct Measurement
{
	/** P = [x1 y1 x2 y2]: midpoints' x and half-lengths of the left and right
	 * vertical inner edges, from the undistorted corners, in px of focal
	 * length lambda = fx relative to the principal point. */
	Eigen::Vector4d P = Eigen::Vector4d::Zero();
	Eigen::Matrix4d C_P = Eigen::Matrix4d::Zero();	//!< covariance of P [px^2]
	/** L = [l2 [m], phi1 [rad], phi2 [rad]] (spec section 4). */
	Eigen::Vector3d L = Eigen::Vector3d::Zero();
	Eigen::Matrix3d C_L = Eigen::Matrix3d::Zero();	//!< covariance of L
	/** The camera's planar pose in frame L: x, y [m] of the optical centre,
	 * theta [rad] heading of the optical axis, wrapped to (-pi, pi]. */
	Eigen::Vector3d pose_in_landmark = Eigen::Vector3d::Zero();
	Eigen::Matrix3d C_R = Eigen::Matrix3d::Zero();	//!< covariance of pose_in_landmark
	PoseMethod method = PoseMethod::ClosedForm;	 //!< the path that produced it

	/** General path only: the camera's optical frame in frame L (6-DoF). */
	mrpt::poses::CPose3D landmark_T_camera;
	/** General path only: RMS reprojection error of the chosen solution [px]. */
	double reprojection_rms_px = 0;
	/** General path only: RMS reprojection error of the other IPPE solution
	 * over that of the chosen one (>= 1; large = unambiguous; infinity when
	 * the chosen one is exact or there is one solution). */
	double ambiguity_ratio = 0;
	/** With PoseOptions::fold_ambiguity: the probability of the second
	 * local optimum (the mirror image about the line of sight), folded into
	 * C_L and C_R (above 0.5 when it fits almost as well and is wider); 0
	 * when there is none or folding is off. */
	double second_mode_weight = 0;
	/** That optimum's L when second_mode_weight > 0. */
	Eigen::Vector3d second_mode_L = Eigen::Vector3d::Zero();
};

/** Measures one landmark from its four reference points.
 * \param corners_raw_px raw (distorted) pixels, order TL, TR, BR, BL as seen
 *        from the front (the Detection::corners order).
 * \param camera intrinsics and distortion.
 * \param geometry the landmark's sizes (scaled landmarks: LandmarkGeometry::scaled()).
 * Throws std::invalid_argument on degenerate corners. */
Measurement measure(
	const std::array<Eigen::Vector2d, 4>& corners_raw_px, const CameraModel& camera,
	const LandmarkGeometry& geometry, const PoseOptions& options = PoseOptions());

/** As measure() on \a detection's corners; with SigmaSource::Detector the
 * corner noise is the detector's own estimate (see SigmaSource); with
 * PoseOptions::reference_noise_grey C_P follows the image noise the
 * detector measured. */
Measurement measure(
	const Detection& detection, const CameraModel& camera, const LandmarkGeometry& geometry,
	const PoseOptions& options = PoseOptions());

}  // namespace codemark::pose
