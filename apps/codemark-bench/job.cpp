// codemark-bench: one job = one dataset through one method, its metrics
// (libs/eval) and the detection rate against the ground truth.
#include <codemark/landmark/random.h>
#include <codemark/eval/ground_truth.h>
#include <codemark/filters/mrpt_landmarks.h>
#include <codemark/filters/stepper.h>
#include <codemark/pose/closed_form.h>
#include <codemark/landmark/camera.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <codemark/sim/frames.h>
#include <codemark/sim/render.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/math/wrap2pi.h>
#include <mrpt/random/RandomGenerators.h>

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <set>

#include "bench.h"
#include "errors.h"

namespace codemark::bench
{
using mrpt::poses::CPose2D;
using Clock = std::chrono::steady_clock;

namespace
{
double seconds(Clock::time_point a, Clock::time_point b)
{
	return std::chrono::duration<double>(b - a).count();
}

// Compares one frame's landmark observation with what the true pose shows.
void tallyDetections(
	const CObservationCodedLandmarks& obs, const CPose2D& truth, const LandmarkMap& map,
	const std::optional<CameraModel>& camera_override, double min_span_px,
	double max_view_angle_deg, DetectionStats& d)
{
	sim::Scene scene;
	scene.map = map;
	scene.camera = camera_override ? *camera_override : CameraModel(obs.camera);
	scene.world_T_camera = mrpt::poses::CPose3D(truth) + obs.cameraPose;
	std::set<int> in_view, visible;
	for (const auto& t : sim::groundTruth(scene))
	{
		if (sim::isInView(t, scene.camera)) visible.insert(t.id);
		// Seen beyond the stepper's max_view_angle_deg, a sighting is dropped
		// before the filter (and before this tally): not expected.
		if (t.fully_visible && std::sqrt(t.area_px) >= min_span_px &&
			pose::viewAngle(t.sighting.L) <= max_view_angle_deg * M_PI / 180.0)
			in_view.insert(t.id);
	}
	std::set<int> right;
	for (const auto& s : obs.sightings)
	{
		if (in_view.count(s.id)) right.insert(s.id);
		if (!visible.count(s.id)) ++d.wrong_ids;
	}
	++d.frames;
	d.sightings_in_view += static_cast<long>(in_view.size());
	d.sightings_detected += static_cast<long>(right.size());
	if (!in_view.empty())
	{
		++d.frames_in_view;
		if (!right.empty()) ++d.frames_detected;
	}
}
}  // namespace

JobResult runJob(
	const BenchConfig& cfg, const Dataset& ds, const std::string& method,
	const std::string& out_dir, std::optional<unsigned> seed,
	const std::function<void(double)>& progress)
{
	JobResult r;
	r.dataset = ds.name;
	r.method = method;
	r.out_dir = out_dir;
	const auto t_start = Clock::now();
	try
	{
		if (seed) reseedMrptRandom(*seed);
		const std::string ini = cfg.config_dir + "/" + method + ".ini";
		mrpt::config::CConfigFile mcfg(ini);
		auto& s = r.summary;
		s.method = method;
		const bool mrpt_map = filters::isMrptLandmarksFile(ds.map);
		const LandmarkMap map =
			mrpt_map ? filters::loadMrptLandmarksFile(ds.map) : LandmarkMap::load(ds.map);
		const eval::GroundTruth gt = eval::GroundTruth::load(ds.gt);
		std::optional<CameraModel> camera;
		if (!ds.camera.empty()) camera = CameraModel::load(ds.camera);

		auto [so, po] = filters::readingOptions(
			mcfg, ds.calibration, mrpt_map ? std::nullopt : std::optional(map));
		po.camera_override = camera;

		// ekf-slam builds its own map: the dataset's map is its ground truth
		// (for the plots and the detection rate), not a prior.
		const LandmarkMap prior = method == "ekf-slam" ? LandmarkMap() : map;
		auto filter = filters::makeLocalizer(method, mcfg, prior, filters::initialPose(mcfg));
		filters::RawlogStepper stepper(ds.rawlog, so, po);
		filters::RawlogStep step;
		double filter_s = 0, detect_s = 0;
		auto t_read = Clock::now();
		while (true)
		{
			const bool more = stepper.next(step);
			const auto t0 = Clock::now();
			if (!more) break;
			if (step.images_detected > 0)
			{
				r.detection.images += step.images_detected;
				detect_s += seconds(t_read, t0);
			}
			const filters::StepStats st = filter->step(step.odometry.get(), step.observations);
			filter_s += seconds(t0, Clock::now());
			const auto truth = gt.poseAt(step.index, step.timestamp, 1e-3, step.actions);
			if (truth && !mrpt_map)
				for (const auto& o : step.observations)
					if (auto lm = std::dynamic_pointer_cast<CObservationCodedLandmarks>(o))
						tallyDetections(
							*lm, *truth, map, camera, cfg.min_span_px, so.max_view_angle_deg,
							r.detection);
			eval::appendStep(s, step, st, filter->estimate(), truth);
			if (progress) progress(stepper.progress());
			t_read = Clock::now();
		}
		s.time_per_step_ms = s.steps ? 1000.0 * filter_s / s.steps : 0.0;
		s.detect_ms_per_image = r.detection.images ? 1000.0 * detect_s / r.detection.images : 0.0;
		r.detection.detect_ms_per_image = s.detect_ms_per_image;
		s.slam_map = filter->landmarks();
		// SLAM without a prior map estimates in the frame of the robot's
		// start: its ATE and NEES after the alignment (NEES anchored at the
		// true first pose), as codemark-localize reports them.
		s.metrics = eval::computeMetrics(s.rows, prior.landmarks.empty());
		eval::summariseInnovations(s);
		r.rpe = eval::relativePoseError(s.rows, cfg.rpe_interval_s);
		r.aligned = eval::alignPath(s.rows);
		eval::writeOutputs(s, map, out_dir);
		r.ok = true;
	}
	catch (const std::exception& e)
	{
		r.error = app::printable(app::oneLine(e));
	}
	r.wall_s = seconds(t_start, Clock::now());
	if (progress) progress(1.0);
	return r;
}

}  // namespace codemark::bench
