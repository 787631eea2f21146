/** \file main.cpp
 * codemark-accuracy-map: the paper's Figs. 5-8 on renders. Parses
 * the command line and calls the survey in accuracy_map.h.
 */
#include <tclap/CmdLine.h>

#include <exception>
#include <iostream>

#include <codemark/pipeline/pipeline.h>
#include <codemark/sim/render.h>

#include "../common/calibration.h"
#include "../common/povray_args.h"
#include "../common/progress.h"
#include "accuracy_map.h"

int main(int argc, char** argv)
{
	namespace ca = codemark::accuracy;
	try
	{
		TCLAP::CmdLine cmd(
			"Renders the survey grid of the paper's section 4 (one half plane in front of a "
			"landmark: cells of --cell m, 0.5-5 m, view angles up to 70 deg; a level camera at the "
			"landmark centre's height looking at it), detects the landmark, measures it with the "
			"closed form and the general 6-DoF path, and writes heat maps of the mean absolute "
			"errors of l2, phi2, x and y beside the predicted sigma (heat_*.png), cells.csv and "
			"summary.txt (the table against the paper's claims) into --out. With AprilTag 3 "
			"(tag36h11, same corner-square size) at the same poses as a comparison column.",
			' ', "0.1.0");
		TCLAP::ValueArg<std::string> out_arg(
			"", "out", "Output folder (created).", true, "", "DIR", cmd);
		TCLAP::ValueArg<std::string> detector_arg(
			"", "detector-config",
			"codemark's detector options (share/codemark/detector.ini's format). Default: the "
			"built-in defaults.",
			false, "", "FILE", cmd);
		TCLAP::ValueArg<std::string> camera_arg(
			"", "camera",
			"Camera file (MRPT ini or YAML). Default: the paper's camera. The AprilTag column "
			"ignores lens distortion.",
			false, "", "FILE", cmd);
		TCLAP::ValueArg<int> renders_arg(
			"", "renders", "Noisy renders per cell. Default 5.", false, 5, "N", cmd);
		TCLAP::ValueArg<double> cell_arg(
			"", "cell", "Grid step [m]. Default 0.5.", false, 0.5, "M", cmd);
		TCLAP::ValueArg<double> maxd_arg(
			"", "max-distance", "Farthest cell [m]. Default 5.", false, 5.0, "M", cmd);
		TCLAP::ValueArg<double> noise_arg(
			"", "noise", "Render noise sigma [grey levels]. Default 2.", false, 2.0, "S", cmd);
		TCLAP::ValueArg<double> blur_arg(
			"", "blur", "Render blur sigma [px]. Default 0.8.", false, 0.8, "PX", cmd);
		TCLAP::ValueArg<double> sigma_arg(
			"", "sigma-px",
			"A constant sigma of each component of P for the predicted covariances [px] (the "
			"spec's diagonal C_P). Default: the size-dependent C_P of --calibration.",
			false, 0, "PX", cmd);
		TCLAP::ValueArg<std::string> sigma_source_arg(
			"", "sigma-source",
			"Fixed (--sigma-px) or Detector (the detector's per-detection corner sigma). Default "
			"Fixed.",
			false, "Fixed", "NAME", cmd);
		TCLAP::ValueArg<std::string> calibration_arg(
			"", "calibration",
			"C_P model: a calibration file (docs/calibration.md), the name of a shipped one "
			"(share/codemark/calibration/: plain, fitted on the plain background this map "
			"renders by default; realistic, fitted on the textured, lit walls of --realistic; "
			"family, the tools' default, fitted through the camera presets), or scene (the one "
			"fitted on the scene rendered). Default "
			"scene.",
			false, "scene", "FILE|NAME", cmd);
		TCLAP::SwitchArg paper_arg(
			"", "paper-closed-form",
			"The closed-form column uses the paper's formulas alone, without the weighted "
			"least-squares refinement on P (PoseOptions::refine_on_primary, on by default).",
			cmd, false);
		TCLAP::SwitchArg fold_arg(
			"", "fold-ambiguity",
			"Both paths weigh the mirror-image solution against the kept one and fold it into "
			"C_L and C_R (PoseOptions::fold_ambiguity; the default, kept for old command lines).",
			cmd, false);
		TCLAP::SwitchArg no_fold_arg(
			"", "no-fold-ambiguity",
			"Each path reports its kept solution's local C_L and C_R alone (PoseOptions::"
			"fold_ambiguity off): the far, square-on cells then show the mirror image's cost.",
			cmd, false);
		TCLAP::ValueArg<std::string> preset_arg(
			"", "preset",
			"Camera preset of codemark's renders (linear, machine-vision, webcam, phone, family: "
			"docs/camera-pipeline.md), in place of --noise and --blur.",
			false, "", "NAME", cmd);
		codemark::app::PovrayArgs pov(cmd);
		TCLAP::SwitchArg realistic_arg(
			"", "realistic",
			"Render codemark's landmark in the realistic scene the C_P calibration was fitted "
			"on (textured wall, light gradient, distractors) instead of the plain background "
			"(the AprilTag renders keep theirs; use with --no-apriltag for a like-for-like "
			"comparison).",
			cmd, false);
		TCLAP::ValueArg<double> aim_arg(
			"", "aim-jitter",
			"Each render aims the camera off the landmark by a bearing drawn within +-RAD (a "
			"landmark dead centre in the image mirrors its edges' pixel phases, whose biases then "
			"cancel). 0 with --height-jitter 0: exactly centred. Default 0.15.",
			false, 0.15, "RAD", cmd);
		TCLAP::ValueArg<double> height_arg(
			"", "height-jitter",
			"Each render puts the camera up to M above or below the landmark's centre. Default "
			"0.2.",
			false, 0.2, "M", cmd);
		TCLAP::SwitchArg no_tag_arg("", "no-apriltag", "Skip the AprilTag comparison.", cmd, false);
		TCLAP::ValueArg<unsigned long> seed_arg(
			"", "seed", "First render seed. Default 1.", false, 1, "N", cmd);
		cmd.setExceptionHandling(false);
		cmd.parse(argc, argv);

		ca::SurveyOptions o;
		o.renders_per_cell = renders_arg.getValue();
		o.cell_m = cell_arg.getValue();
		o.max_distance_m = maxd_arg.getValue();
		o.noise_sigma = noise_arg.getValue();
		o.blur_sigma_px = blur_arg.getValue();
		std::string calibration = calibration_arg.getValue();
		if (calibration == "scene") calibration = realistic_arg.getValue() ? "realistic" : "plain";
		o.pose = codemark::pipeline::calibratedPoseOptions(calibration);
		o.noise_label = "calibration " + calibration;
		if (sigma_arg.isSet())
		{
			o.pose = codemark::pose::PoseOptions();
			o.pose.sigma_px = sigma_arg.getValue();
			o.noise_label = "constant sigma_px " + std::to_string(sigma_arg.getValue());
		}
		o.apriltag = !no_tag_arg.getValue();
		if (!detector_arg.getValue().empty())
			o.detector = codemark::detect::DetectorOptions::load(detector_arg.getValue());
		if (paper_arg.getValue()) o.pose.refine_on_primary = false;
		if (fold_arg.getValue() && no_fold_arg.getValue())
			throw std::invalid_argument(
				"--fold-ambiguity and --no-fold-ambiguity exclude each other");
		o.pose.fold_ambiguity = !no_fold_arg.getValue();
		o.realistic = realistic_arg.getValue();
		if (pov.povray())
		{
			o.renderer = pov.make();
			o.source_label = "POV-Ray (docs/povray.md)";
		}
		if (preset_arg.isSet())
		{
			(void)codemark::sim::RenderOptions::presetKeys(preset_arg.getValue());
			o.preset = preset_arg.getValue();
		}
		o.pose.sigma_source = codemark::pose::sigmaSourceFromString(sigma_source_arg.getValue());
		if (o.pose.sigma_source == codemark::pose::SigmaSource::Detector)
			o.noise_label = "the detector's per-detection corner sigma";
		o.seed = seed_arg.getValue();
		o.aim_jitter_rad = aim_arg.getValue();
		o.height_jitter_m = height_arg.getValue();
		if (!(o.aim_jitter_rad >= 0 && o.aim_jitter_rad < 0.5) ||
			!(o.height_jitter_m >= 0 && o.height_jitter_m < 2))
			throw std::invalid_argument(
				"--aim-jitter must lie in [0, 0.5) rad and --height-jitter in [0, 2) m");
		if (o.renders_per_cell < 1 || !(o.cell_m > 0) || !(o.max_distance_m > 0) ||
			!(o.pose.sigma_px > 0) || o.noise_sigma < 0 || o.blur_sigma_px < 0)
			throw std::invalid_argument(
				"--renders >= 1, --cell, --max-distance, --sigma-px > 0, --noise, --blur >= 0");
		const codemark::CameraModel camera =
			camera_arg.getValue().empty() ? codemark::CameraModel::paperDefault()
										  : codemark::CameraModel::load(camera_arg.getValue());
		codemark::app::ProgressBar bar("accuracy-map");
		const auto cells = ca::runSurvey(camera, o, [&](long d, long t) { bar.update(d, t); });
		bar.finish();
		std::cout << ca::writeResults(cells, o, out_arg.getValue());
		return 0;
	}
	catch (const TCLAP::ExitException& e)
	{
		return e.getExitStatus();
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << "codemark-accuracy-map: error: " << e.argId() << ": " << e.error()
				  << " (see --help)\n";
		return 1;
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-accuracy-map: error: " << e.what() << "\n";
		return 1;
	}
}
