// codemark-simul: writes a simulated MRPT dataset (rawlog with external
// images, map, ground truth) from an ini file.
#include <codemark/landmark/text.h>
#include <codemark/sim/dataset.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/core/exceptions.h>
#include <tclap/CmdLine.h>

#include <fstream>
#include <iostream>

#include "errors.h"
#include "povray_args.h"
#include "preset.h"
#include "progress.h"

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd(
			"Writes a simulated dataset for codemark: a map (from a file, or a generated room with "
			"landmarks on its walls), a trajectory (from a file, or a generated loop), noisy "
			"odometry "
			"from MRPT's motion models, and rendered camera images with exact ground truth. Output "
			"in "
			"--out DIR: dataset.rawlog (MRPT actions-observations format: CActionRobotMovement2D + "
			"CSensoryFrame with a CObservationImage; or with --obs-only the observations-only "
			"format "
			"with CObservationOdometry at its own rate), the images in dataset_Images/ (MRPT's "
			"external-image convention), map.txt, gt_path.txt ('timestamp x y yaw' per image). "
			"Deterministic for a seed. See share/codemark/simul.ini for every setting.",
			' ', "0.1");
		TCLAP::ValueArg<std::string> config(
			"c", "config",
			"the dataset ini (sections [map] [trajectory] [odometry] [camera] [render] "
			"[dataset]); without it the built-in defaults (a 6 x 4 m room, 12 landmarks, one loop)",
			false, "", "INI", cmd);
		TCLAP::ValueArg<std::string> out(
			"o", "out", "output directory (created if missing)", true, "", "DIR", cmd);
		TCLAP::SwitchArg obsOnly("", "obs-only", "write the observations-only rawlog format", cmd);
		TCLAP::ValueArg<unsigned int> seed(
			"s", "seed", "override [dataset] seed", false, 0, "N", cmd);
		TCLAP::ValueArg<int> frames(
			"", "max-frames", "stop after N images (0: the whole trajectory)", false, 0, "N", cmd);
		TCLAP::ValueArg<std::string> preset(
			"", "preset", codemark::app::presetHelp() + " in [render]", false, "", "NAME", cmd);
		codemark::app::PovrayArgs pov(cmd);
		TCLAP::SwitchArg quiet("q", "quiet", "no progress bar", cmd);
		cmd.setExceptionHandling(false);  // one-line errors, below
		cmd.parse(argc, argv);

		codemark::sim::DatasetOptions opts;
		if (!config.getValue().empty() || preset.isSet())
		{
			if (!config.getValue().empty() && !std::ifstream(config.getValue()).good())
				throw std::runtime_error(config.getValue() + ": cannot open config file");
			const auto cfg =
				codemark::app::iniWithPreset(config.getValue(), "render", preset.getValue());
			try
			{
				opts.loadFromConfigFile(cfg, "");
			}
			catch (const std::exception&)
			{
				if (config.getValue().empty()) throw;
				codemark::rethrowNamingIniFile(config.getValue());
			}
		}
		if (seed.isSet()) opts.seed = seed.getValue();
		const codemark::sim::Renderer renderer = pov.make();
		codemark::app::ProgressBar bar("codemark-simul", !quiet.getValue());
		const auto sum = codemark::sim::writeDataset(
			opts, out.getValue(), obsOnly.getValue(),
			[&](int done, int total) { bar.update(done, total); }, frames.getValue(), renderer);
		bar.finish();
		std::cout << "codemark-simul: " << sum.frames << " images, " << sum.odometry_readings
				  << " odometry readings, " << sum.map.landmarks.size() << " landmarks, "
				  << sum.sightings << " landmark sightings in view; wrote " << out.getValue()
				  << "/dataset.rawlog\n";
		return 0;
	}
	catch (const TCLAP::ExitException& e)  // --help, --version
	{
		return e.getExitStatus();
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << codemark::app::argumentError("codemark-simul", e) << "\n";
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-simul: " << codemark::app::oneLine(mrpt::exception_to_str(e))
				  << "\n";
	}
	return 1;
}
