#pragma once
/** \file bench.h
 * codemark-bench's internals: the benchmark ini, one job (a dataset run
 * through one method, its metrics from libs/eval and the detection rate
 * against the ground truth), and the report (CSV, Markdown, plots). The
 * per-job loop is eval::runLocalization()'s with per-frame detection
 * bookkeeping and timing added.
 */
#include <codemark/eval/localization.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace codemark::bench
{
/** One dataset of the benchmark ini (section `[dataset:NAME]`). Paths are
 * absolute once loaded (relative ones are taken from the ini's folder, or
 * from `[bench] data_dir` when given). */
struct Dataset
{
	std::string name;  //!< NAME of `[dataset:NAME]`
	std::string rawlog;	 //!< images and/or landmark observations, either format
	std::string map;  //!< landmark map (spec section 3) or MRPT landmark file
	std::string gt;	 //!< ground truth, either form of spec section 6
	std::string camera;	 //!< optional camera file: replaces the rawlog's intrinsics
	/** Optional calibration of C_P (a file or a shipped calibration's
	 * name): images are measured with it and annotated sightings measured
	 * again (filters::StepperOptions::remeasure_sightings); the method
	 * ini's [pose] keys override it. Empty: the default calibration. */
	std::string calibration;
};

/** The whole benchmark ini. */
struct BenchConfig
{
	std::string file;  //!< the ini's path
	std::vector<Dataset> datasets;	//!< in file order
	std::vector<std::string> methods{"ekf", "ekf-pose", "ekf-slam", "pf"};	//!< `[bench] methods`
	/** Folder of the method inis `<method>.ini` (`[bench] config_dir`,
	 * default: share/codemark/config). */
	std::string config_dir;
	/** A landmark counts as "in view" for the detection rate when it is
	 * fully visible and its reference square spans at least this many
	 * pixels (sqrt of its image area) [px]: docs/benchmarks/detect.md's
	 * criterion. */
	double min_span_px = 30;
	/** RPE interval [s]: pairs of frames this far apart in time (the first
	 * frame at least this much later). */
	double rpe_interval_s = 1.0;
};

/** Loads and checks \a path. Throws std::runtime_error with one line naming
 * the file, the section and the key on any problem (missing file, unknown
 * section or key, missing required key, bad number, missing data file). */
BenchConfig loadBenchConfig(const std::string& path);

/** Splits "a,b, c" into {"a","b","c"}; throws std::invalid_argument naming
 * \a what on an unknown method or an empty list. */
std::vector<std::string> parseMethods(const std::string& list, const std::string& what);

/** Detection bookkeeping against the ground truth (frames with images or
 * landmark observations and a matched true pose). */
struct DetectionStats
{
	long frames = 0;  //!< camera frames with a true pose
	long frames_in_view = 0;  //!< ... where >= 1 landmark is in view (BenchConfig::min_span_px)
	long frames_detected = 0;  //!< ... and >= 1 of those was detected with its right ID
	long sightings_in_view = 0;	 //!< landmark-frames in view
	long sightings_detected = 0;  //!< ... detected with the right ID
	long wrong_ids = 0;	 //!< detections whose ID is not of a landmark that is (even partly) in view
	long images = 0;  //!< images detected on the fly (0: pre-annotated rawlog)
	double detect_ms_per_image = 0;	 //!< wall time per image: load + decode + detect + measure [ms]
};

/** The result of one job. */
struct JobResult
{
	std::string dataset, method;
	bool ok = false;
	std::string error;	//!< one line when !ok
	eval::LocalizeSummary summary;	//!< rows, metrics, first fix, per-step time
	DetectionStats detection;
	std::optional<eval::RelativePoseError> rpe;
	std::optional<eval::PathAlignment> aligned;	 //!< ATE after the best SE(2) alignment
	double wall_s = 0;	//!< the job's wall time: reading, detection, filtering, outputs [s]
	std::string out_dir;  //!< where the job's spec section 6 files are
};

/** Runs \a method over \a ds and writes its spec section 6 outputs into
 * \a out_dir. Never throws: failures are reported in JobResult::error.
 * \a progress(fraction) after each frame. \a seed, when given, first seeds
 * MRPT's random generator (mrpt::random::getRandomGenerator(), shared by
 * the whole process): the caller must then keep every other job from
 * touching the generator while this one runs. */
JobResult runJob(
	const BenchConfig& cfg, const Dataset& ds, const std::string& method,
	const std::string& out_dir, std::optional<unsigned> seed,
	const std::function<void(double)>& progress = {});

/** results.csv's header line (no newline). */
std::string csvHeader();
/** One results.csv row (no newline); fields that do not apply are empty. */
std::string csvRow(const JobResult& r);

/** Plots of one dataset into \a dir: `<name>-error.png` (position error
 * against time with the reported 3-sigma bound, one panel per method) and
 * `<name>-trajectories.png` (every method's estimate, the ground truth, the
 * landmarks). Returns the two file names (relative to \a dir). */
std::vector<std::string> writeDatasetPlots(
	const std::string& name, const std::vector<const JobResult*>& jobs, const std::string& map_file,
	const std::string& dir);

/** report.md's text. */
std::string markdownReport(
	const BenchConfig& cfg, const std::vector<JobResult>& results,
	const std::vector<std::pair<std::string, std::vector<std::string>>>& plots, int jobs,
	double total_wall_s);

}  // namespace codemark::bench
