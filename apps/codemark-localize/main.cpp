// codemark-localize: runs one filter (ekf, ekf-pose, ekf-slam, pf) over a
// rawlog and writes the outputs of docs/spec.md section 6. The logic is
// codemark::eval::runLocalization (libs/eval/src/localization.cpp).
#include <codemark/eval/localization.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/core/exceptions.h>
#include <tclap/CmdLine.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>

#include "calibration.h"
#include "errors.h"
#include "live_view.h"
#include "progress.h"
#include "rawlog_check.h"

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd(
			"Localizes a robot (or builds a map with ekf-slam) from a rawlog of either MRPT "
			"format: "
			"camera images (detected on the fly with the camera stored in each image observation), "
			"codemark landmark observations, or CObservationBearingRange, fused with the odometry "
			"(CActionRobotMovement2D, or CObservationOdometry interpolated to each image's time). "
			"Writes into --out DIR, one row per processed camera frame from the first fix on: "
			"estimated_path.txt (timestamp x y yaw), estimated_path.tum, covariances.txt "
			"(timestamp + 9 entries), map.txt and map_covariances.txt (SLAM), trajectory.png, "
			"trajectory.3Dscene (SceneViewer3D) and summary.json. Configuration: "
			"share/codemark/config/<method>.ini.",
			' ', "0.1");
		TCLAP::ValueArg<std::string> config(
			"c", "config", "the method's ini file", true, "", "CFG.ini", cmd);
		TCLAP::ValueArg<std::string> rawlog(
			"r", "rawlog", "input rawlog", true, "", "IN.rawlog", cmd);
		TCLAP::ValueArg<std::string> map(
			"m", "map",
			"landmark map (spec section 3) or MRPT landmark ground truth (x y z type 0 0 id); "
			"required except for ekf-slam",
			false, "", "MAP.txt", cmd);
		TCLAP::ValueArg<std::string> method(
			"", "method",
			"ekf | ekf-pose | ekf-slam | pf (default: the ini's [localize] method, else ekf)",
			false, "", "NAME", cmd);
		TCLAP::ValueArg<std::string> gt(
			"g", "gt",
			"ground truth: 'timestamp x y yaw' rows (matched by timestamp) or an MRPT robot path "
			"'x y z yaw pitch roll' (row 0 = the start pose; in actions-observations rawlogs a "
			"frame matches the row of the number of actions before it, kf-slam's step i row i + 1; "
			"else step i = row i + 1)",
			false, "", "GT.txt", cmd);
		TCLAP::ValueArg<std::string> gt_map(
			"", "gt-map",
			"ekf-slam: the true landmark map (spec section 3 or MRPT's x y z type 0 0 id) for the "
			"landmark RMSE in summary.json",
			false, "", "MAP.txt", cmd);
		TCLAP::ValueArg<std::string> out(
			"o", "out", "output directory (created)", true, "", "DIR", cmd);
		TCLAP::ValueArg<std::string> calibration(
			"", "calibration",
			"C_P's noise model: a calibration file (docs/calibration.md) or the name of a "
			"shipped one (" +
				codemark::app::shippedNames() +
				"). Images detected on the fly are "
				"measured with it, and the sightings of an annotated rawlog are measured again "
				"from "
				"their stored corners and camera (their stored C_L and C_R are used without it). "
				"The config's [pose] keys override it. Default: " +
				std::string(codemark::pipeline::kDefaultCalibration) + ".",
			false, "", "FILE|NAME", cmd);
		TCLAP::SwitchArg gui(
			"", "gui",
			"live 3D view while running (estimate, ground truth, landmarks, current pose with its "
			"95% ellipse); "
			"needs an X display (e.g. xvfb-run -a)",
			cmd);
		TCLAP::ValueArg<int> gui_every(
			"", "gui-every", "--gui: redraw every N steps (default 10)", false, 10, "N", cmd);
		TCLAP::SwitchArg gui_wait(
			"", "gui-wait", "--gui: at the end, wait for a key in the window", cmd);
		TCLAP::SwitchArg quiet("q", "quiet", "no progress bar", cmd);
		cmd.setExceptionHandling(false);  // one-line errors, below
		cmd.parse(argc, argv);

		codemark::eval::LocalizeRequest req;
		req.config_file = config.getValue();
		req.rawlog = rawlog.getValue();
		req.map_file = map.getValue();
		req.method = method.getValue();
		req.gt_file = gt.getValue();
		req.gt_map_file = gt_map.getValue();
		req.out_dir = out.getValue();
		req.calibration = calibration.getValue();
		// MRPT reads a corrupt gzip stream as a clean end of file: check first.
		codemark::app::checkRawlogGzip(req.rawlog);
		if (gui_every.getValue() < 1) throw std::invalid_argument("--gui-every must be >= 1");
		std::unique_ptr<codemark::app::LiveView> view;
		if (gui.getValue())
		{
			std::optional<codemark::eval::GroundTruth> gt_path;
			if (!req.gt_file.empty()) gt_path = codemark::eval::GroundTruth::load(req.gt_file);
			view = std::make_unique<codemark::app::LiveView>(gui_every.getValue(), gt_path);
		}
		// The label names the method: two runs over one rawlog (the demo's
		// ekf and pf) draw distinguishable progress lines.
		std::string method_name = req.method;
		if (method_name.empty() && std::ifstream(req.config_file).good())
			method_name =
				mrpt::config::CConfigFile(req.config_file).read_string("localize", "method", "ekf");
		codemark::app::ProgressBar bar(
			"codemark-localize" + (method_name.empty() ? "" : " (" + method_name + ")"),
			!quiet.getValue());
		codemark::LandmarkMap used_map;
		codemark::eval::StepObserver on_step;
		if (view)
			on_step = [&](const codemark::filters::RawlogStep&,
						  const codemark::eval::LocalizeSummary& so_far,
						  const codemark::LandmarkMap& m, const codemark::filters::Localizer& f)
			{
				used_map = m;
				view->update(so_far, m, f);
			};
		const auto s = codemark::eval::runLocalization(
			req, [&](double f) { bar.update(static_cast<long>(1000 * f), 1000); }, on_step);
		bar.finish();
		if (s.steps == 0)
			throw std::runtime_error(
				req.rawlog +
				": no camera frame to localize from (no CObservationImage, "
				"CObservationCodedLandmarks "
				"or CObservationBearingRange in the rawlog)");
		if (view)
		{
			view->finish(s, used_map, false);
			if (gui_wait.getValue()) view->finish(s, used_map, true);
		}
		std::cout << "codemark-localize: " << s.method << ", " << s.steps << " steps, "
				  << s.sightings_used << " sightings used, " << s.sightings_rejected
				  << " rejected, " << s.sightings_unknown_id << " unknown IDs, "
				  << s.time_per_step_ms << " ms/step";
		if (s.metrics)
			std::cout << "; ATE " << s.metrics->ate_rmse_m << " m, yaw RMSE "
					  << s.metrics->yaw_rmse_deg << " deg, mean NEES " << s.metrics->nees_mean
					  << (s.metrics->aligned ? " (SE(2)-aligned to the ground truth; " +
												   std::to_string(s.metrics->ate_rmse_anchored_m) +
												   " m anchored at the true start)"
											 : std::string());
		std::cout << "; wrote " << req.out_dir << "; innovations: mean NIS " << s.nis_mean
				  << " for " << s.nis_dof << " DoF over " << s.nis_count << " sightings, "
				  << 100.0 * s.gated_fraction << "% gated: " << s.nis_verdict;
		// With persistent errors the visits' first sightings judge the
		// sightings' covariances; the others show only how errors change.
		const double judged = s.persistent_errors ? s.nis_visit_ratio
												  : (s.nis_dof > 0 ? s.nis_mean / s.nis_dof : 1.0);
		if (s.persistent_errors)
			std::cout << "; but the first sightings of " << s.nis_visits
					  << " landmark visits read NIS/DoF " << s.nis_visit_ratio
					  << ": the sightings' errors persist from frame to frame, and the NIS over "
						 "all sightings understates them";
		if (s.nis_count > 0 && (judged > codemark::filters::kNisConsistentHigh ||
								judged < codemark::filters::kNisConsistentLow))
			std::cout << "; to fit the sighting noise to this run: codemark-calibrate-noise "
						 "--rawlog "
					  << req.rawlog << " --map " << (req.map_file.empty() ? "MAP" : req.map_file)
					  << " --out calibration.ini, then codemark-localize --calibration "
						 "calibration.ini";
		// The components the sightings barely inform judge the prediction.
		if (s.prediction.off())
			std::cout << "; the " << s.prediction.components
					  << " innovations are the prediction's and read NIS/DoF " << s.prediction.ratio
					  << ": its covariance looks " << s.prediction.verdict
					  << " (the odometry's model in the rawlog, the config's motion noise"
					  << (s.method == "pf" ? ", the likelihood's floors and roughening" : "")
					  << ")";
		std::cout << "\n";
		return 0;
	}
	catch (const TCLAP::ExitException& e)  // --help, --version
	{
		return e.getExitStatus();
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << codemark::app::argumentError("codemark-localize", e) << "\n";
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-localize: " << codemark::app::oneLine(e) << "\n";
	}
	return 1;
}
