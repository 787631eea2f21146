/** \file main.cpp
 * codemark-detect: runs the landmark detector on images, folders of images
 * and videos, and prints one JSON object per image (docs/spec.md
 * section 5). Parses the command line and calls codemark::detect::detect().
 */
#include "calibration.h"
#include "errors.h"
#include <codemark/detect/colour.h>
#include <codemark/detect/detector.h>
#include <codemark/detect/json.h>
#include <codemark/pipeline/pipeline.h>
#include <codemark/pose/measurement.h>
#include <codemark/landmark/camera.h>
#include <mrpt/config/CConfigFile.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <tclap/CmdLine.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace codemark;

namespace
{
const std::vector<std::string> kImageExt = {".png",	 ".jpg", ".jpeg", ".bmp", ".tif",
											".tiff", ".pgm", ".ppm",  ".webp"};
const std::vector<std::string> kVideoExt = {".mp4",	 ".avi", ".mkv",  ".mov",
											".webm", ".mpg", ".mpeg", ".m4v"};

std::string lowerExt(const fs::path& p)
{
	std::string e = p.extension().string();
	std::transform(
		e.begin(), e.end(), e.begin(),
		[](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	return e;
}

bool hasExt(const fs::path& p, const std::vector<std::string>& exts)
{
	return std::find(exts.begin(), exts.end(), lowerExt(p)) != exts.end();
}

/** A name safe for a file: path separators and '#' replaced. */
std::string flatName(const std::string& s)
{
	std::string out = s;
	for (char& c : out)
		if (c == '/' || c == '\\' || c == '#' || c == ':') c = '_';
	while (!out.empty() && out[0] == '.') out.erase(0, 1);
	return out.empty() ? "image" : out;
}

std::string jsonVector(const Eigen::Vector3d& v)
{
	return "[" + detect::jsonNumber(v[0]) + ", " + detect::jsonNumber(v[1]) + ", " +
		   detect::jsonNumber(v[2]) + "]";
}

std::string jsonMatrix(const Eigen::Matrix3d& m)
{
	return "[" + jsonVector(m.row(0).transpose()) + ", " + jsonVector(m.row(1).transpose()) + ", " +
		   jsonVector(m.row(2).transpose()) + "]";
}

struct Runner
{
	CameraModel camera;
	/** The detector's, the pose library's options (the default calibration
	 * unless told otherwise), the landmark and the map's per-ID sizes. */
	pipeline::PipelineOptions pipe;
	std::string draw_dir, debug_dir;
	bool colour_report = false;
	int failures = 0;

	/** The colour report's readable table of one detection, on stderr. */
	void printColourTable(const std::string& name, int id, const detect::ColourReport& c) const
	{
		const auto& s = pipe.detector.segmentation;
		char buf[512];
		std::cerr << "codemark-detect: colours of landmark " << id << " in " << name << "\n";
		std::cerr << "            R      G      B   hue[deg]  sat      I\n";
		for (const auto& [label, m] :
			 {std::pair<const char*, const detect::MeasuredColour&>{"fill ", c.fill},
			  {"frame", c.frame}})
		{
			std::snprintf(
				buf, sizeof buf, "  %s %6.1f %6.1f %6.1f %8.1f %6.3f %6.1f\n", label, m.r, m.g, m.b,
				m.hue_deg, m.saturation, m.intensity);
			std::cerr << buf;
		}
		// One margin: its name, value, and the test it is the margin of
		// (\a rule with the threshold in place of its %g).
		const auto row = [&](const char* what, double margin, const char* rule, double threshold)
		{
			char test[96];
			std::snprintf(test, sizeof test, rule, threshold);
			std::snprintf(
				buf, sizeof buf, "  margin %-12s %+8.3f  (%s)%s\n", what, margin, test,
				margin < 0 ? "  FAILS" : "");
			std::cerr << buf;
		};
		row("intensity", c.margin_intensity, "fill I >= %g", s.min_intensity);
		row("saturation", c.margin_saturation, "fill S >= %g", s.min_saturation);
		row("hue min", c.margin_hue_min_deg, "fill hue >= %g deg", s.hue_min_deg);
		row("hue max", c.margin_hue_max_deg, "fill hue <= %g deg", s.hue_max_deg);
		row("black ratio", c.margin_black_ratio, "frame G / fill G <= %g",
			pipe.detector.code.max_black_ratio);
		row("contrast", c.margin_contrast, "fill G - frame G >= %g",
			pipe.detector.code.min_contrast);
	}

	void fail(const std::string& name, const std::string& why)
	{
		std::cout << detect::errorToJson(name, why) << std::endl;
		// The same one line on stderr, for people and scripts that watch it.
		std::cerr << "codemark-detect: " << name << ": " << why << "\n";
		++failures;
	}

	void process(const std::string& name, const cv::Mat& img)
	{
		if (img.empty() || img.type() != CV_8UC3)
		{
			fail(name, "not a colour image");
			return;
		}
		// Intrinsics are only valid for the resolution they were calibrated
		// at: another size would give a silently wrong P, L and pose.
		if (img.cols != camera.width() || img.rows != camera.height())
		{
			fail(
				name, "image is " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
						  " but the camera is " + std::to_string(camera.width()) + "x" +
						  std::to_string(camera.height()) +
						  ": pass --camera with this image's calibration");
			return;
		}
		std::string dbg;
		if (!debug_dir.empty())
		{
			dbg = (fs::path(debug_dir) / flatName(name)).string();
			fs::create_directories(dbg);
		}
		pipeline::ImageResult res;
		try
		{
			res = pipeline::processImage(img, camera, pipe, dbg);
		}
		catch (const std::exception& e)
		{
			// One error line for this input (e.g. out of memory on a huge
			// frame); the run goes on.
			fail(name, std::string("detection failed: ") + e.what());
			return;
		}
		// Each measured detection with L, C_L, pose_in_landmark and C_R
		// (spec section 5), then those whose corners gave no measurement.
		std::vector<detect::DetectedLandmark> dets;
		std::vector<detect::JsonFields> extra;
		for (const auto& lm : res.landmarks)
		{
			const auto& d = lm.detected;
			const auto& m = lm.measurement;
			detect::JsonFields f;
			f.emplace_back("L", jsonVector(m.L));
			f.emplace_back("C_L", jsonMatrix(m.C_L));
			f.emplace_back("pose_in_landmark", jsonVector(m.pose_in_landmark));
			f.emplace_back("C_R", jsonMatrix(m.C_R));
			// The mirror-image optimum folded into C_L and C_R (PoseOptions::
			// fold_ambiguity), when there is one: its probability and L.
			if (m.second_mode_weight > 0)
			{
				f.emplace_back("second_mode_weight", detect::jsonNumber(m.second_mode_weight));
				f.emplace_back("second_mode_L", jsonVector(m.second_mode_L));
			}
			if (colour_report)
			{
				const auto c = detect::colourReport(
					img, d.detection, camera, pipeline::geometryFor(d.detection.id, pipe),
					pipe.detector);
				f.emplace_back("fill_colour", detect::colourReportJson(c));
				printColourTable(name, d.detection.id, c);
			}
			dets.push_back(d);
			extra.push_back(std::move(f));
		}
		for (const auto& d : res.unmeasured)
		{
			dets.push_back(d);
			extra.emplace_back();
		}
		std::cout << detect::imageToJson(
						 name, img.cols, img.rows, res.timings.total_us / 1000.0, dets, extra)
				  << std::endl;
		if (!draw_dir.empty())
		{
			cv::Mat ov = img.clone();
			detect::drawDetections(ov, dets);
			const std::string out = (fs::path(draw_dir) / (flatName(name) + ".png")).string();
			if (!cv::imwrite(out, ov)) std::cerr << "warning: cannot write " << out << "\n";
		}
	}

	void image(const std::string& path)
	{
		cv::Mat img;
		try
		{
			img = cv::imread(path, cv::IMREAD_UNCHANGED);
		}
		catch (const std::exception& e)
		{
			fail(path, std::string("cannot read the image: ") + e.what());
			return;
		}
		if (img.empty())
		{
			fail(path, "cannot read the image (missing, empty, unreadable or not an image)");
			return;
		}
		// Refuse rather than silently rescale or invent colour: the detector
		// segments the green fill in 8-bit colour.
		if (img.depth() != CV_8U)
		{
			fail(
				path, "the image has " + std::to_string(8 * img.elemSize1()) +
						  "-bit samples; codemark needs 8-bit colour images");
			return;
		}
		if (img.channels() == 1)
		{
			fail(path, "grey image; codemark needs colour images (it segments the green fill)");
			return;
		}
		if (img.channels() == 4) cv::cvtColor(img, img, cv::COLOR_BGRA2BGR);
		process(path, img);
	}

	void video(const std::string& path)
	{
		cv::VideoCapture cap(path);
		if (!cap.isOpened())
		{
			fail(path, "cannot open the video");
			return;
		}
		cv::Mat frame;
		for (int i = 0;; ++i)
		{
			if (!cap.read(frame) || frame.empty())
			{
				if (i == 0) fail(path, "the video has no readable frame");
				break;
			}
			cv::Mat bgr = frame;
			if (frame.channels() == 1) cv::cvtColor(frame, bgr, cv::COLOR_GRAY2BGR);
			process(path + "#" + std::to_string(i), bgr);
		}
	}

	void input(const std::string& arg)
	{
		std::error_code ec;
		if (fs::is_directory(arg, ec))
		{
			std::vector<fs::path> files;
			for (const auto& e : fs::directory_iterator(arg, ec))
				if (e.is_regular_file() && hasExt(e.path(), kImageExt)) files.push_back(e.path());
			std::sort(files.begin(), files.end());
			if (files.empty()) std::cerr << "warning: no image in folder " << arg << "\n";
			for (const auto& f : files) image(f.string());
		}
		else if (hasExt(arg, kVideoExt))
			video(arg);
		else
			image(arg);
	}
};
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd(
			"Detects coded landmarks (docs/spec.md) in images with the detector of Baczyk, "
			"Kasinski and Skrzypczynski (2003) and prints one JSON object per image on its own "
			"line (spec section 5): {\"image\", \"width\", \"height\", \"time_ms\", "
			"\"detections\": "
			"[{\"id\", \"corners\" (inner frame corners in raw pixels, TL TR BR BL as they appear "
			"in "
			"the image, pixel (0,0) at the centre of the top-left pixel), \"P\" ([x1 y1 x2 y2] "
			"from "
			"the undistorted corners)}]}. time_ms is the detector's own time, without file "
			"decoding. An input that cannot be read gives {\"image\", \"error\"} and the run goes "
			"on; the exit code is 1 at the end if any input failed.",
			' ', "0.1.0");
		TCLAP::ValueArg<std::string> camera_arg(
			"", "camera",
			"Camera intrinsics: MRPT [CAMERA_PARAMS] ini (.ini/.cfg/.txt, e.g. from camera-calib) "
			"or "
			"ROS/OpenCV calibration YAML (.yaml/.yml). Distortion is taken into account for the "
			"line fits and P. Default: share/codemark/camera-paper.ini (640x480, fx = fy = 800).",
			false, "", "CAM", cmd);
		TCLAP::ValueArg<std::string> landmark_arg(
			"", "landmark",
			"Landmark sizes: ini file with a [LANDMARK] section (share/codemark/landmark.ini). "
			"Only the proportions matter to the detector. Default: the spec's A4 landmark.",
			false, "", "LM.ini", cmd);
		TCLAP::ValueArg<std::string> config_arg(
			"", "config",
			"Detector parameters: ini file with a [DETECTOR] section (share/codemark/detector.ini "
			"lists every parameter with its default and unit), and optionally a [pose] section "
			"(method = ClosedForm|General6Dof, and any key of the noise model, which overrides "
			"--calibration's). Default: the built-in defaults.",
			false, "", "detector.ini", cmd);
		auto calibration_arg = app::calibrationArg(cmd);
		TCLAP::ValueArg<std::string> map_arg(
			"", "map",
			"landmark map (docs/spec.md section 3): each ID in it is measured at its printed "
			"scale; other IDs at the landmark file's size",
			false, "", "MAP.txt", cmd);
		TCLAP::ValueArg<std::string> draw_arg(
			"", "draw",
			"Folder (created when missing) that receives one overlay PNG per image: the "
			"detected frame, corners (top-left marked), ID and the landmark's axes.",
			false, "", "DIR", cmd);
		TCLAP::ValueArg<std::string> debug_arg(
			"", "debug-dir",
			"Folder (created when missing) that receives per image a sub-folder with the "
			"detector's stage images: colour mask, components, edgels, fitted lines (in "
			"magenta the quadrangles refused because their centre cell reads green), overlay.",
			false, "", "DIR", cmd);
		TCLAP::SwitchArg colour_arg(
			"", "colour-report",
			"Measure each detected landmark's fill and frame colours: adds \"fill_colour\" to "
			"each detection ({\"fill\", \"frame\": {\"rgb\", \"hue_deg\", \"saturation\", "
			"\"intensity\", \"samples\"}, \"margins\": {\"intensity\", \"saturation\", "
			"\"hue_min_deg\", \"hue_max_deg\", \"black_ratio\", \"contrast\"}}; a margin is "
			"the distance to the detector's threshold, negative where that test fails) and "
			"prints a table per landmark on stderr. Check a print under your light with it "
			"before recording.",
			cmd);
		TCLAP::UnlabeledMultiArg<std::string> inputs_arg(
			"inputs",
			"Image files, folders (every image inside, sorted by name; not recursive) or video "
			"files (.mp4, .avi, .mkv, ...; frames named VIDEO#N, N from 0).",
			true, "INPUT", cmd);
		// Our own one-line error per unreadable input replaces OpenCV's
		// decoder warnings on stderr.
		cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
		cmd.setExceptionHandling(false);  // one-line errors, below
		cmd.parse(argc, argv);

		// Single-threaded: time_ms is the detector's own, comparable figure.
		cv::setNumThreads(1);
		Runner r;
		r.camera = camera_arg.isSet() ? CameraModel::load(camera_arg.getValue())
									  : CameraModel::paperDefault();
		if (landmark_arg.isSet())
		{
			const std::string& path = landmark_arg.getValue();
			if (!std::ifstream(path).good())
				throw std::runtime_error(path + ": cannot open the landmark file");
			mrpt::config::CConfigFile cfg(path);
			if (!cfg.sectionExists("LANDMARK"))
				throw std::runtime_error(path + ": no [LANDMARK] section");
			try
			{
				r.pipe.geometry.loadFromConfigFile(cfg, "LANDMARK");
			}
			catch (const std::exception& e)
			{
				throw std::runtime_error(path + ": " + e.what());
			}
		}
		r.pipe.pose = pipeline::calibratedPoseOptions(calibration_arg.getValue());
		if (map_arg.isSet()) r.pipe.map = LandmarkMap::load(map_arg.getValue());
		if (config_arg.isSet())
		{
			r.pipe.detector = detect::DetectorOptions::load(config_arg.getValue());
			mrpt::config::CConfigFile cfg(config_arg.getValue());
			if (cfg.sectionExists("pose")) r.pipe.pose.loadFromConfigFile(cfg, "pose");
		}
		r.draw_dir = draw_arg.getValue();
		r.debug_dir = debug_arg.getValue();
		r.colour_report = colour_arg.getValue();
		// The inputs take every word TCLAP does not know: a mistyped option
		// (no file of that name) is one, not an unreadable image.
		for (const auto& in : inputs_arg.getValue())
			if (std::error_code ec; in.size() > 1 && in[0] == '-' && !fs::exists(in, ec))
				throw TCLAP::CmdLineParseException("Couldn't find match for argument", in);
		if (!r.draw_dir.empty()) codemark::createFolder(r.draw_dir, "the --draw folder");
		if (!r.debug_dir.empty()) codemark::createFolder(r.debug_dir, "the --debug-dir folder");
		// Warm up once, so that the first image's time_ms does not carry
		// OpenCV's one-time initialisation and the detector's colour table.
		{
			cv::Mat warm(64, 64, CV_8UC3, cv::Scalar(235, 235, 235));
			cv::rectangle(warm, cv::Rect(12, 12, 40, 40), cv::Scalar(25, 25, 25), cv::FILLED);
			cv::rectangle(warm, cv::Rect(16, 16, 32, 32), cv::Scalar(0, 255, 0), cv::FILLED);
			detect::detect(warm, r.camera, r.pipe.geometry, r.pipe.detector);
		}
		for (const auto& in : inputs_arg.getValue()) r.input(in);
		return r.failures ? 1 : 0;
	}
	catch (const TCLAP::ExitException& e)  // --help, --version
	{
		return e.getExitStatus();
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << codemark::app::argumentError("codemark-detect", e) << "\n";
		return 2;
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-detect: error: " << codemark::app::oneLine(e) << "\n";
		return 1;
	}
}
