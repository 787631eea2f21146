/** \file pose_calib.cpp
 * codemark-bench-pose-calib: the data behind the detector's calibrated C_P
 * (codemark::pipeline::detectorCalibratedPoseOptions()). Renders a level
 * camera at random poses in front of one landmark (the accuracy map's flat
 * background by default, --realistic for the simulated datasets' scene;
 * pixel noise 2, blur 0.8 px, the paper's camera), runs codemark's
 * detector, optionally writes one CSV row per detection (pose, apparent
 * size, errors of the four corners and of P against the renderer's exact
 * truth), fits the noise model of pose::PoseOptions::primaryCovariance() by
 * maximum likelihood and prints it with a per-distance table
 * (docs/benchmarks/pose.md).
 */
#include <codemark/detect/detector.h>
#include <codemark/landmark/primary.h>
#include <codemark/landmark/truth.h>
#include <codemark/sim/dataset.h>
#include <codemark/sim/render.h>
#include <mrpt/config/CConfigFile.h>
#include <tclap/CmdLine.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <stdexcept>
#include <vector>

using namespace codemark;

namespace
{
struct Sample
{
	double d, angle_deg;
	double side_px;	 // apparent height y1 + y2 (true) [px]
	double width_px;  // apparent width x2 - x1 (true) [px]
	Eigen::Matrix<double, 8, 1> e_corner;  // (u, v) errors TL TR BR BL [px]
	Eigen::Vector4d e_P;
};
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd(
			"Detector corner and P errors on renders (calibration data of C_P).", ' ', "0.1.0");
		TCLAP::ValueArg<int> n_arg(
			"", "renders", "Number of renders. Default 2000.", false, 2000, "N", cmd);
		TCLAP::ValueArg<double> dmin_arg(
			"", "min-distance", "Nearest [m]. Default 0.5.", false, 0.5, "M", cmd);
		TCLAP::ValueArg<double> dmax_arg(
			"", "max-distance", "Farthest [m]. Default 5.", false, 5.0, "M", cmd);
		TCLAP::ValueArg<double> amax_arg(
			"", "max-angle", "Largest view angle [deg]. Default 70.", false, 70, "DEG", cmd);
		TCLAP::ValueArg<unsigned long> seed_arg("", "seed", "Seed. Default 1.", false, 1, "N", cmd);
		TCLAP::ValueArg<double> bearing_arg(
			"", "max-bearing", "Largest |phi1| [rad]. Default 0.15.", false, 0.15, "RAD", cmd);
		TCLAP::ValueArg<double> height_arg(
			"", "max-height", "Largest |camera height - landmark centre height| [m]. Default 0.2.",
			false, 0.2, "M", cmd);
		TCLAP::SwitchArg realistic_arg(
			"", "realistic",
			"Render as the simulated datasets do (sim::DatasetOptions::realisticRender(): textured "
			"wall, light gradient, noise 2, blur 0.8) instead of the accuracy map's flat "
			"background.",
			cmd, false);
		TCLAP::ValueArg<std::string> render_arg(
			"", "render-config",
			"Ini file whose [render] section overrides the render options (after --realistic), "
			"e.g. gradient, background, noise_sigma, blur_sigma_px.",
			false, "", "FILE", cmd);
		TCLAP::SwitchArg uniform_distance_arg(
			"", "uniform-distance",
			"Draw distances uniformly (each distance as often) instead of uniformly in area (as "
			"the survey grid, which makes far views the majority and leaves the near-range floor "
			"of the noise model to few samples).",
			cmd, false);
		TCLAP::ValueArg<std::string> detector_arg(
			"", "detector-config", "Detector options ini (share/codemark/detector.ini's format).",
			false, "", "FILE", cmd);
		TCLAP::ValueArg<std::string> csv_arg(
			"", "csv", "Per-detection CSV to write.", false, "", "FILE", cmd);
		cmd.setExceptionHandling(false);
		cmd.parse(argc, argv);

