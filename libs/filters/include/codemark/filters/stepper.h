#pragma once
/** \file stepper.h
 * Reads a rawlog of either MRPT format (streaming) and yields one step per
 * processed camera frame, the unit every filter consumes
 * (Localizer::step()):
 *  - actions-observations format: one step per sensory frame that holds a
 *    camera frame; its odometry is the CActionRobotMovement2D of the
 *    actions since the previous step, composed (means and covariances);
 *  - observations-only format: one step per camera frame (consecutive
 *    image / landmark / range-bearing observations with the same
 *    timestamp); its odometry is the CObservationOdometry reading
 *    INTERPOLATED to the frame's timestamp between the readings before and
 *    after it (never just the last one), turned into a
 *    CActionRobotMovement2D with the configured motion model.
 * A frame's observations: CObservationCodedLandmarks as they are; a
 * CObservationImage with no landmark observation of the same camera
 * (`<label>_LANDMARKS`) in its frame is detected on the fly
 * (pipeline::observeImage); CObservationBearingRange passed through.
 */
#include <codemark/pipeline/pipeline.h>
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>

#include <deque>
#include <memory>
#include <optional>
#include <string>

namespace codemark::filters
{
/** Options of the stepper (ini section `[stepper]`). */
struct StepperOptions : public mrpt::config::CLoadableOptions
{
	/** Observations-only rawlogs: the motion model that turns the
	 * interpolated odometry increment into a CActionRobotMovement2D (MRPT's
	 * keys: modelSelection = mmGaussian | mmThrun, gaussianModel.a1..a4,
	 * minStdXY [m], minStdPHI [rad], thrunModel.alfa1_rot_rot ...; read from
	 * the same section). */
	mrpt::obs::CActionRobotMovement2D::TMotionModelOptions motion;
	/** Detect landmarks in images that have no landmark observation. */
	bool detect_images = true;
	/** Coded sightings seen more obliquely than this are dropped before any
	 * filter sees them [deg]: the angle between the line of sight and the
	 * landmark's normal, |phi1 + phi2| (docs/spec.md section 4). The
	 * detector and the closed form are validated up to 60 deg (the
	 * render tests); beyond it the measured range is biased short, a
	 * systematic error that C_L does not describe and that makes the filters
	 * overconfident. >= 90 keeps everything. ini key `max_view_angle_deg`. */
	double max_view_angle_deg = 60.0;
	/** Measure the sightings of annotated rawlogs again (their stored
	 * corners, quality and camera, the pipeline options' C_P, the map's
	 * sizes) instead of using their stored C_L and C_R: a rawlog annotated
	 * with one calibration, localized with another (codemark-localize
	 * --calibration). ini key `remeasure_sightings`. */
	bool remeasure_sightings = false;

	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;
};

/** What a filter config sets up for reading a rawlog. */
struct ReadingOptions
{
	StepperOptions stepper;	 //!< the config's [stepper]
	pipeline::PipelineOptions pipeline;	 //!< [detector], C_P, the map's sizes
};

/** The reading options of the filter config \a cfg: [stepper] and
 * [detector]; C_P from the calibration \a calibration (a file or a shipped
 * name, pipeline::calibratedPoseOptions()), then the config's [pose] keys;
 * each ID's printed size from \a map when given (a map in the spec's
 * format). An empty \a calibration keeps the default one, and annotated
 * sightings keep their stored covariances; a set one measures them again
 * (StepperOptions::remeasure_sightings). Throws as the loaders do, naming
 * the section, key or file. */
ReadingOptions readingOptions(
	const mrpt::config::CConfigFileBase& cfg, const std::string& calibration,
	const std::optional<LandmarkMap>& map = std::nullopt);

/** One processed camera frame. */
struct RawlogStep
{
	long index = 0;	 //!< 0, 1, 2, ... in rawlog order
	long entry = 0;	 //!< index of the rawlog entry that completed the frame
	/** UNIX time [s] of the frame; the step index when the rawlog has none. */
	double timestamp = 0;
	bool has_timestamp = false;	 //!< false: timestamp is the step index
	/** Actions-observations format: the number of CActionCollection entries
	 * read before this frame (0 for a sensory frame ahead of the first
	 * action, i.e. taken at the start pose). It indexes an MRPT robot-path
	 * ground truth, whose row 0 is the start pose and row k the pose after
	 * k actions (kf-slam's step i, the (i+1)-th action-observation pair,
	 * matches row i + 1). -1 in the observations-only format. */
	long actions = -1;
	/** Robot motion since the previous step (null: none known, e.g. the
	 * first step or a rawlog without odometry). */
	mrpt::obs::CActionRobotMovement2D::Ptr odometry;
	/** The frame's CObservationCodedLandmarks (read or detected) and
	 * CObservationBearingRange. */
	mrpt::obs::CSensoryFrame observations;
	int images_detected = 0;  //!< images run through the detector in this step
	/** Coded sightings dropped as seen beyond max_view_angle_deg. */
	int sightings_too_oblique = 0;
};

/** Linear interpolation of a pose between (\a t0, \a p0) and (\a t1, \a p1)
 * at \a t (yaw along the shortest arc); \a t outside [t0, t1] is clamped. */
mrpt::poses::CPose2D interpolatePose(
	double t0, const mrpt::poses::CPose2D& p0, double t1, const mrpt::poses::CPose2D& p1, double t);

/** The streaming stepper. */
class RawlogStepper
{
   public:
	/** Opens \a path (throws std::runtime_error naming it). Images stored
	 * externally are looked up in pipeline::imagesDirectoryOf(path). */
	RawlogStepper(
		const std::string& path, const StepperOptions& options = StepperOptions(),
		const pipeline::PipelineOptions& pipeline = pipeline::PipelineOptions());
	~RawlogStepper();
	RawlogStepper(const RawlogStepper&) = delete;
	RawlogStepper& operator=(const RawlogStepper&) = delete;

	/** The next step; false at the end of the rawlog. Throws
	 * std::runtime_error naming the file and the entry index on an entry that
	 * cannot be read or is not a rawlog entry, or an image that cannot be
	 * loaded. */
	bool next(RawlogStep& out);

	/** Fraction of the file's bytes read so far, 0..1. */
	double progress() const;
	/** Entries read so far. */
	long entriesRead() const;
	/** True once an entry of the actions-observations format was read. */
	bool actionsObservationsFormat() const;

   private:
	struct Impl;
	std::unique_ptr<Impl> impl_;
};

}  // namespace codemark::filters
