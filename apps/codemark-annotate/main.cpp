// codemark-annotate: adds a codemark landmark observation after every camera
// image of an MRPT rawlog.
#include <codemark/landmark/text.h>
#include <codemark/pipeline/annotate.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/core/exceptions.h>
#include <tclap/CmdLine.h>

#include <fstream>
#include <iomanip>
#include <iostream>

#include "calibration.h"
#include "errors.h"
#include "progress.h"
#include "rawlog_check.h"

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd(
			"Runs codemark's detector and pose computation on every CObservationImage of an MRPT "
			"rawlog (actions-observations or observations-only format; embedded or external "
			"images, "
			"looked up in <input name>_Images/ beside the input) and writes a copy with a "
			"codemark::CObservationCodedLandmarks (label <CAM>_LANDMARKS, the image's timestamp "
			"and camera pose) right after each image. Open the output with the plugin: "
			"RawLogViewer -l libcodemark_mrpt.so, rawlog-edit -p libcodemark_mrpt.so. Any entry "
			"that cannot be read stops the run with its index and a non-zero exit.",
			' ', "0.1");
		TCLAP::ValueArg<std::string> in("i", "input", "input rawlog", true, "", "IN.rawlog", cmd);
		TCLAP::ValueArg<std::string> out(
			"o", "output", "output rawlog", true, "", "OUT.rawlog", cmd);
		TCLAP::ValueArg<std::string> camera(
			"", "camera",
			"camera file (MRPT ini or ROS/OpenCV YAML) replacing the intrinsics stored "
			"in the images",
			false, "", "CAM", cmd);
		TCLAP::ValueArg<std::string> landmark(
			"", "landmark",
			"landmark sizes ([LANDMARK] section; default share/codemark/landmark.ini)", false, "",
			"LM.ini", cmd);
		TCLAP::ValueArg<std::string> map(
			"", "map", "landmark map: each ID's scale column sets its size", false, "", "MAP.txt",
			cmd);
		TCLAP::ValueArg<std::string> config(
			"", "config",
			"ini with [DETECTOR] and [pose] sections (share/codemark/detector.ini "
			"keys; pose: method = ClosedForm|General6Dof, and noise-model keys overriding "
			"--calibration's)",
			false, "", "INI", cmd);
		auto calibration = codemark::app::calibrationArg(cmd);
		TCLAP::SwitchArg br(
			"", "bearing-range", "also insert the CObservationBearingRange twin (<CAM>_BR)", cmd);
		TCLAP::SwitchArg drop("", "drop-images", "leave the image observations out", cmd);
		TCLAP::ValueArg<int> threads(
			"", "threads", "worker threads (0: all cores)", false, 0, "N", cmd);
		TCLAP::SwitchArg quiet("q", "quiet", "no progress bar", cmd);
		cmd.setExceptionHandling(false);  // one-line errors, below
		cmd.parse(argc, argv);

		codemark::pipeline::AnnotateOptions o;
		o.bearing_range = br.getValue();
		o.drop_images = drop.getValue();
		o.threads = threads.getValue();
		if (threads.getValue() < 0) throw std::runtime_error("--threads must be >= 0");
		o.pipeline.pose = codemark::pipeline::calibratedPoseOptions(calibration.getValue());
		if (!camera.getValue().empty())
			o.pipeline.camera_override = codemark::CameraModel::load(camera.getValue());
		const std::string lm = landmark.getValue().empty() ? codemark::findShareFile("landmark.ini")
														   : landmark.getValue();
		if (!lm.empty())
		{
			if (!std::ifstream(lm).good()) throw std::runtime_error(lm + ": cannot open");
			try
			{
				mrpt::config::CConfigFile cfg(lm);
				o.pipeline.geometry.loadFromConfigFile(cfg, "LANDMARK");
			}
			catch (const std::exception&)
			{
				codemark::rethrowNamingIniFile(lm);
			}
		}
		if (!map.getValue().empty()) o.pipeline.map = codemark::LandmarkMap::load(map.getValue());
		if (!config.getValue().empty())
		{
			if (!std::ifstream(config.getValue()).good())
				throw std::runtime_error(config.getValue() + ": cannot open");
			try
			{
				mrpt::config::CConfigFile cfg(config.getValue());
				o.pipeline.detector.loadFromConfigFile(cfg, "DETECTOR");
				o.pipeline.pose.loadFromConfigFile(cfg, "pose");
			}
			catch (const std::exception&)
			{
				codemark::rethrowNamingIniFile(config.getValue());
			}
		}

		codemark::app::checkRawlogGzip(in.getValue());
		codemark::app::ProgressBar bar("codemark-annotate", !quiet.getValue());
		codemark::pipeline::AnnotateSummary s;
		try
		{
			s = codemark::pipeline::annotateRawlog(
				in.getValue(), out.getValue(), o, [&](long d, long t) { bar.update(d, t); });
		}
		catch (const std::exception& e)
		{
			// Errors about an image (decoder, missing file) may not name the rawlog.
			const std::string msg = codemark::app::oneLine(mrpt::exception_to_str(e));
			throw std::runtime_error(
				msg.find(in.getValue()) == std::string::npos ? in.getValue() + ": " + msg : msg);
		}
		bar.finish();
		if (s.images == 0)
			throw std::runtime_error(
				in.getValue() + ": no camera image (CObservationImage) in its " +
				std::to_string(s.entries) + " entries; nothing to annotate");
		std::cout << "codemark-annotate: " << s.entries << " entries ("
				  << (s.actions_observations ? "actions-observations" : "observations-only")
				  << " format), " << s.images << " images, " << s.detections
				  << " landmark sightings, detector " << std::fixed << std::setprecision(3)
				  << s.detect_ms_per_image << " ms/image, wall " << std::setprecision(1) << s.wall_s
				  << " s\n";
		std::cout << "sightings per ID:";
		for (const auto& [id, n] : s.per_id) std::cout << " " << id << ":" << n;
		std::cout << "\nwrote " << out.getValue() << "\n";
		return 0;
	}
	catch (const TCLAP::ExitException& e)  // --help, --version
	{
		return e.getExitStatus();
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << codemark::app::argumentError("codemark-annotate", e) << "\n";
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-annotate: error: "
				  << codemark::app::oneLine(mrpt::exception_to_str(e)) << "\n";
	}
	return 1;
}