		sim::Scene scene;
		MapLandmark lm;
		lm.id = 37;
		lm.z_m = 0.5;
		scene.map.landmarks.push_back(lm);
		scene.camera = CameraModel::paperDefault();
		sim::RenderOptions ro;
		ro.noise_sigma = 2;
		ro.blur_sigma_px = 0.8;
		if (realistic_arg.getValue()) ro = sim::DatasetOptions::realisticRender();
		if (!render_arg.getValue().empty())
		{
			// MRPT reads a missing file as an empty one: say so instead.
			const std::string& path = render_arg.getValue();
			if (!std::ifstream(path).good())
				throw std::runtime_error(path + ": cannot open the render options file");
			const mrpt::config::CConfigFile ini(path);
			if (!ini.sectionExists("render"))
				throw std::runtime_error(path + ": no [render] section");
			ro.loadFromConfigFile(ini, "render");
		}
		const LandmarkGeometry g = lm.geometry();
		const detect::DetectorOptions dopt =
			detector_arg.getValue().empty()
				? detect::DetectorOptions()
				: detect::DetectorOptions::load(detector_arg.getValue());
		std::mt19937_64 rng(seed_arg.getValue());
		std::uniform_real_distribution<double> U(0, 1);
		std::vector<Sample> samples;
		int missed = 0;
		for (int i = 0; i < n_arg.getValue(); ++i)
		{
			// Uniform in area over the annulus sector: as the survey grid.
			const double r0 = dmin_arg.getValue(), r1 = dmax_arg.getValue();
			const double d = uniform_distance_arg.getValue()
								 ? r0 + U(rng) * (r1 - r0)
								 : std::sqrt(r0 * r0 + U(rng) * (r1 * r1 - r0 * r0));
			const double a = (2 * U(rng) - 1) * amax_arg.getValue();
			const double bearing = (2 * U(rng) - 1) * bearing_arg.getValue(),
						 height = (2 * U(rng) - 1) * height_arg.getValue();
			scene.world_T_camera =
				sim::levelCameraLookingAt(lm, d, a * M_PI / 180, height, bearing);
			const sim::Render img = sim::render(scene, ro, seed_arg.getValue() * 100003 + i);
			if (!img.truth[0].fully_visible) continue;
			const auto res = detect::detect(img.image, scene.camera, g, dopt);
			bool found = false;
			for (const auto& dl : res.landmarks)
				if (dl.detection.id == lm.id)
				{
					Sample s;
					s.d = d;
					s.angle_deg = a;
					s.side_px = img.truth[0].P[1] + img.truth[0].P[3];
					s.width_px = img.truth[0].P[2] - img.truth[0].P[0];
					for (int k = 0; k < 4; ++k)
						s.e_corner.segment<2>(2 * k) =
							dl.detection.corners[k] - img.truth[0].corners_px[k];
					s.e_P = primaryMeasurement(dl.detection.corners, scene.camera) - img.truth[0].P;
					samples.push_back(s);
					found = true;
					break;
				}
			missed += !found;
		}
		if (!csv_arg.getValue().empty())
		{
			std::ofstream f(csv_arg.getValue());
			f << "distance_m,angle_deg,side_px,width_px,e_tl_u,e_tl_v,e_tr_u,e_tr_v,e_br_u,e_br_v,"
				 "e_bl_u,e_bl_v,e_x1,e_y1,e_x2,e_y2\n";
			for (const auto& s : samples)
			{
				f << s.d << "," << s.angle_deg << "," << s.side_px << "," << s.width_px;
				for (int k = 0; k < 8; ++k) f << "," << s.e_corner[k];
				for (int k = 0; k < 4; ++k) f << "," << s.e_P[k];
				f << "\n";
			}
		}
		std::printf("%zu detections, %d missed\n", samples.size(), missed);

