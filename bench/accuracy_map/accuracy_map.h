#pragma once
/** \file accuracy_map.h
 * The survey of the paper's section 4 (Figs. 5-8) on renders: a grid of
 * level-camera positions in front of one landmark (one half plane, the map
 * being symmetric), rendered with the project's renderer, detected, measured
 * by the closed form and the general 6-DoF path, and compared with the
 * geometric truth; optionally AprilTag 3 (tag36h11) with the general path on
 * a tag of the same corner-square size rendered at the same poses.
 * Kept beside the tool because it needs both the renderer and the detector,
 * which the pose library must not depend on.
 */
#include <codemark/detect/options.h>
#include <codemark/landmark/camera.h>
#include <codemark/pipeline/pipeline.h>
#include <codemark/pose/measurement.h>
#include <codemark/sim/render.h>

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace codemark::accuracy
{
/** Settings of the survey. */
struct SurveyOptions
{
	double cell_m = 0.5;  //!< grid step [m]
	double min_distance_m = 0.5;  //!< cells closer than this are skipped [m]
	double max_distance_m = 5.0;  //!< cells farther than this are skipped [m]
	double max_angle_deg = 70;	//!< cells beyond this view angle are skipped [deg]
	int renders_per_cell = 5;  //!< noisy renders per cell (different seeds)
	double noise_sigma = 2.0;  //!< renderer pixel noise [grey levels]
	double blur_sigma_px = 0.8;	 //!< renderer blur [px]
	/** Noise model of P for C_L, C_R (the method field is ignored: both paths
	 * run): the tools' default calibration (pipeline::calibratedPoseOptions()). */
	pose::PoseOptions pose = pipeline::calibratedPoseOptions();
	/** A one-line description of \a pose's noise model for the summary. */
	std::string noise_label = std::string("calibration ") + pipeline::kDefaultCalibration;
	/** codemark's detector settings (--detector-config). */
	detect::DetectorOptions detector;
	bool apriltag = true;  //!< also run AprilTag 3 + the general path
	/** Render codemark's landmark in the realistic scene of the C_P
	 * calibration and the simulated datasets (sim::DatasetOptions::
	 * realisticRender(): textured wall, light gradient, distractors) instead
	 * of the paper's plain grey background; noise and blur as set. The
	 * AprilTag renders keep the plain background. */
	bool realistic = false;
	/** Camera preset (docs/camera-pipeline.md) of the renders, codemark's
	 * and AprilTag's alike, in place of noise_sigma and blur_sigma_px;
	 * "" = none. */
	std::string preset;
	/** The image source of codemark's renders: sim::render (the project's
	 * renderer), or e.g. sim::povrayRenderer(); \a source_label names it in
	 * the summary. */
	sim::Renderer renderer = sim::render;
	std::string source_label = "the project's renderer";
	/** Each render aims the camera off the landmark by a bearing drawn
	 * uniformly within +-aim_jitter_rad and puts it higher or lower by up to
	 * height_jitter_m (the cell fixes the camera's planar position): a robot
	 * never looks exactly at a landmark's centre, and a landmark dead centre
	 * in the image mirrors its left and right (top and bottom) edges' pixel
	 * phases, so their sampling biases cancel in the bearing (and phi2) and
	 * make C_P look 2x pessimistic there. 0, 0: exactly centred. */
	double aim_jitter_rad = 0.15;
	double height_jitter_m = 0.2;  //!< see aim_jitter_rad [m]
	uint64_t seed = 1;	//!< first render seed
};

/** Mean absolute errors over the renders of one cell for one method. */
struct MethodErrors
{
	int detected = 0;  //!< renders where the method found the landmark
	double l2_m = 0, phi1_rad = 0, phi2_rad = 0;  //!< mean |error| of L
	double x_m = 0, y_m = 0, theta_rad = 0;	 //!< mean |error| of the pose in L
	double position_m = 0;	//!< mean Euclidean position error in L
	double nees = 0;  //!< mean NEES of the pose with the reported C_R (3 dof)
	double nees_L = 0;	//!< mean NEES of L with the reported C_L (3 dof)
	/** Sum and count of the pose NEES over the sightings whose reported phi2
	 * sigma is at most 2 deg (where a Gaussian C_R can hold). */
	double nees_small_phi2_sum = 0;
	int nees_small_phi2_n = 0;
	/** Standard errors of the seven means above (l2, phi1, phi2, x, y,
	 * theta, position), from the spread of |error| over the renders
	 * (infinite with under two detections); \a sum_sq accumulates. */
	std::array<double, 7> se{}, sum_sq{};
	/** The seven means in that order. */
	std::array<double, 7> means() const
	{
		return {l2_m, phi1_rad, phi2_rad, x_m, y_m, theta_rad, position_m};
	}
};

/** One grid cell. */
struct CellResult
{
	double X_m = 0, Y_m = 0;  //!< camera position in frame L [m]
	double distance_m = 0, angle_deg = 0;
	int renders = 0;
	/** Predicted 1-sigma (closed form at the exact corners, SurveyOptions::pose). */
	double sigma_l2_m = 0, sigma_phi1_rad = 0, sigma_phi2_rad = 0, sigma_x_m = 0, sigma_y_m = 0;
	MethodErrors closed_form, general, apriltag;
	/** Mean (detected - true) AprilTag corner position over the cell's
	 * detections [px]: the tag detector's own bias. */
	double tag_corner_dx_px = 0, tag_corner_dy_px = 0;
	/** The same for codemark's detector. */
	double corner_dx_px = 0, corner_dy_px = 0;
	/** RMS corner error over the cell's detections [px], codemark and tag. */
	double corner_rms_px = 0, tag_corner_rms_px = 0;
};

/** Runs the survey on \a camera (level, at the landmark centre's height,
 * looking at the landmark centre). \a progress, when given, is called with
 * (cells done, cells total). */
std::vector<CellResult> runSurvey(
	const CameraModel& camera, const SurveyOptions& options,
	const std::function<void(long, long)>& progress = {});

/** Writes cells.csv, heat maps (heat_l2.png, heat_phi2.png, heat_x.png,
 * heat_y.png: measured mean absolute error beside the predicted sigma) and
 * summary.txt into \a dir (created when missing); returns the summary text
 * (the table against the paper's claims and the targets). */
std::string writeResults(
	const std::vector<CellResult>& cells, const SurveyOptions& options, const std::string& dir);

}  // namespace codemark::accuracy
