// codemark-bench: one job = one dataset through one method, its metrics
// (libs/eval) and the detection rate against the ground truth.
#include <codemark/landmark/random.h>
#include <codemark/filters/mrpt_landmarks.h>
#include <codemark/filters/stepper.h>
#include <codemark/landmark/text.h>
#include <codemark/pose/closed_form.h>
#include <codemark/landmark/camera.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <codemark/sim/frames.h>
#include <codemark/sim/render.h>
#include <mrpt/config/CConfigFile.h>

#include <chrono>
#include <cmath>
#include <fstream>
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
		if (!std::ifstream(ini).good()) throw std::runtime_error(ini + ": cannot open config file");
		const bool mrpt_map = filters::isMrptLandmarksFile(ds.map);
		const LandmarkMap map = filters::loadAnyMap(ds.map);
		std::optional<CameraModel> camera;
		if (!ds.camera.empty()) camera = CameraModel::load(ds.camera);
		// The stepper drops sightings seen beyond its max_view_angle_deg: not expected.
		filters::StepperOptions stepper;
		try
		{
			stepper.loadFromConfigFile(mrpt::config::CConfigFile(ini), "stepper");
		}
		catch (const std::exception&)
		{
			rethrowNamingIniFile(ini);
		}

		eval::LocalizeRequest req;
		req.config_file = ini;
		req.rawlog = ds.rawlog;
		req.method = method;
		// ekf-slam builds its own map: the dataset's map is its ground truth
		// (landmark errors, plots, per-ID scales), not a prior.
		(method == "ekf-slam" ? req.gt_map_file : req.map_file) = ds.map;
		req.gt_file = ds.gt;
		req.out_dir = out_dir;
		req.calibration = ds.calibration;
		req.camera_file = ds.camera;
		r.summary = eval::runLocalization(
			req, progress,
			[&](const filters::RawlogStep& step, const eval::LocalizeSummary& so_far,
				const LandmarkMap&, const filters::Localizer&)
			{
				r.detection.images += step.images_detected;
				const auto& truth = so_far.rows.back().truth;
				if (truth && !mrpt_map)
					for (const auto& o : step.observations)
						if (auto lm = std::dynamic_pointer_cast<CObservationCodedLandmarks>(o))
							tallyDetections(
								*lm, *truth, map, camera, cfg.min_span_px,
								stepper.max_view_angle_deg, r.detection);
			});
		r.detection.detect_ms_per_image = r.summary.detect_ms_per_image;
		r.rpe = eval::relativePoseError(r.summary.rows, cfg.rpe_interval_s);
		r.aligned = eval::alignPath(r.summary.rows);
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
