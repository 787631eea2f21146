#pragma once
/** \file localization.h
 * The logic of codemark-localize: read a rawlog step by step
 * (RawlogStepper), run one filter (makeLocalizer), and write the outputs of
 * docs/spec.md section 6 into a folder: estimated_path.txt,
 * estimated_path.tum, covariances.txt, map.txt and map_covariances.txt
 * (SLAM), trajectory.png, trajectory.3Dscene, summary.json.
 */
#include <codemark/filters/localizer.h>
#include <codemark/filters/stepper.h>
#include <mrpt/config/CConfigFileBase.h>

#include <Eigen/Core>

#include <array>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace codemark::eval
{
/** What to run. */
struct LocalizeRequest
{
	std::string config_file;  //!< the method's ini (share/codemark/config/<method>.ini)
	std::string rawlog;	 //!< input rawlog (either format)
	std::string
		map_file;  //!< landmark map (spec section 3) or MRPT landmark file; may be empty for SLAM
	std::string
		method;	 //!< ekf | ekf-pose | ekf-slam | pf; empty: the ini's [localize] method, else ekf
	std::string gt_file;  //!< ground truth (either form of spec section 6); may be empty
	/** SLAM: the true landmark map (spec section 3 or MRPT's landmark file)
	 * for summary.json's landmark_rmse_m, the plots and, without map_file,
	 * the landmarks' per-ID scales; may be empty. */
	std::string gt_map_file;
	std::string camera_file;  //!< when set, replaces the camera stored in the rawlog
	std::string out_dir;  //!< output folder (created)
	/** C_P's calibration (a file or a shipped calibration's name,
	 * pipeline::calibratedPoseOptions()); the config's [pose] keys override
	 * it. Empty: the default calibration for images detected on the fly,
	 * and annotated sightings keep their stored C_L and C_R; set: annotated
	 * sightings are measured again with it (StepperOptions::remeasure_sightings). */
	std::string calibration;
};

struct LocalizeSummary;

/** Called after each step of runLocalization (live views, benchmarks'
 * detection tallies): the step as read (its observations, images detected
 * in it), the summary so far (its rows up to this step, the last with its
 * matched ground truth; metrics not yet computed), the map in use (empty
 * for SLAM without a prior map) and the filter (e.g. its landmarks()). */
using StepObserver = std::function<void(
	const filters::RawlogStep& step, const LocalizeSummary& so_far, const LandmarkMap& map,
	const filters::Localizer& filter)>;

/** One processed camera frame. */
struct PathRow
{
	long step = 0;
	double timestamp = 0;  //!< UNIX s, or the step index
	filters::PoseEstimate estimate;
	filters::StepStats stats;
	std::optional<mrpt::poses::CPose2D> truth;	//!< matched ground truth
};

/** Accuracy against ground truth over the initialised steps with a match. */
struct PathMetrics
{
	int matched = 0;  //!< steps compared
	double ate_rmse_m = 0;	//!< RMS of the position error [m]
	double max_error_m = 0;	 //!< largest position error [m]
	double yaw_rmse_deg = 0;  //!< RMS of the wrapped yaw error [deg]
	double nees_mean = 0;  //!< mean of e^T P^-1 e (3 DoF: x, y, yaw)
	/** Two-sided 95% band of the mean NEES of a consistent filter:
	 * chi2inv(0.025 / 0.975, 3 N) / N. */
	double nees_band_low = 0, nees_band_high = 0;
	/** True when the estimate was rigidly aligned to the ground truth before
	 * the errors were taken (SLAM without a prior map: its frame is the
	 * robot's start, arbitrary with respect to the ground truth's). */
	bool aligned = false;
	/** The alignment, truth_T_estimate (x, y [m], yaw [rad]): the SE(2)
	 * least-squares fit of the estimated positions onto the true ones
	 * (Horn/Umeyama without scale); identity when not aligned. */
	mrpt::poses::CPose2D truth_T_estimate;
	/** When aligned: the NEES is not taken in the least-squares alignment
	 * (the filter's covariance is relative to its own frame, the robot's
	 * start, where it is zero) but with the estimate's frame anchored at the
	 * true first pose: truth_T_start = truth_0 (+) (-estimate_0). */
	mrpt::poses::CPose2D truth_T_start;
	/** When aligned: the RMS position error [m] in that anchored frame (no
	 * fit), the figure kf-slam's users and bench/filters_slam compare (on
	 * kf-slam_demo the true start is the origin: the raw estimate). */
	double ate_rmse_anchored_m = 0;
	/** SLAM with ground truth map: RMS of the landmark position error after
	 * the same alignment [m], and the number of landmarks compared (0: none). */
	double landmark_rmse_m = 0;
	double landmark_yaw_rmse_deg = 0;  //!< as landmark_rmse_m: RMS of the wrapped yaw error [deg]
	int landmarks_matched = 0;
};

/** What a run did. */
struct LocalizeSummary
{
	std::string method;
	/** The calibration file that measured the sightings (resolved from
	 * LocalizeRequest::calibration); empty when none was given: images are
	 * detected with the default calibration and annotated sightings keep
	 * their stored covariances. */
	std::string calibration;
	long steps = 0;	 //!< processed camera frames
	long sightings_used = 0, sightings_rejected = 0, sightings_unknown_id = 0;
	/** Coded sightings dropped before the filter as seen beyond
	 * [stepper] max_view_angle_deg (not in sightings_rejected). */
	long sightings_too_oblique = 0;
	long reinitializations = 0;	 //!< global initialisation and kidnap recoveries
	/** Innovation consistency over the sightings tested against a
	 * prediction (fused and gated alike, filters::StepStats::innovations): the mean
	 * NIS, the mean degrees of freedom, how many were tested, the fraction
	 * gated out, and the verdict (nisVerdict()). */
	double nis_mean = 0;
	double nis_dof = 0;
	long nis_count = 0;
	double gated_fraction = 0;
	std::string nis_verdict;
	/** Mean Innovation::sighting_share (NaN when the filter reports none):
	 * how much the NIS can say about the sightings' covariances. */
	double nis_sighting_share = std::numeric_limits<double>::quiet_NaN();
	/** Per component of the innovation (filters::InnovationSummary): its
	 * mean normalised squared innovation and the sighting's share of its
	 * variance (NaN: not reported). */
	std::array<double, 3> nis_component_mean = filters::Innovation::nanComponents();
	std::array<double, 3> nis_component_share = filters::Innovation::nanComponents();
	/** First sightings of a landmark visit, their mean NIS / DoF, and
	 * whether it exceeds the others' beyond chance
	 * (InnovationSummary::persistent_errors). */
	long nis_visits = 0;
	double nis_visit_ratio = 0;
	bool persistent_errors = false;
	/** The prediction as the components the sightings barely inform read it
	 * (filters::predictionCheck()). */
	filters::PredictionCheck prediction;
	long first_fix_step = -1;  //!< first step with an estimate (-1: never)
	double first_fix_time_s = 0;  //!< time of the first fix after the first step [s]
	double time_per_step_ms = 0;  //!< mean wall time of filters::Localizer::step() [ms]
	double detect_ms_per_image = 0;	 //!< mean on-the-fly detection time [ms] (0: none)
	std::optional<PathMetrics> metrics;	 //!< with ground truth
	std::vector<PathRow> rows;
	std::vector<filters::MappedLandmark> slam_map;	//!< SLAM only
};

/** Appends the row of \a step to \a s (its estimate \a e, the filter's
 * \a stats and the matched \a truth) and updates the counters and the
 * first fix. */
void appendStep(
	LocalizeSummary& s, const filters::RawlogStep& step, const filters::StepStats& stats,
	const filters::PoseEstimate& e, const std::optional<mrpt::poses::CPose2D>& truth);

/** Sets \a s's NIS fields (nis_mean, nis_dof, nis_count, gated_fraction,
 * nis_verdict) from its rows' innovations; infinite NIS (a covariance that
 * is not positive definite) count as gated and stay out of the mean. */
void summariseInnovations(LocalizeSummary& s);

/** Metrics of \a rows (those initialised and with truth); none matched: nullopt.
 * \a align_se2: first fit truth_T_estimate (rotation and translation, no
 * scale) minimising the squared position errors, and compare the aligned
 * estimate (its covariance rotated with it) with the truth. */
std::optional<PathMetrics> computeMetrics(const std::vector<PathRow>& rows, bool align_se2 = false);

/** Fills \a m's landmark errors (landmark_rmse_m, landmark_yaw_rmse_deg,
 * landmarks_matched) of the \a estimated SLAM map against \a truth, matched
 * by ID, through \a m's truth_T_estimate (identity when not aligned). The
 * yaw error means nothing for point landmarks. */
void addLandmarkErrors(
	PathMetrics& m, const std::vector<filters::MappedLandmark>& estimated,
	const LandmarkMap& truth);

/** The SE(2) least-squares alignment b_T_a of 2D points \a a onto \a b
 * (pairs, at least one): closed form (Horn 1987 / Umeyama 1991 in the
 * plane, no scale). */
mrpt::poses::CPose2D alignSE2(
	const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b);

/** Relative pose error over a time interval. */
struct RelativePoseError
{
	int pairs = 0;	//!< pairs (i, j) compared: j the first step at least the interval after i
	double trans_rmse_m = 0;  //!< RMS of the translation of (gt_i^-1 gt_j)^-1 (est_i^-1 est_j) [m]
	double yaw_rmse_deg = 0;  //!< RMS of its rotation [deg]
};

/** The RPE of \a rows (the initialised ones with truth) over \a interval_s
 * [s]; none when no pair is that far apart. */
std::optional<RelativePoseError> relativePoseError(
	const std::vector<PathRow>& rows, double interval_s);

/** A path's least-squares rigid alignment onto its ground truth. */
struct PathAlignment
{
	mrpt::poses::CPose2D truth_T_estimate;	//!< aligned = truth_T_estimate (+) estimate
	double ate_m = 0;  //!< RMS position error after the alignment [m]
};

/** The alignSE2() of \a rows' estimated positions (initialised, with truth)
 * onto the true ones; none with fewer than 2 such rows. */
std::optional<PathAlignment> alignPath(const std::vector<PathRow>& rows);

/** Runs the whole thing and writes the outputs. \a progress(fraction) is
 * called after each step. Throws std::runtime_error / std::invalid_argument
 * with one line naming the file, line or entry on bad input. */
LocalizeSummary runLocalization(
	const LocalizeRequest& request, const std::function<void(double)>& progress = {},
	const StepObserver& on_step = {});

/** Writes the output files of \a s into \a out_dir (created). \a map: the
 * map used (drawn in the plot and the 3D scene). */
void writeOutputs(const LocalizeSummary& s, const LandmarkMap& map, const std::string& out_dir);

/** summary.json's text. */
std::string summaryJson(const LocalizeSummary& s);

}  // namespace codemark::eval
