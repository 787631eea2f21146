// codemark-calibrate-noise: identifies the sighting noise model (C_P's
// scales) from a recorded run with odometry and a map, without ground truth,
// and writes it as a calibration file. The logic is
// codemark::filters::fitSightingNoise (libs/filters/src/noise_fit.cpp).
#include <codemark/filters/noise_fit.h>
#include <codemark/landmark/camera.h>
#include <codemark/pose/calibration.h>
#include <mrpt/system/datetime.h>
#include <tclap/CmdLine.h>

#include <cmath>
#include <cstdio>
#include <iostream>

#include "calibration.h"
#include "errors.h"
#include "progress.h"
#include "rawlog_check.h"

namespace
{
void printStats(const char* what, const codemark::filters::InnovationSummary& s)
{
	std::printf(
		"  %-7s mean NIS %.3g for %.3g DoF (ratio %.2f) over %ld sightings, %.1f%% gated, "
		"sightings %.0f%% of the innovations' covariance; first sightings of %ld visits %.2f, "
		"the others %.2f\n",
		what, s.nis_mean, s.nis_dof, s.nis_dof > 0 ? s.nis_mean / s.nis_dof : 0.0, s.tested,
		s.tested ? 100.0 * double(s.gated) / double(s.tested) : 0.0, 100.0 * s.sighting_share,
		s.visits, s.visit_ratio, s.other_ratio);
	// Per component: a component whose innovation is mostly the prediction's
	// (a small sighting share; the bearing's on a wheel odometry) says little
	// of the sightings' noise.
	std::printf("          per component, mean NIS (sightings' share):");
	for (size_t i = 0; i < 3; ++i)
		if (std::isfinite(s.component_nis[i]))
			std::printf(
				" %s %.2f (%.0f%%)", codemark::filters::kInnovationComponents[i],
				s.component_nis[i], 100.0 * s.component_share[i]);
	std::printf("\n");
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd(
			"Identifies the sighting noise model from a recorded run, without ground truth: the "
			"scales of C_P's constant and size-dependent parts, for x and for y, that maximise "
			"the likelihood of the EKF's innovations over the run (the config's motion noise "
			"held fixed). Reads rawlogs of either MRPT format, with images (detected with the "
			"starting calibration) or annotated landmark observations (measured again from "
			"their corners). Errors of the map's survey are absorbed into the noise it finds. "
			"Writes a calibration file (docs/calibration.md) for --calibration of every tool. "
			"With --scale K instead of a run, writes the starting calibration with every sigma "
			"multiplied by K (C_P by K^2), e.g. after codemark-localize reads covariances too "
			"small by about K^2x.",
			' ', "0.1");
		TCLAP::ValueArg<std::string> rawlog(
			"r", "rawlog", "the recorded run, with odometry (required unless --scale)", false, "",
			"IN.rawlog", cmd);
		TCLAP::ValueArg<std::string> map(
			"m", "map",
			"landmark map (spec) or MRPT landmark ground truth (required unless --scale)", false,
			"", "MAP.txt", cmd);
		TCLAP::ValueArg<std::string> camera(
			"", "camera", "camera file replacing the camera stored in the rawlog", false, "",
			"CAMERA.ini", cmd);
		TCLAP::ValueArg<std::string> config(
			"c", "config",
			"the EKF's ini ([ekf] gate and motion noise, [stepper], [detector], [pose]); "
			"default: the shipped ekf.ini",
			false, "", "CFG.ini", cmd);
		TCLAP::ValueArg<std::string> start(
			"", "calibration",
			"the starting calibration (file or shipped name: " + codemark::app::shippedNames() +
				"); default: " + std::string(codemark::pipeline::kDefaultCalibration),
			false, codemark::pipeline::kDefaultCalibration, "FILE|NAME", cmd);
		TCLAP::ValueArg<std::string> out(
			"o", "out", "the calibration file to write", true, "", "OUT.ini", cmd);
		TCLAP::ValueArg<int> evals(
			"", "max-evaluations", "likelihood evaluations of the search (default 400)", false, 400,
			"N", cmd);
		TCLAP::ValueArg<double> scale(
			"", "scale",
			"no fit: write the starting calibration with every sigma multiplied by K (> 0)", false,
			1.0, "K", cmd);
		TCLAP::SwitchArg quiet("q", "quiet", "no progress bar", cmd);
		cmd.setExceptionHandling(false);  // one-line errors, below
		cmd.parse(argc, argv);

		std::string command = "codemark-calibrate-noise";
		for (int a = 1; a < argc; ++a) command += std::string(" ") + argv[a];
		if (scale.isSet())
		{
			if (!(scale.getValue() > 0) || !std::isfinite(scale.getValue()))
				throw TCLAP::ArgException("must be finite and > 0", "scale");
			if (rawlog.isSet() || map.isSet())
				throw TCLAP::ArgException(
					"--scale writes a calibration without a run: "
					"drop --rawlog and --map, or --scale",
					"scale");
			const std::string from = codemark::pose::resolveCalibration(start.getValue());
			codemark::pose::saveCalibration(
				out.getValue(),
				codemark::pose::scaledNoiseModel(
					codemark::pose::loadCalibration(from), scale.getValue()),
				{"codemark calibration: " + from + " with every sigma multiplied by " +
					 std::to_string(scale.getValue()),
				 "made by: " + command,
				 "date: " + mrpt::system::dateTimeToString(mrpt::Clock::now())});
			std::printf("wrote %s\n", out.getValue().c_str());
			return 0;
		}
		if (!rawlog.isSet() || !map.isSet())
			throw TCLAP::ArgException(
				"required to fit (or --scale to scale a calibration)",
				rawlog.isSet() ? "map" : "rawlog");

		codemark::filters::NoiseFitRequest req;
		req.rawlog = rawlog.getValue();
		req.map_file = map.getValue();
		req.camera_file = camera.getValue();
		req.config_file =
			config.isSet() ? config.getValue() : codemark::findShareFile("config/ekf.ini");
		req.calibration = start.getValue();
		req.max_evaluations = evals.getValue();
		if (req.max_evaluations < 20)
			throw std::invalid_argument("--max-evaluations must be >= 20");
		codemark::app::checkRawlogGzip(req.rawlog);

		codemark::app::ProgressBar bar("codemark-calibrate-noise", !quiet.getValue());
		const auto r = codemark::filters::fitSightingNoise(
			req, [&](double f) { bar.update(std::lround(1000 * f), 1000); });
		bar.finish();

		std::printf(
			"codemark-calibrate-noise: %ld frames, %ld sightings of mapped landmarks at %.0f-%.0f "
			"px apparent width, %d likelihood evaluations\n",
			r.steps, r.sightings, r.width_min_px, r.width_max_px, r.evaluations);
		const double s0[4] = {
			r.start_scales.sigma_x_px, r.start_scales.growth_x_px, r.start_scales.sigma_y_px,
			r.start_scales.growth_y_px};
		const double s1[4] = {
			r.fitted_scales.sigma_x_px, r.fitted_scales.growth_x_px, r.fitted_scales.sigma_y_px,
			r.fitted_scales.growth_y_px};
		const char* names[4] = {"sigma_px", "growth_x_px", "sigma_y_px", "growth_y_px"};
		std::printf(
			"  %-12s %10s %10s %8s %12s\n", "scale [px]", "start", "fitted", "ratio", "+-1 sigma");
		for (int i = 0; i < 4; ++i)
			std::printf(
				"  %-12s %10.4g %10.4g %8.2f %11.0f%%\n", names[i], s0[i], s1[i], s1[i] / s0[i],
				100.0 * r.relative_std[i]);
		printStats("before:", r.before);
		printStats("after:", r.after);
		std::printf(
			"  the motion noise is the config's, held fixed; errors of the map's survey are "
			"absorbed into the noise found\n");
		for (const auto& w : r.warnings)
			std::fprintf(stderr, "codemark-calibrate-noise: warning: %s\n", w.c_str());

		char data[512];
		std::snprintf(
			data, sizeof data,
			"data: %s with map %s, %ld frames, %ld sightings at %.0f-%.0f px; EKF innovations' "
			"likelihood maximised (motion noise held at %s); mean NIS per DoF %.2f -> %.2f",
			req.rawlog.c_str(), req.map_file.c_str(), r.steps, r.sightings, r.width_min_px,
			r.width_max_px, req.config_file.c_str(),
			r.before.nis_dof > 0 ? r.before.nis_mean / r.before.nis_dof : 0.0,
			r.after.nis_dof > 0 ? r.after.nis_mean / r.after.nis_dof : 0.0);
		codemark::pose::saveCalibration(
			out.getValue(), r.fitted,
			{"codemark calibration: the sighting noise identified from a recorded run",
			 "made by: " + command, data, "the map's survey errors are absorbed into this noise",
			 "date: " + mrpt::system::dateTimeToString(mrpt::Clock::now())});
		std::printf("wrote %s\n", out.getValue().c_str());
		return 0;
	}
	catch (const TCLAP::ExitException& e)  // --help, --version
	{
		return e.getExitStatus();
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << codemark::app::argumentError("codemark-calibrate-noise", e) << "\n";
		return 2;
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-calibrate-noise: " << codemark::app::oneLine(e) << "\n";
		return 1;
	}
}
