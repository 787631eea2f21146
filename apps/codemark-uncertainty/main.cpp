/** \file main.cpp
 * codemark-uncertainty: the predicted uncertainty of a landmark fix before
 * anything is printed or imaged (paper section 3, Fig. 3). Parses the
 * command line and calls codemark::pose (uncertainty.h).
 */
#include <codemark/eval/uncertainty_figure.h>
#include <codemark/pose/uncertainty.h>
#include "calibration.h"
#include "errors.h"

#include <tclap/CmdLine.h>

#include <cmath>
#include <exception>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace
{
std::pair<double, double> parsePair(const std::string& s, const std::string& what)
{
	std::istringstream in(s);
	double a = 0, b = 0;
	char comma = 0;
	if (!(in >> a >> comma >> b) || comma != ',' || !(in >> std::ws).eof())
		throw std::invalid_argument(what + ": expected two numbers A,B, got '" + s + "'");
	return {a, b};
}
}  // namespace

int main(int argc, char** argv)
{
	namespace cp = codemark::pose;
	try
	{
		TCLAP::CmdLine cmd(
			"Predicted uncertainty of one landmark fix (the paper's closed form and first-order "
			"propagation; level camera). Draws the paper's Fig. 3 (95% position ellipses and "
			"heading wedges on a grid of robot positions in front of a landmark) with --out; "
			"answers which landmark scale to print for a wanted accuracy with --size-for; prints "
			"the accuracy of a given --scale across distances with --table. Without any of these "
			"it draws the figure to uncertainty.png.",
			' ', "0.1.0");
		TCLAP::ValueArg<std::string> camera_arg(
			"", "camera",
			"Camera file: MRPT [CAMERA_PARAMS] ini or ROS/OpenCV YAML. Default: the paper's "
			"camera (640x480, fx = fy = 800 px).",
			false, "", "FILE", cmd);
		TCLAP::ValueArg<double> sigma_arg(
			"", "sigma-px",
			"Standard deviation of each component of P = [x1 y1 x2 y2] [px] (the paper used "
			"1 px). Default: the library's default (" +
				std::to_string(cp::kDefaultSigmaPx) + ").",
			false, cp::kDefaultSigmaPx, "PX", cmd);
		TCLAP::ValueArg<std::string> calibration_arg(
			"", "calibration",
			"Predict with the size-dependent C_P of a calibration (a file, docs/calibration.md, "
			"or the name of a shipped one: " +
				codemark::app::shippedNames() + "; the tools measure with " +
				codemark::pipeline::kDefaultCalibration +
				") in place of --sigma-px's constant one.",
			false, "", "FILE|NAME", cmd);
		TCLAP::ValueArg<double> scale_arg(
			"", "scale",
			"Landmark scale for --out and --table (1 = the A4 landmark, 160 mm reference square). "
			"Default 1.",
			false, 1.0, "S", cmd);
		TCLAP::ValueArg<std::string> out_arg(
			"", "out", "Write the Fig. 3 PNG here.", false, "", "PNG", cmd);
		TCLAP::ValueArg<double> xmax_arg(
			"", "max-distance",
			"Figure: farthest grid row along the landmark's normal [m]; table: farthest distance. "
			"Default 3 (figure) / 5 (table).",
			false, 0, "M", cmd);
		TCLAP::ValueArg<double> mag_arg(
			"", "ellipse-scale",
			"Figure: magnification of the ellipses and heading wedges; 0 = automatic. Default 0.",
			false, 0, "K", cmd);
		TCLAP::ValueArg<double> hmag_arg(
			"", "heading-scale",
			"Figure: magnification of the heading wedges; 0 = automatic. Default 0.", false, 0, "K",
			cmd);
		TCLAP::ValueArg<std::string> size_for_arg(
			"", "size-for",
			"Wanted accuracy ACC_M,ACC_DEG (e.g. 0.02,1): prints the smallest landmark scale "
			"whose k-sigma position error (worst direction) and heading error are within it at "
			"--distance and --angle.",
			false, "", "ACC_M,ACC_DEG", cmd);
		TCLAP::ValueArg<double> distance_arg(
			"", "distance", "Distance from the camera to the landmark centre for --size-for [m].",
			false, 0, "D", cmd);
		TCLAP::ValueArg<double> angle_arg(
			"", "angle",
			"Angle between the line of sight and the landmark's normal for --size-for and "
			"--table [deg]. Default 0.",
			false, 0, "DEG", cmd);
		TCLAP::ValueArg<double> k_arg(
			"", "k-sigma",
			"--size-for: how many sigmas must fit in the wanted accuracy. Default 2 (about 95% "
			"for one coordinate).",
			false, 2.0, "K", cmd);
		TCLAP::ValueArg<double> min_size_arg(
			"", "min-size-px",
			"Smallest reference square (vertical, px) the detector can use. Default 30.", false,
			30.0, "PX", cmd);
		TCLAP::SwitchArg table_arg(
			"", "table",
			"Print the accuracy of --scale at distances 0.5, 1, ... --max-distance (default 5 m).",
			cmd, false);
		cmd.setExceptionHandling(false);
		cmd.parse(argc, argv);

		const codemark::CameraModel camera =
			camera_arg.getValue().empty() ? codemark::CameraModel::paperDefault()
										  : codemark::CameraModel::load(camera_arg.getValue());
		const double sigma = sigma_arg.getValue();
		if (!(sigma > 0)) throw std::invalid_argument("--sigma-px must be > 0");
		if (sigma_arg.isSet() && calibration_arg.isSet())
			throw std::invalid_argument("--sigma-px and --calibration exclude each other");
		const std::string noise_label = "C_P of calibration " + calibration_arg.getValue();
		const cp::PoseOptions noise =
			calibration_arg.isSet()
				? codemark::pipeline::calibratedPoseOptions(calibration_arg.getValue())
				: cp::constantNoise(sigma);
		if (!(scale_arg.getValue() > 0)) throw std::invalid_argument("--scale must be > 0");
		bool did = false;

		if (size_for_arg.isSet())
		{
			const auto [acc_m, acc_deg] = parsePair(size_for_arg.getValue(), "--size-for");
			if (!distance_arg.isSet()) throw std::invalid_argument("--size-for needs --distance");
			const cp::SizeAdvice a = cp::sizeFor(
				camera, noise, acc_m, acc_deg * M_PI / 180, distance_arg.getValue(),
				angle_arg.getValue() * M_PI / 180, k_arg.getValue(), min_size_arg.getValue());
			std::cout << codemark::eval::describeSizeAdvice(a, k_arg.getValue());
			did = true;
			if (!a.found) return 2;
		}
		if (table_arg.getValue())
		{
			const double dmax = xmax_arg.isSet() ? xmax_arg.getValue() : 5.0;
			std::vector<double> d;
			for (double x = 0.5; x <= dmax + 1e-9; x += 0.5) d.push_back(x);
			std::cout
				<< (calibration_arg.isSet()
						? codemark::eval::accuracyTable(
							  camera, scale_arg.getValue(), noise, noise_label,
							  angle_arg.getValue() * M_PI / 180, d, min_size_arg.getValue())
						: codemark::eval::accuracyTable(
							  camera, scale_arg.getValue(), sigma,
							  angle_arg.getValue() * M_PI / 180, d, min_size_arg.getValue()));
			did = true;
		}
		if (out_arg.isSet() || !did)
		{
			codemark::eval::FigureOptions fo;
			fo.sigma_px = sigma;
			if (calibration_arg.isSet())
			{
				fo.noise = noise;
				fo.noise_label = noise_label;
			}
			fo.scale = scale_arg.getValue();
			if (xmax_arg.isSet()) fo.x_max_m = xmax_arg.getValue();
			fo.magnification = mag_arg.getValue();
			fo.heading_magnification = hmag_arg.getValue();
			fo.min_size_px = min_size_arg.getValue();
			const std::string path = out_arg.isSet() ? out_arg.getValue() : "uncertainty.png";
			const codemark::eval::FigureScales mag =
				codemark::eval::drawUncertaintyFigure(path, camera, fo);
			std::cout << "wrote " << path << " (ellipses drawn x" << mag.ellipse
					  << ", heading wedges x" << mag.heading << ")\n";
		}
		return 0;
	}
	catch (const TCLAP::ExitException& e)
	{
		return e.getExitStatus();
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << codemark::app::argumentError("codemark-uncertainty", e) << "\n";
		return 1;
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-uncertainty: error: " << e.what() << "\n";
		return 1;
	}
}