		// Maximum-likelihood fit (grid search) of the noise model of
		// PoseOptions::primaryCovariance: each component of P has
		// sigma(s) = sqrt(floor^2 + (growth (ref / s)^exponent)^2), s the
		// apparent width x2 - x1 for x1, x2 and the apparent height y1 + y2
		// for y1, y2; then the correlations of the normalised errors.
		const double ref = 30;
		struct Fit
		{
			double nll = 1e300, floor = 0, growth = 0, exponent = 0;
		};
		const auto sizeOf = [](const Sample& s, bool x) { return x ? s.width_px : s.side_px; };
		const auto fit = [&](bool x)
		{
			Fit best;
			for (int i = 1; i <= 16; ++i)
				for (int j = 1; j <= 40; ++j)
					for (int k = 0; k <= 16; ++k)
					{
						const double fl = 0.0025 * i, gr = 0.005 * j, ex = 0.25 * k;
						double nll = 0;
						for (const auto& s : samples)
						{
							const double g = gr * std::pow(ref / sizeOf(s, x), ex);
							const double v = fl * fl + g * g;
							for (const int c : {x ? 0 : 1, x ? 2 : 3})
								nll += s.e_P[c] * s.e_P[c] / v + std::log(v);
						}
						if (nll < best.nll) best = {nll, fl, gr, ex};
					}
			return best;
		};
		const Fit fx = fit(true), fy = fit(false);
		double cxx = 0, cyy = 0, c12x = 0, c12y = 0;
		for (const auto& s : samples)
		{
			const auto sig = [&](const Fit& f, double size)
			{
				const double g = f.growth * std::pow(ref / size, f.exponent);
				return std::sqrt(f.floor * f.floor + g * g);
			};
			const double sx = sig(fx, s.width_px), sy = sig(fy, s.side_px);
			const Eigen::Vector4d z(s.e_P[0] / sx, s.e_P[1] / sy, s.e_P[2] / sx, s.e_P[3] / sy);
			cxx += (z[0] * z[0] + z[2] * z[2]) / 2;
			cyy += (z[1] * z[1] + z[3] * z[3]) / 2;
			c12x += z[0] * z[2];
			c12y += z[1] * z[3];
		}
		// The correlation of the two edges' errors, separately for the floor
		// term (a common shift of the inner edges, large landmarks) and the
		// growth term (small landmarks), by maximum likelihood on a grid.
		const auto fitCorr = [&](const Fit& f, bool x, double& r_floor, double& r_growth)
		{
			double best = 1e300;
			for (int i = -19; i <= 19; ++i)
				for (int j = -19; j <= 19; ++j)
				{
					const double rf = 0.05 * i, rg = 0.05 * j;
					double nll = 0;
					for (const auto& s : samples)
					{
						const double g = f.growth * std::pow(ref / sizeOf(s, x), f.exponent);
						const double v = f.floor * f.floor + g * g,
									 c = rf * f.floor * f.floor + rg * g * g;
						const double det = v * v - c * c;
						const double e1 = s.e_P[x ? 0 : 1], e2 = s.e_P[x ? 2 : 3];
						nll += (v * e1 * e1 - 2 * c * e1 * e2 + v * e2 * e2) / det + std::log(det);
					}
					if (nll < best)
					{
						best = nll;
						r_floor = rf;
						r_growth = rg;
					}
				}
		};
		double rfx = 0, rgx = 0, rfy = 0, rgy = 0;
		fitCorr(fx, true, rfx, rgx);
		fitCorr(fy, false, rfy, rgy);
		std::printf("\nfit (size reference %.0f px, %zu detections):\n", ref, samples.size());
		std::printf(
			"  correlation of the two edges' errors: x floor %+.2f growth %+.2f; y floor %+.2f "
			"growth %+.2f\n",
			rfx, rgx, rfy, rgy);
		std::printf(
			"  x1, x2: sigma_px %.4f growth_x_px %.3f size_exponent_x %.2f; normalised variance "
			"%.3f, corr_x12 %+.3f\n",
			fx.floor, fx.growth, fx.exponent, cxx / samples.size(),
			c12x / samples.size() / (cxx / samples.size()));
		std::printf(
			"  y1, y2: sigma_y_px %.4f growth_y_px %.3f size_exponent_y %.2f; normalised variance "
			"%.3f, corr_y12 %+.3f\n",
			fy.floor, fy.growth, fy.exponent, cyy / samples.size(),
			c12y / samples.size() / (cyy / samples.size()));
		// The corners' four other numbers (PoseOptions::corner_midpoint_ratio,
		// corner_tilt_ratio; pose::cornerCovarianceFromPrimary()): each
		// vertical edge's midpoint height m = (v_top + v_bottom) / 2 against
		// sigma_y, its tilt t = (u_top - u_bottom) / 2 against sigma_x, RMS of
		// the normalised errors.
		double zm = 0, zt = 0;
		for (const auto& s : samples)
		{
			const auto var = [&](const Fit& f, double size)
			{
				const double g = f.growth * std::pow(ref / size, f.exponent);
				return f.floor * f.floor + g * g;
			};
			const double vx = var(fx, s.width_px), vy = var(fy, s.side_px);
			const auto& e = s.e_corner;	 // TL.u TL.v TR.u TR.v BR.u BR.v BL.u BL.v
			const double m1 = (e[1] + e[7]) / 2, m2 = (e[3] + e[5]) / 2;
			const double t1 = (e[0] - e[6]) / 2, t2 = (e[2] - e[4]) / 2;
			zm += (m1 * m1 + m2 * m2) / (2 * vy);
			zt += (t1 * t1 + t2 * t2) / (2 * vx);
		}
		std::printf(
			"  corner_midpoint_ratio %.2f corner_tilt_ratio %.2f\n", std::sqrt(zm / samples.size()),
			std::sqrt(zt / samples.size()));
		std::printf(
			"%-9s %5s %7s | %7s %7s | %7s %7s %7s %7s | %6s %6s %6s\n", "band", "n", "side",
			"rms_u", "rms_v", "sd_x1", "sd_y1", "sd_x2", "sd_y2", "r_y1y2", "r_x1x2", "r_uTB");
		for (double lo = 0.5; lo < dmax_arg.getValue() - 1e-9; lo += 0.5)
		{
			const double hi = lo + 0.5;
			Eigen::Matrix<double, 8, 8> Cc = Eigen::Matrix<double, 8, 8>::Zero();
			Eigen::Matrix4d CP = Eigen::Matrix4d::Zero();
			double side = 0;
			int n = 0;
			for (const auto& s : samples)
				if (s.d >= lo && s.d < hi)
				{
					Cc += s.e_corner * s.e_corner.transpose();
					CP += s.e_P * s.e_P.transpose();
					side += s.side_px;
					++n;
				}
			if (n < 5) continue;
			Cc /= n;
			CP /= n;
			double ru = 0, rv = 0;
			for (int k = 0; k < 4; ++k)
			{
				ru += Cc(2 * k, 2 * k) / 4;
				rv += Cc(2 * k + 1, 2 * k + 1) / 4;
			}
			// Correlation of the u errors of the two ends of a vertical edge
			// (TL-BL and TR-BR): one line fit's ends.
			const double r_uTB = 0.5 * (Cc(0, 6) / std::sqrt(Cc(0, 0) * Cc(6, 6)) +
										Cc(2, 4) / std::sqrt(Cc(2, 2) * Cc(4, 4)));
			std::printf(
				"%3.1f-%3.1f m %5d %7.1f | %7.4f %7.4f | %7.4f %7.4f %7.4f %7.4f | %6.2f %6.2f "
				"%6.2f\n",
				lo, hi, n, side / n, std::sqrt(ru), std::sqrt(rv), std::sqrt(CP(0, 0)),
				std::sqrt(CP(1, 1)), std::sqrt(CP(2, 2)), std::sqrt(CP(3, 3)),
				CP(1, 3) / std::sqrt(CP(1, 1) * CP(3, 3)),
				CP(0, 2) / std::sqrt(CP(0, 0) * CP(2, 2)), r_uTB);
		}
		return 0;
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << "codemark-bench-pose-calib: error: " << e.argId() << ": " << e.error() << "\n";
		return 1;
	}
	catch (const TCLAP::ExitException& e)
	{
		return e.getExitStatus();
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-bench-pose-calib: error: " << e.what() << "\n";
		return 1;
	}
}
