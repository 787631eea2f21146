// codemark-render: renders camera frames of a landmark map with exact ground
// truth (the demo's render step). A thin main over codemark::sim.
#include <codemark/landmark/text.h>
#include <codemark/sim/frames.h>
#include <codemark/sim/render.h>
#include <mrpt/config/CConfigFile.h>
#include <tclap/CmdLine.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "errors.h"
#include "povray_args.h"
#include "preset.h"
#include "progress.h"

namespace
{
/** The demo's look: a wall with a few distractors, mild noise and blur. */
codemark::sim::RenderOptions demoOptions()
{
	codemark::sim::RenderOptions o;
	o.background = codemark::sim::Background::Cluttered;
	o.distractors = 6;
	o.noise_sigma = 2.0;
	o.blur_sigma_px = 0.8;
	return o;
}

}  // namespace

int main(int argc, char** argv)
{
	namespace fs = std::filesystem;
	using namespace codemark;
	using app::oneLine;
	try
	{
		TCLAP::CmdLine cmd(
			"Renders camera frames of the landmarks of a map with exact ground truth. Writes into "
			"--out DIR: frame_000.png, frame_001.png, ...; truth.jsonl (one JSON object per frame: "
			"image, width, height, camera_pose [x y z yaw pitch roll] of the camera body frame "
			"(x forward, y left, z up; m, rad), and for every landmark in view: id, corners (the "
			"four "
			"inner frame corners in raw pixels, TL TR BR BL), P, L, pose_in_landmark, "
			"fully_visible, "
			"area_px, occluded_fraction); camera.ini (the camera used, MRPT [CAMERA_PARAMS]); "
			"render.ini (the render options used, section [RENDER]). Deterministic for a seed.",
			' ', "0.1");
		TCLAP::ValueArg<std::string> mapArg(
			"m", "map", "landmark map file ('id x y z yaw_deg [scale]' per line)", true, "",
			"MAP.txt", cmd);
		TCLAP::ValueArg<std::string> outArg(
			"o", "out", "output directory (created if missing)", true, "", "DIR", cmd);
		TCLAP::ValueArg<std::string> cameraArg(
			"c", "camera",
			"camera file: MRPT [CAMERA_PARAMS] .ini or ROS/OpenCV calibration .yaml; default: the "
			"paper's camera (share/codemark/camera-paper.ini: 640x480, f = 800 px, no distortion)",
			false, "", "CAM.ini|yaml", cmd);
		TCLAP::ValueArg<std::string> posesArg(
			"p", "poses",
			"camera poses, one frame per line: 'x y z yaw pitch roll' (m, deg) of the camera body "
			"frame (x forward, y left, z up) in the world, '#' comments. Default: --frames level "
			"poses that look at the map's landmarks in turn",
			false, "", "POSES.txt", cmd);
		TCLAP::ValueArg<int> framesArg(
			"n", "frames", "number of generated poses without --poses (default 8)", false, 8, "N",
			cmd);
		TCLAP::ValueArg<uint64_t> seedArg(
			"s", "seed", "seed of the generated poses and of the renderer's randomness (default 1)",
			false, 1, "S", cmd);
		TCLAP::ValueArg<std::string> optionsArg(
			"", "options",
			"render options ini (keys of codemark::sim::RenderOptions: background = Flat|Textured|"
			"Cluttered, distractors, noise_sigma, blur_sigma_px, motion_blur_px, jpeg_quality, "
			"gain, "
			"gradient, occlusion, preset and the camera pipeline's stage keys: "
			"docs/camera-pipeline.md). Keys not given keep the demo defaults: Cluttered (texture "
			"with "
			"6 distractors), noise_sigma 2, blur_sigma_px 0.8",
			false, "", "RENDER.ini", cmd);
		TCLAP::ValueArg<std::string> presetArg(
			"", "preset", app::presetHelp(), false, "", "NAME", cmd);
		TCLAP::ValueArg<std::string> sectionArg(
			"", "section", "section of --options to read (default RENDER)", false, "RENDER", "NAME",
			cmd);
		TCLAP::ValueArg<double> minDistArg(
			"", "min-distance",
			"generated poses: least horizontal distance to the landmark [m] (default 0.8)", false,
			0.8, "M", cmd);
		TCLAP::ValueArg<double> maxDistArg(
			"", "max-distance", "generated poses: greatest horizontal distance [m] (default 4)",
			false, 4.0, "M", cmd);
		TCLAP::ValueArg<double> maxAngleArg(
			"", "max-angle",
			"generated poses: greatest view angle from the landmark's normal [deg] (default 50)",
			false, 50.0, "DEG", cmd);
		TCLAP::ValueArg<double> heightArg(
			"", "height", "generated poses: camera height in the world [m] (default 0.6)", false,
			0.6, "M", cmd);
		TCLAP::SwitchArg quietArg("q", "quiet", "no progress indication on stderr", cmd);
		app::PovrayArgs povArgs(cmd);
		TCLAP::SwitchArg linearArg(
			"", "linear",
			"with --renderer povray: also write linear_000.png, ... (POV-Ray's 16-bit linear "
			"renders, before the camera pipeline) and povray.ini (the POV-Ray options used)",
			cmd);
		cmd.setExceptionHandling(false);  // one-line errors, below
		cmd.parse(argc, argv);

		const LandmarkMap map = LandmarkMap::load(mapArg.getValue());
		if (map.landmarks.empty())
			throw std::runtime_error(mapArg.getValue() + ": the map has no landmarks");
		CameraModel camera;
		try
		{
			camera = cameraArg.isSet() ? CameraModel::load(cameraArg.getValue())
									   : CameraModel::paperDefault();
		}
		catch (const std::exception& e)
		{
			const std::string msg = oneLine(e.what());
			const std::string file =
				cameraArg.isSet() ? cameraArg.getValue() : "the default camera";
			throw std::runtime_error(msg.find(file) == std::string::npos ? file + ": " + msg : msg);
		}

		sim::RenderOptions options = demoOptions();
		if (optionsArg.isSet() || presetArg.isSet())
		{
			if (optionsArg.isSet() && !std::ifstream(optionsArg.getValue()).good())
				throw std::runtime_error(
					optionsArg.getValue() + ": cannot open render options file");
			const auto cfg = app::iniWithPreset(
				optionsArg.getValue(), sectionArg.getValue(), presetArg.getValue());
			try
			{
				options.loadFromConfigFile(cfg, sectionArg.getValue());
			}
			catch (const std::exception&)
			{
				if (!optionsArg.isSet()) throw;
				rethrowNamingIniFile(optionsArg.getValue());
			}
		}

		std::vector<mrpt::poses::CPose3D> poses;
		if (posesArg.isSet())
			poses = sim::loadCameraPoses(posesArg.getValue());
		else
		{
			if (framesArg.getValue() < 1) throw std::runtime_error("--frames must be at least 1");
			sim::ViewpointOptions vp;
			vp.min_distance_m = minDistArg.getValue();
			vp.max_distance_m = maxDistArg.getValue();
			vp.max_view_angle_rad = maxAngleArg.getValue() * M_PI / 180;
			vp.camera_height_m = heightArg.getValue();
			poses =
				sim::viewpointsAroundLandmarks(map, framesArg.getValue(), seedArg.getValue(), vp);
		}

		const fs::path out(outArg.getValue());
		fs::create_directories(out);
		{
			std::ofstream cam(out / "camera.ini");
			cam << camera.toIniText();
			if (!cam) throw std::runtime_error((out / "camera.ini").string() + ": cannot write");
		}
		{
			mrpt::config::CConfigFile cfg((out / "render.ini").string());
			options.saveToConfigFile(cfg, "RENDER");
		}
		if (povArgs.povray() && linearArg.getValue())
		{
			mrpt::config::CConfigFile cfg((out / "povray.ini").string());
			povArgs.options().saveToConfigFile(cfg, "povray");
		}
		const sim::Renderer renderer = povArgs.make();
		std::ofstream truth(out / "truth.jsonl");
		if (!truth) throw std::runtime_error((out / "truth.jsonl").string() + ": cannot write");

		sim::Scene scene;
		scene.map = map;
		scene.camera = camera;
		app::ProgressBar bar("codemark-render", !quietArg.getValue());
		int in_view = 0;
		for (size_t i = 0; i < poses.size(); ++i)
		{
			scene.world_T_camera = poses[i];
			const uint64_t frame_seed = seedArg.getValue() * 1000003ull + i;
			const sim::Render r = renderer(scene, options, frame_seed);
			char name[32];
			std::snprintf(name, sizeof(name), "frame_%03zu.png", i);
			if (!cv::imwrite((out / name).string(), r.image))
				throw std::runtime_error((out / name).string() + ": cannot write image");
			if (linearArg.getValue())
			{
				char linear[32];
				std::snprintf(linear, sizeof(linear), "linear_%03zu.png", i);
				povArgs.saveLinear(scene, options, frame_seed, (out / linear).string());
			}
			truth << sim::frameTruthJson(name, scene.world_T_camera, r.truth, camera) << '\n';
			for (const auto& t : r.truth) in_view += sim::isInView(t, camera);
			bar.update(static_cast<long>(i + 1), static_cast<long>(poses.size()));
		}
		bar.finish();
		if (!truth.flush())
			throw std::runtime_error((out / "truth.jsonl").string() + ": cannot write");
		std::cout << "codemark-render: " << poses.size() << " frames, " << in_view
				  << " landmark sightings in view; wrote " << out.string()
				  << "/{frame_*.png,truth.jsonl,camera.ini,render.ini}\n";
		return 0;
	}
	catch (const TCLAP::ExitException& e)  // --help, --version
	{
		return e.getExitStatus();
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << codemark::app::argumentError("codemark-render", e) << "\n";
		return 1;
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-render: error: " << oneLine(e.what()) << "\n";
		return 1;
	}
}
