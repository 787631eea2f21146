/** \file pose_calib.cpp
 * codemark-bench-pose-calib: fits the noise model of P for codemark's
 * detector and writes it as a calibration file (--out; docs/calibration.md,
 * the shipped ones in share/codemark/calibration/). Renders a level
 * camera at random poses in front of one landmark (the accuracy map's flat
 * background by default, --realistic for the simulated datasets' scene;
 * pixel noise 2, blur 0.8 px, the paper's camera), runs codemark's
 * detector, optionally writes one CSV row per detection (pose, apparent
 * size, errors of the four corners and of P against the renderer's exact
 * truth), fits the noise model of pose::PoseOptions::primaryCovariance() by
 * maximum likelihood and prints it with a per-distance table.
 */
#include <codemark/detect/detector.h>
#include <codemark/landmark/primary.h>
#include <codemark/pose/calibration.h>
#include <codemark/pose/measurement.h>
#include <codemark/landmark/truth.h>
#include <codemark/sim/dataset.h>
#include <codemark/sim/povray.h>
#include <codemark/sim/render.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/datetime.h>
#include <tclap/CmdLine.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

using namespace codemark;

namespace
{
/** -2 log-likelihood (up to a constant) of the error pair (e1, e2) under
 * variances v1, v2 and covariance c. */
double pairNll(double e1, double e2, double v1, double v2, double c)
{
	const double det = v1 * v2 - c * c;
	return (v2 * e1 * e1 - 2 * c * e1 * e2 + v1 * e2 * e2) / det + std::log(det);
}

struct Sample
{
	double d, angle_deg;
	double side_px;	 // apparent height y1 + y2 (true) [px]
	double width_px;  // apparent width x2 - x1 (true) [px]
	Eigen::Matrix<double, 8, 1> e_corner;  // (u, v) errors TL TR BR BL [px]
	Eigen::Vector4d e_P;
	std::array<bool, 4> clipped{};	// DetectionQuality::fill_clipped (top, right, bottom, left)
	std::array<double, 4> line_rms{};  // DetectionQuality::line_rms_px
	std::array<int, 4> line_support{};	// DetectionQuality::line_support
	double code_margin = 0;	 // DetectionQuality::code_margin
	/** PoseOptions::aligned_edge_ratio's weight of the top and bottom edges:
	 * 1 - the rows between their ends (true corners), 0 beyond one row. */
	double aligned_weight = 0;
	double rows_top = 0, rows_bottom = 0;  // rows between the top and bottom edges' ends [px]
	double image_noise = 0;	 // DetectionQuality::image_noise_grey (0: not measured)
	double bend = 0, bend_se = 0;  // DetectionQuality::edge_bend_px, edge_bend_se_px
	int group = 0;	// --vary-scene: print (i % 3) + 3 * light
	int preset = 0;	 // its --preset's index in the list
	Eigen::Vector4d P_true = Eigen::Vector4d::Zero();
	/** Clipped sides on x1, x2 (left, right: 0 or 1) and on y1, y2 (top and bottom: 0-2). */
	int clippedOn(int component) const
	{
		if (component == 0) return clipped[3];
		if (component == 2) return clipped[1];
		return int(clipped[0]) + int(clipped[2]);
	}
	/** Each vertical edge's midpoint height and tilt errors (the corners'
	 * four numbers P does not hold, pose::cornerCovarianceFromPrimary()). */
	Eigen::Vector2d midpointErrors() const
	{
		return {(e_corner[1] + e_corner[7]) / 2, (e_corner[3] + e_corner[5]) / 2};
	}
	Eigen::Vector2d tiltErrors() const
	{
		return {(e_corner[0] - e_corner[6]) / 2, (e_corner[2] - e_corner[4]) / 2};
	}
};

/** Means over \a v of the squared errors over their variances: x_i and y_i
 * of P, and the edges' midpoints and tilts against y_i's and x_i's; \a var
 * (sample, component of P) the variance. */
struct Normalised
{
	double x = 0, y = 0, midpoint = 0, tilt = 0;
};
template <class Var>
Normalised normalised(const std::vector<Sample>& v, const Var& var)
{
	Normalised z;
	for (const Sample& s : v)
	{
		const Eigen::Vector2d m = s.midpointErrors(), t = s.tiltErrors();
		const double v0 = var(s, 0), v1 = var(s, 1), v2 = var(s, 2), v3 = var(s, 3);
		z.x += (s.e_P[0] * s.e_P[0] / v0 + s.e_P[2] * s.e_P[2] / v2) / 2;
		z.y += (s.e_P[1] * s.e_P[1] / v1 + s.e_P[3] * s.e_P[3] / v3) / 2;
		z.midpoint += (m[0] * m[0] / v1 + m[1] * m[1] / v3) / 2;
		z.tilt += (t[0] * t[0] / v0 + t[1] * t[1] / v2) / 2;
	}
	const double n = std::max<size_t>(1, v.size());
	z.x /= n;
	z.y /= n;
	z.midpoint /= n;
	z.tilt /= n;
	return z;
}

/** One bin of sizeBins(): its samples in order of size, and its median size
 * rounded to 0.1 px. */
struct SizeBin
{
	std::vector<const Sample*> samples;
	double size_px = 0;
};
/** \a v sorted by \a size (sample -> px), cut into bins a factor 1.25 in size
 * wide, of at least \a min_count samples; a short remainder joins the last
 * bin. The calibration's tables are fitted per bin. */
template <class Size>
std::vector<SizeBin> sizeBins(const std::vector<Sample>& v, const Size& size, size_t min_count)
{
	std::vector<size_t> order(v.size());
	for (size_t k = 0; k < order.size(); ++k) order[k] = k;
	std::sort(
		order.begin(), order.end(), [&](size_t a, size_t b) { return size(v[a]) < size(v[b]); });
	std::vector<SizeBin> bins;
	size_t b0 = 0;
	while (b0 < order.size())
	{
		size_t b1 = b0;
		const double start = size(v[order[b0]]);
		while (b1 < order.size() && (b1 - b0 < min_count || size(v[order[b1]]) < 1.25 * start))
			++b1;
		if (order.size() - b1 < min_count) b1 = order.size();
		SizeBin bin;
		for (size_t k = b0; k < b1; ++k) bin.samples.push_back(&v[order[k]]);
		bin.size_px = std::round(10 * size(v[order[(b0 + b1) / 2]])) / 10;
		bins.push_back(std::move(bin));
		b0 = b1;
	}
	return bins;
}
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
		TCLAP::ValueArg<std::string> renderer_arg(
			"", "renderer",
			"own (default): the project's renderer; povray: POV-Ray 3.7 with its default "
			"options (docs/povray.md; cached renders)",
			false, "own", "own|povray", cmd);
		TCLAP::ValueArg<std::string> preset_arg(
			"", "preset",
			"Camera preset of the renders (docs/camera-pipeline.md), applied after --realistic "
			"and before --render-config; several, comma-separated (e.g. "
			"linear,webcam,phone,family): --renders each, at poses of their own, fitted "
			"together, so that no one camera's errors set the model.",
			false, "", "NAME[,NAME...]", cmd);
		TCLAP::ValueArg<std::string> render_arg(
			"", "render-config",
			"Ini file whose [render] section overrides the render options (after --realistic), "
			"e.g. gradient, background, noise_sigma, blur_sigma_px.",
			false, "", "FILE", cmd);
		TCLAP::ValueArg<double> level_arg(
			"", "level-fraction",
			"Fraction of the renders with the camera exactly at the landmark's height (top and "
			"bottom edges along pixel rows: PoseOptions::aligned_edge_ratio). Default 0.",
			false, 0, "F", cmd);
		TCLAP::SwitchArg vary_arg(
			"", "vary-scene",
			"Cycle each render's print and light through the per-camera benchmark's groups "
			"(scripts/povray-sets.sh): fluorescent paper, an office inkjet's and a laser's green; "
			"normal, dim (0.35x), bright (1.6x) and graded (+-25%) light.",
			cmd, false);
		TCLAP::SwitchArg uniform_distance_arg(
			"", "uniform-distance",
			"Draw distances uniformly (each distance as often) instead of uniformly in area (as "
			"the survey grid, which makes far views the majority and leaves the near-range floor "
			"of the noise model to few samples).",
			cmd, false);
		TCLAP::SwitchArg averaged_arg(
			"", "averaged",
			"Fit the power-law model with clipped and unclipped sides averaged "
			"(clipped_side_sigma_px 0), the form of the shipped calibration 'realistic'; "
			"without it --out writes the tabulated fit with the clipped sides apart.",
			cmd, false);
		TCLAP::ValueArg<std::string> detector_arg(
			"", "detector-config", "Detector options ini (share/codemark/detector.ini's format).",
			false, "", "FILE", cmd);
		TCLAP::ValueArg<std::string> out_arg(
			"", "out",
			"Calibration file to write (docs/calibration.md): the power-law fit with "
			"--averaged, else the tabulated one; the noise split's tables with --noise-split.",
			false, "", "FILE", cmd);
		TCLAP::ValueArg<std::string> csv_arg(
			"", "csv", "Per-detection CSV to write.", false, "", "FILE", cmd);
		TCLAP::SwitchArg scatter_arg(
			"", "scatter-model",
			"Also fit the scatter model (PoseOptions::band_ratio_x, band_floor_x_table: C_P "
			"from the standard error of each detection's bands) and write it with --out; "
			"without it the calibration holds the tables alone.",
			cmd, false);
		TCLAP::ValueArg<double> noise_split_arg(
			"", "noise-split",
			"Render the same poses again at this pixel noise [grey levels] and print the part "
			"of the tabulated sigmas that grows with the noise (PoseOptions::"
			"reference_noise_grey, noise_sigma_x_table, noise_sigma_y_table). 0: off.",
			false, 0, "S", cmd);
		cmd.setExceptionHandling(false);
		cmd.parse(argc, argv);
		if (scatter_arg.getValue() && averaged_arg.getValue())
			throw std::invalid_argument(
				"--scatter-model adds to the tabulated fit: drop --averaged");
		if (renderer_arg.getValue() != "own" && renderer_arg.getValue() != "povray")
			throw std::invalid_argument(
				"--renderer must be own or povray, got '" + renderer_arg.getValue() + "'");
		const sim::Renderer renderer = renderer_arg.getValue() == "povray"
										   ? sim::povrayRenderer(sim::PovrayOptions())
										   : sim::Renderer(sim::render);
		if (n_arg.getValue() < 1 || !(dmin_arg.getValue() > 0) ||
			!(dmax_arg.getValue() > dmin_arg.getValue()) || !(amax_arg.getValue() >= 0) ||
			!(amax_arg.getValue() < 90) || !(bearing_arg.getValue() >= 0) ||
			!(height_arg.getValue() >= 0) || !(level_arg.getValue() >= 0) ||
			!(level_arg.getValue() <= 1) || !(noise_split_arg.getValue() >= 0))
			throw std::invalid_argument(
				"expected --renders >= 1, 0 < --min-distance < --max-distance, --max-angle in "
				"[0, 90), --max-bearing and --max-height >= 0, --level-fraction in [0, 1], "
				"--noise-split >= 0");

		sim::Scene scene = sim::singleLandmarkScene();
		const MapLandmark& lm = scene.map.landmarks[0];
		sim::RenderOptions ro;
		ro.noise_sigma = 2;
		ro.blur_sigma_px = 0.8;
		if (realistic_arg.getValue()) ro = sim::DatasetOptions::realisticRender();
		std::vector<std::string> presets;
		{
			std::stringstream list(preset_arg.getValue());
			for (std::string name; std::getline(list, name, ',');)
				if (!name.empty()) presets.push_back(name);
		}
		if (presets.empty()) presets.emplace_back();
		if (presets.size() > 1 && noise_split_arg.getValue() > 0)
			throw std::invalid_argument("--noise-split takes one --preset");
		// The render options per preset.
		std::vector<sim::RenderOptions> ro_presets;
		for (const auto& name : presets)
		{
			sim::RenderOptions r = ro;
			if (!name.empty()) r.applyPreset(name);
			if (!render_arg.getValue().empty())
			{
				// MRPT reads a missing file as an empty one: say so instead.
				const std::string& path = render_arg.getValue();
				if (!std::ifstream(path).good())
					throw std::runtime_error(path + ": cannot open the render options file");
				const mrpt::config::CConfigFile ini(path);
				if (!ini.sectionExists("render"))
					throw std::runtime_error(path + ": no [render] section");
				r.loadFromConfigFile(ini, "render");
			}
			ro_presets.push_back(r);
		}
		ro = ro_presets.front();
		const LandmarkGeometry g = lm.geometry();
		const detect::DetectorOptions dopt =
			detector_arg.getValue().empty()
				? detect::DetectorOptions()
				: detect::DetectorOptions::load(detector_arg.getValue());
		// The renders at \a r (the same poses and noise seeds for any r of
		// one \a seed).
		const auto collect = [&](const sim::RenderOptions& r, int& missed, uint64_t seed)
		{
			std::mt19937_64 rng(seed);
			std::uniform_real_distribution<double> U(0, 1);
			std::vector<Sample> samples;
			missed = 0;
			for (int i = 0; i < n_arg.getValue(); ++i)
			{
				// Uniform in area over the annulus sector: as the survey grid.
				const double r0 = dmin_arg.getValue(), r1 = dmax_arg.getValue();
				const double d = uniform_distance_arg.getValue()
									 ? r0 + U(rng) * (r1 - r0)
									 : std::sqrt(r0 * r0 + U(rng) * (r1 * r1 - r0 * r0));
				const double a = (2 * U(rng) - 1) * amax_arg.getValue();
				const double bearing = (2 * U(rng) - 1) * bearing_arg.getValue();
				double height = (2 * U(rng) - 1) * height_arg.getValue();
				if (U(rng) < level_arg.getValue()) height = 0;
				scene.world_T_camera =
					sim::levelCameraLookingAt(lm, d, a * M_PI / 180, height, bearing);
				sim::RenderOptions ri = r;
				if (vary_arg.getValue())
				{
					// The prints' greens as linear reflectances x 255 (BGR), as
					// scripts/povray-sets.sh draws them.
					static const cv::Scalar kGreens[] = {
						{0, 255, 0}, {20.4, 102.5, 5.4}, {26.1, 89.6, 11.5}};
					ri.green_bgr = kGreens[i % 3];
					const int light = (i / 3) % 4;
					if (light == 1) ri.gain *= 0.35;
					if (light == 2) ri.gain *= 1.6;
					if (light == 3)
					{
						ri.gradient = 0.5;
						ri.gradient_angle_rad = std::fmod(0.7 * i, 2 * M_PI);
					}
				}
				const sim::Render img = renderer(scene, ri, seed * 100003 + i);
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
						s.e_P =
							primaryMeasurement(dl.detection.corners, scene.camera) - img.truth[0].P;
						s.clipped = dl.detection.quality.fill_clipped;
						s.line_rms = dl.detection.quality.line_rms_px;
						s.line_support = dl.detection.quality.line_support;
						s.code_margin = dl.detection.quality.code_margin;
						s.image_noise = dl.detection.quality.image_noise_grey;
						s.bend = dl.detection.quality.edge_bend_px;
						s.bend_se = dl.detection.quality.edge_bend_se_px;
						s.group = i % 12;
						const auto& tc = img.truth[0].corners_px;
						s.P_true = img.truth[0].P;
						s.rows_top = tc[1].y() - tc[0].y();
						s.rows_bottom = tc[2].y() - tc[3].y();
						for (const double rows : {tc[1].y() - tc[0].y(), tc[2].y() - tc[3].y()})
							s.aligned_weight += std::max(0.0, 1 - std::abs(rows));
						samples.push_back(s);
						found = true;
						break;
					}
				missed += !found;
			}
			return samples;
		};
		int missed = 0;
		std::vector<Sample> samples;
		for (size_t k = 0; k < ro_presets.size(); ++k)
		{
			int m = 0;
			// Poses of its own per preset (the first keeps --seed's).
			auto v = collect(ro_presets[k], m, seed_arg.getValue() + 7919 * k);
			for (auto& sm : v) sm.preset = static_cast<int>(k);
			samples.insert(samples.end(), v.begin(), v.end());
			missed += m;
		}
		if (!csv_arg.getValue().empty())
		{
			std::ofstream f(csv_arg.getValue());
			f << "distance_m,angle_deg,side_px,width_px,e_tl_u,e_tl_v,e_tr_u,e_tr_v,e_br_u,e_br_v,"
				 "e_bl_u,e_bl_v,e_x1,e_y1,e_x2,e_y2,clipped_top,clipped_right,clipped_bottom,"
				 "clipped_left,rms_top,rms_right,rms_bottom,rms_left,image_noise,group,support_top,"
				 "support_right,support_bottom,support_left,code_margin,bend,bend_se,preset\n";
			for (const auto& s : samples)
			{
				f << s.d << "," << s.angle_deg << "," << s.side_px << "," << s.width_px;
				for (int k = 0; k < 8; ++k) f << "," << s.e_corner[k];
				for (int k = 0; k < 4; ++k) f << "," << s.e_P[k];
				for (int k = 0; k < 4; ++k) f << "," << int(s.clipped[k]);
				for (int k = 0; k < 4; ++k) f << "," << s.line_rms[k];
				f << "," << s.image_noise << "," << s.group;
				for (int k = 0; k < 4; ++k) f << "," << s.line_support[k];
				f << "," << s.code_margin << "," << s.bend << "," << s.bend_se << ","
				  << presets[s.preset] << "\n";
			}
		}
		std::printf("%zu detections, %d missed\n", samples.size(), missed);
		// A fit of a handful would print numbers that mean nothing.
		if (samples.size() < 20)
			throw std::runtime_error(
				std::to_string(samples.size()) +
				" detections: at least 20 are needed for a fit (more --renders, or distances the "
				"landmark is detected at)");

		// Maximum-likelihood fit (grid search) of the noise model of
		// PoseOptions::primaryCovariance and clippedSidesCovariance: each
		// component of P has sigma(s)^2 = floor^2 + (growth (ref /
		// s)^exponent)^2 + its clipped sides' share of clip^2, s the apparent
		// width x2 - x1 for x1, x2 and the apparent height y1 + y2 for y1, y2
		// (a clipped left or right side adds clip^2 to x1 or x2, a clipped top
		// or bottom clip^2 / 4 to both y1 and y2); one clip for all sides
		// (the x and y fits' summed likelihood); then the correlations of the
		// normalised errors.
		const double ref = 30;
		struct Fit
		{
			double nll = 1e300, floor = 0, growth = 0, exponent = 0, clip = 0;
			/** Variance of component c of sample s. */
			double var(const Sample& s, int c, double size) const
			{
				const double g = growth * std::pow(30 / size, exponent);
				const double share = c % 2 == 0 ? 1.0 : 0.25;
				return floor * floor + g * g + share * s.clippedOn(c) * clip * clip;
			}
		};
		const auto sizeOf = [](const Sample& s, bool x) { return x ? s.width_px : s.side_px; };
		constexpr int kExponents = 17;
		std::vector<std::array<double, kExponents>> size_pow[2];
		for (int x = 0; x < 2; ++x)
			for (const auto& s : samples)
			{
				std::array<double, kExponents> t{};
				for (int k = 0; k < kExponents; ++k) t[k] = std::pow(ref / sizeOf(s, x), 0.25 * k);
				size_pow[x].push_back(t);
			}
		const auto fit = [&](bool x, double clip)
		{
			Fit best;
			for (int i = 1; i <= 32; ++i)
				for (int j = 1; j <= 40; ++j)
					for (int k = 0; k < kExponents; ++k)
					{
						const double fl = 0.00125 * i, gr = 0.005 * j;
						double nll = 0;
						for (size_t n = 0; n < samples.size(); ++n)
						{
							const Sample& s = samples[n];
							const double g = gr * size_pow[x][n][k];
							for (const int c : {x ? 0 : 1, x ? 2 : 3})
							{
								const double v =
									fl * fl + g * g +
									(c % 2 == 0 ? 1.0 : 0.25) * s.clippedOn(c) * clip * clip;
								nll += s.e_P[c] * s.e_P[c] / v + std::log(v);
							}
						}
						if (nll < best.nll) best = {nll, fl, gr, 0.25 * k, clip};
					}
			return best;
		};
		int n_clipped = 0;
		for (const auto& s : samples)
			for (const bool c : s.clipped) n_clipped += c;
		Fit fx, fy;
		for (int m = 0; m <= (n_clipped > 20 && !averaged_arg.getValue() ? 16 : 0); ++m)
		{
			const double clip = 0.005 * m;
			const Fit a = fit(true, clip), b = fit(false, clip);
			if (a.nll + b.nll < fx.nll + fy.nll)
			{
				fx = a;
				fy = b;
			}
		}
		double cxx = 0, cyy = 0, c12x = 0, c12y = 0;
		for (const auto& s : samples)
		{
			Eigen::Vector4d z;
			for (int c = 0; c < 4; ++c)
			{
				const bool x = c % 2 == 0;
				z[c] = s.e_P[c] / std::sqrt((x ? fx : fy).var(s, c, sizeOf(s, x)));
			}
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
			// |r| <= 0.8: two edges fitted apart are never almost fully
			// correlated; a floor far below the growth leaves its own
			// correlation undetermined, and the grid's edge would make C_P
			// nearly singular where the floor dominates (large landmarks).
			for (int i = -16; i <= 16; ++i)
				for (int j = -16; j <= 16; ++j)
				{
					const double rf = 0.05 * i, rg = 0.05 * j;
					double nll = 0;
					for (const auto& s : samples)
					{
						const int c1 = x ? 0 : 1, c2 = x ? 2 : 3;
						const double g = f.growth * std::pow(ref / sizeOf(s, x), f.exponent);
						const double v1 = f.var(s, c1, sizeOf(s, x)),
									 v2 = f.var(s, c2, sizeOf(s, x));
						// A clipped top or bottom moves y1 and y2 together.
						const double c = rf * f.floor * f.floor + rg * g * g +
										 (x ? 0.0 : 0.25 * s.clippedOn(1) * f.clip * f.clip);
						nll += pairNll(s.e_P[c1], s.e_P[c2], v1, v2, c);
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
			const auto& e = s.e_corner;	 // TL.u TL.v TR.u TR.v BR.u BR.v BL.u BL.v
			const double m1 = (e[1] + e[7]) / 2, m2 = (e[3] + e[5]) / 2;
			const double t1 = (e[0] - e[6]) / 2, t2 = (e[2] - e[4]) / 2;
			zm += (m1 * m1 / fy.var(s, 1, s.side_px) + m2 * m2 / fy.var(s, 3, s.side_px)) / 2;
			zt += (t1 * t1 / fx.var(s, 0, s.width_px) + t2 * t2 / fx.var(s, 2, s.width_px)) / 2;
		}
		std::printf(
			"  clipped_side_sigma_px %.3f (%d clipped sides of %zu)\n", fx.clip, n_clipped,
			4 * samples.size());
		std::printf(
			"  corner_midpoint_ratio %.2f corner_tilt_ratio %.2f\n", std::sqrt(zm / samples.size()),
			std::sqrt(zt / samples.size()));
		// The calibration --out writes: the power-law fit (--averaged) or the
		// tabulated one below.
		pose::PoseOptions fitted;
		fitted.sigma_px = fx.floor;
		fitted.sigma_y_px = fy.floor;
		fitted.growth_x_px = fx.growth;
		fitted.growth_y_px = fy.growth;
		fitted.size_exponent_x = fx.exponent;
		fitted.size_exponent_y = fy.exponent;
		fitted.size_reference_px = ref;
		fitted.corr_x12 = rfx;
		fitted.corr_growth_x12 = rgx;
		fitted.corr_y12 = rfy;
		fitted.corr_growth_y12 = rgy;
		fitted.corner_midpoint_ratio = std::sqrt(zm / samples.size());
		fitted.corner_tilt_ratio = std::sqrt(zt / samples.size());
		// The same tabulated against size (PoseOptions::sigma_x_table,
		// sigma_y_table): the maximum-likelihood sigma of each size bin (at
		// least 60 detections, at most 12 bins), with the clipped sides' term
		// above; one correlation of the two edges; the corner ratios again.
		{
			const double clip2 = fx.clip * fx.clip;
			const auto share = [&](const Sample& s, int c)
			{ return (c % 2 == 0 ? 1.0 : 0.25) * s.clippedOn(c) * clip2; };
			// The aligned edges' variance over the table's: y components only.
			double k_aligned = 0;
			const auto aligned = [&](const Sample& s, int c)
			{ return c % 2 == 0 ? 0.0 : 0.25 * k_aligned * k_aligned * s.aligned_weight; };
			const auto table = [&](bool x)
			{
				// Bins of at least 40 detections.
				pose::SigmaTable t;
				for (const SizeBin& bin : sizeBins(
						 samples, [&](const Sample& s) { return sizeOf(s, x); }, 40))
				{
					double best = 1e300, best_sigma = 0;
					for (int g = 0; g <= 400; ++g)
					{
						const double sg = 1e-4 * std::pow(1e4, g / 400.0), v0 = sg * sg;
						double nll = 0;
						for (const Sample* s : bin.samples)
							for (const int c : {x ? 0 : 1, x ? 2 : 3})
							{
								const double v = v0 * (1 + aligned(*s, c)) + share(*s, c);
								nll += s->e_P[c] * s->e_P[c] / v + std::log(v);
							}
						if (nll < best)
						{
							best = nll;
							best_sigma = sg;
						}
					}
					// 3 digits of sigma.
					const double p10 = std::pow(10, std::floor(std::log10(best_sigma)) - 2);
					if (t.empty() || bin.size_px > t.back().first)
						t.emplace_back(bin.size_px, std::round(best_sigma / p10) * p10);
				}
				return t;
			};
			pose::SigmaTable tx = table(true), ty = table(false);
			const auto var = [&](const Sample& s, int c)
			{
				const bool x = c % 2 == 0;
				return std::pow(pose::interpolateSigma(x ? tx : ty, sizeOf(s, x)), 2) *
						   (1 + aligned(s, c)) +
					   share(s, c);
			};
			double rx = 0, ry = 0;
			// k_aligned by maximum likelihood on y1, y2 given the table, the
			// table again given it (three rounds).
			const int n_aligned = static_cast<int>(std::count_if(
				samples.begin(), samples.end(),
				[](const Sample& s) { return s.aligned_weight > 0.5; }));
			for (int round = 0; round < 3 && n_aligned >= 20; ++round)
			{
				double best = 1e300, best_k = 0;
				for (int i = 0; i <= 40; ++i)
				{
					k_aligned = 0.1 * i;
					double nll = 0;
					for (const auto& s : samples)
					{
						const double t2 = std::pow(pose::interpolateSigma(ty, s.side_px), 2);
						const double v = var(s, 1), c = aligned(s, 1) * t2 + share(s, 1);
						// y1, y2 share the aligned and clipped shifts.
						nll += pairNll(s.e_P[1], s.e_P[3], v, v, c);
					}
					if (nll < best)
					{
						best = nll;
						best_k = k_aligned;
					}
				}
				k_aligned = best_k;
				ty = table(false);
			}
			for (const bool x : {true, false})
			{
				double best = 1e300;
				for (int i = -16; i <= 16; ++i)
				{
					const double r = 0.05 * i;
					double nll = 0;
					for (const auto& s : samples)
					{
						const int c1 = x ? 0 : 1, c2 = x ? 2 : 3;
						const double v1 = var(s, c1), v2 = var(s, c2);
						const double t2 =
							std::pow(pose::interpolateSigma(x ? tx : ty, sizeOf(s, x)), 2);
						const double c = r * t2 + (x ? 0.0 : share(s, 1) + aligned(s, 1) * t2);
						nll += pairNll(s.e_P[c1], s.e_P[c2], v1, v2, c);
					}
					if (nll < best)
					{
						best = nll;
						(x ? rx : ry) = r;
					}
				}
			}
			const Normalised z1 = normalised(samples, var);
			std::printf("tabulated fit (the same clipped_side_sigma_px):\n");
			std::printf("  sigma_x_table = %s\n", pose::toString(tx).c_str());
			std::printf("  sigma_y_table = %s\n", pose::toString(ty).c_str());
			std::printf(
				"  corr_growth_x12 %+.2f corr_growth_y12 %+.2f; normalised variance x %.3f y %.3f; "
				"corner_midpoint_ratio %.2f corner_tilt_ratio %.2f\n",
				rx, ry, z1.x, z1.y, std::sqrt(z1.midpoint), std::sqrt(z1.tilt));
			std::printf(
				"  aligned_edge_ratio %.1f (%d detections with a top or bottom edge along a row)\n",
				k_aligned, n_aligned);
			// The tilt ratio against the apparent height
			// (PoseOptions::corner_tilt_ratio_table): far, the detector's line
			// fits err by shifts of whole lines, near by tilts too. Bins of at
			// least 100 detections (the ratio then good to about 5%).
			pose::SigmaTable tt;
			for (const SizeBin& bin : sizeBins(
					 samples, [](const Sample& s) { return s.side_px; }, 100))
			{
				double zt = 0;
				for (const Sample* sm : bin.samples)
				{
					const Eigen::Vector2d t = sm->tiltErrors();
					zt += (t[0] * t[0] / var(*sm, 0) + t[1] * t[1] / var(*sm, 2)) / 2;
				}
				const double ratio = std::round(100 * std::sqrt(zt / bin.samples.size())) / 100;
				if ((tt.empty() || bin.size_px > tt.back().first) && ratio > 0)
					tt.emplace_back(bin.size_px, ratio);
			}
			std::printf("  corner_tilt_ratio_table = %s\n", pose::toString(tt).c_str());
			if (!averaged_arg.getValue())
			{
				fitted.sigma_x_table = tx;
				fitted.sigma_y_table = ty;
				fitted.corr_x12 = fitted.corr_y12 = 0;	// unused with the tables
				fitted.corr_growth_x12 = rx;
				fitted.corr_growth_y12 = ry;
				fitted.aligned_edge_ratio = k_aligned;
				fitted.corner_midpoint_ratio = std::sqrt(z1.midpoint);
				fitted.corner_tilt_ratio = std::sqrt(z1.tilt);
				fitted.corner_tilt_ratio_table = tt;
			}
			// The scatter model (PoseOptions::band_ratio_x): on the
			// detections whose bands the detector measured, var = (K se)^2 +
			// floor(size)^2 with the table's clipped and aligned terms; K by
			// maximum likelihood on a grid, the floor per size bin given K
			// (bins of at least 150 detections: a floor is a small
			// difference of two variances, noisy on fewer). Only with
			// --scatter-model.
			if (scatter_arg.getValue())
			{
				std::vector<Sample> banded;
				for (const auto& sm : samples)
					if (sm.bend_se > 0) banded.push_back(sm);
				if (banded.size() < 100)
					throw std::runtime_error(
						"--scatter-model: the detector measured the bands on " +
						std::to_string(banded.size()) +
						" detections, under the 100 the fit needs (more --renders, or renders "
						"whose frames span at least 3 px)");
				const auto bandFit = [&](bool x, double& ratio)
				{
					double best_total = 1e300;
					pose::SigmaTable best_table;
					const auto bins = sizeBins(
						banded, [&](const Sample& sm) { return sizeOf(sm, x); }, 150);
					for (int i = 1; i <= 120; ++i)
					{
						const double k = 0.1 * i;
						double total = 0;
						pose::SigmaTable t;
						for (const SizeBin& bin : bins)
						{
							double best = 1e300, best_floor = 0;
							for (int g = 0; g <= 200; ++g)
							{
								// 0, then 0.001 to 1 px.
								const double fl = g == 0 ? 0.0 : 1e-3 * std::pow(1e3, g / 200.0);
								double nll = 0;
								for (const Sample* sm : bin.samples)
									for (const int c : {x ? 0 : 1, x ? 2 : 3})
									{
										const double v =
											(k * k * sm->bend_se * sm->bend_se + fl * fl) *
												(1 + aligned(*sm, c)) +
											share(*sm, c);
										nll += sm->e_P[c] * sm->e_P[c] / v + std::log(v);
									}
								if (nll < best)
								{
									best = nll;
									best_floor = fl;
								}
							}
							total += best;
							// A table holds sigmas > 0: 0.1 mpx stands for none.
							const double f = std::max(1e-4, best_floor);
							const double p10 = std::pow(10, std::floor(std::log10(f)) - 2);
							if (t.empty() || bin.size_px > t.back().first)
								t.emplace_back(bin.size_px, std::round(f / p10) * p10);
						}
						if (total < best_total)
						{
							best_total = total;
							best_table = t;
							ratio = k;
						}
					}
					return best_table;
				};
				double kx = 0, ky = 0;
				const pose::SigmaTable fx_t = bandFit(true, kx), fy_t = bandFit(false, ky);
				const auto bandVar = [&](const Sample& sm, int c)
				{
					const bool x = c % 2 == 0;
					const double k = x ? kx : ky,
								 f = pose::interpolateSigma(x ? fx_t : fy_t, sizeOf(sm, x));
					return (k * k * sm.bend_se * sm.bend_se + f * f) * (1 + aligned(sm, c)) +
						   share(sm, c);
				};
				const Normalised zb = normalised(banded, bandVar);
				std::printf(
					"scatter model (%zu of %zu detections with bands measured):\n"
					"  band_ratio_x = %.1f\n  band_ratio_y = %.1f\n"
					"  band_floor_x_table = %s\n  band_floor_y_table = %s\n"
					"  normalised variance x %.3f y %.3f midpoint %.3f tilt %.3f\n",
					banded.size(), samples.size(), kx, ky, pose::toString(fx_t).c_str(),
					pose::toString(fy_t).c_str(), zb.x, zb.y, zb.midpoint, zb.tilt);
				fitted.band_ratio_x = kx;
				fitted.band_ratio_y = ky;
				fitted.band_floor_x_table = fx_t;
				fitted.band_floor_y_table = fy_t;
			}
			// The one ratio where no bin gives one (exact renders: no tilt error).
			const auto tiltRatio2 = [&](const Sample& sm)
			{ return tt.empty() ? z1.tilt : std::pow(pose::interpolateSigma(tt, sm.side_px), 2); };
			if (noise_split_arg.getValue() > 0)
			{
				sim::RenderOptions r2 = ro;
				r2.noise_sigma = noise_split_arg.getValue();
				if (!(ro.noise_sigma > 0) || r2.noise_sigma == ro.noise_sigma)
					throw std::invalid_argument(
						"--noise-split needs renders with noise and a different second noise");
				int missed2 = 0;
				const std::vector<Sample> second = collect(r2, missed2, seed_arg.getValue());
				// The noise as the detector measures it (its estimator's own
				// bias then cancels): the reference is the mean measured on
				// the calibration renders, the ratio that of the two passes.
				const auto meanNoise = [](const std::vector<Sample>& v)
				{
					double sum = 0;
					int n = 0;
					for (const Sample& sm : v)
						if (sm.image_noise > 0)
						{
							sum += sm.image_noise;
							++n;
						}
					return n >= 20 ? sum / n : 0.0;
				};
				const double ref_measured = meanNoise(samples), second_measured = meanNoise(second);
				if (!(ref_measured > 0) || !(second_measured > ref_measured))
					throw std::runtime_error(
						"--noise-split: the detector measured the noise on too few renders (under "
						"20, or no more at the second noise than at the first)");
				const double q = std::pow(second_measured / ref_measured, 2);
				// Per entry of the table: the mean square of the unclipped
				// components (all with --averaged) whose size is nearest it (in log size), at both
				// noises; the noise-driven variance at the reference is their
				// difference over q - 1 (the bias part is common to both).
				const auto split = [&](bool x, const pose::SigmaTable& t)
				{
					std::vector<double> size, var;
					for (size_t k = 0; k < t.size(); ++k)
					{
						const double lo = k ? std::sqrt(t[k - 1].first * t[k].first) : 0;
						const double hi =
							k + 1 < t.size() ? std::sqrt(t[k].first * t[k + 1].first) : 1e300;
						double ms[2] = {0, 0};
						int n[2] = {0, 0};
						for (int pass = 0; pass < 2; ++pass)
							for (const Sample& sm : pass ? second : samples)
							{
								const double size = sizeOf(sm, x);
								if (size < lo || size >= hi) continue;
								for (const int c : {x ? 0 : 1, x ? 2 : 3})
									// With --averaged the tables hold clipped sides
									// too, and so must their noise-driven part (a
									// clipped side's edge rests on its dark half and
									// gains more from the noise).
									if (sm.clippedOn(c) == 0 || averaged_arg.getValue())
									{
										ms[pass] += sm.e_P[c] * sm.e_P[c];
										++n[pass];
									}
							}
						if (n[0] < 40 || n[1] < 40) continue;
						size.push_back(t[k].first);
						var.push_back((ms[1] / n[1] - ms[0] / n[0]) / (q - 1));
					}
					// Each bin's difference of two mean squares is noisy (a few
					// hundred samples of a bias-dominated error): averaged with
					// its neighbours' (three bins, two at the ends). Where the
					// error did not grow (the noise dithers part of a
					// pixel-phase bias away, as much as it adds), 1e-4 px: a
					// table's sigmas must be > 0.
					pose::SigmaTable out;
					for (size_t k = 0; k < var.size(); ++k)
					{
						const size_t a = k ? k - 1 : 0, b = std::min(var.size() - 1, k + 1);
						double mean = 0;
						for (size_t i = a; i <= b; ++i) mean += var[i] / double(b - a + 1);
						const double sn = std::sqrt(std::max(mean, 1e-8));
						const double p10 = std::pow(10, std::floor(std::log10(sn)) - 2);
						out.emplace_back(size[k], std::round(sn / p10) * p10);
					}
					return out;
				};
				const pose::SigmaTable nx = split(true, tx), ny = split(false, ty);
				fitted.reference_noise_grey = ref_measured;
				fitted.noise_sigma_x_table = nx;
				fitted.noise_sigma_y_table = ny;
				std::printf(
					"noise split (%zu detections again at noise %.2f, %d missed; the detector "
					"measured %.3f and %.3f):\n"
					"  reference_noise_grey = %.2f\n  noise_sigma_x_table = %s\n"
					"  noise_sigma_y_table = %s\n",
					second.size(), r2.noise_sigma, missed2, ref_measured, second_measured,
					ref_measured, pose::toString(nx).c_str(), pose::toString(ny).c_str());
				// The second pass against the C_P that the split gives at each
				// landmark's measured noise (PoseOptions::noiseScale()): the
				// normalised variances and the general path's corner ratios
				// there, which the noise scaling assumes unchanged.
				if (!nx.empty() && !ny.empty())
				{
					pose::PoseOptions split_options;
					split_options.reference_noise_grey = ref_measured;
					split_options.noise_sigma_x_table = nx;
					split_options.noise_sigma_y_table = ny;
					const auto var2 = [&](const Sample& sm, int c)
					{
						const bool x = c % 2 == 0;
						const double v = var(sm, c);
						return v * split_options.noiseScale(x, sizeOf(sm, x), v, sm.image_noise);
					};
					const Normalised z2 = normalised(second, var2);
					std::printf(
						"  at noise %.2f with the split: normalised variance x %.3f y %.3f; "
						"corner_midpoint_ratio %.2f corner_tilt_ratio %.2f\n",
						r2.noise_sigma, z2.x, z2.y, std::sqrt(z2.midpoint), std::sqrt(z2.tilt));
					// An edge's tilt gains more from the noise than its position
					// (a line fit's end points: the slope's share is 3x the
					// offset's), and less from the detector's bias (whole lines
					// shift): the ratio of its noise-driven part to x's
					// (PoseOptions::corner_tilt_noise_ratio) that makes its
					// normalised variance 1 at the second noise, by bisection.
					// The tilts' reference part: corner_tilt_ratio_table's.
					const auto tiltZ = [&](double k)
					{
						return normalised(
								   second,
								   [&](const Sample& sm, int c) {
									   return tiltRatio2(sm) * var(sm, c) +
											  k * k * (var2(sm, c) - var(sm, c));
								   })
							.tilt;
					};
					double lo = 0, hi = 10;
					if (tiltZ(lo) > 1 && tiltZ(hi) < 1)
					{
						for (int it = 0; it < 50; ++it)
						{
							const double mid = 0.5 * (lo + hi);
							(tiltZ(mid) > 1 ? lo : hi) = mid;
						}
						{
							fitted.corner_tilt_noise_ratio = std::round(50 * (lo + hi)) / 100;
							std::printf("  corner_tilt_noise_ratio = %.2f\n", 0.5 * (lo + hi));
						}
					}
					else
						std::printf(
							"  corner_tilt_noise_ratio: none fits (the tilt's normalised variance "
							"%.2f with none, %.2f at 10)\n",
							tiltZ(lo), tiltZ(hi));
				}
			}
			// The clipped sides' sigma again and the correlation of their
			// shifts, by maximum likelihood of all of P under the pose
			// library's own C_P with the tables above.
			pose::PoseOptions po;
			po.sigma_x_table = tx;
			po.sigma_y_table = ty;
			po.corr_growth_x12 = rx;
			po.corr_growth_y12 = ry;
			po.aligned_edge_ratio = k_aligned;
			double best = 1e300, best_s = fx.clip, best_r = 0;
			for (int i = 1; i <= 20 && n_clipped > 20; ++i)
				for (int j = 0; j <= 9; ++j)
				{
					po.clipped_side_sigma_px = 0.005 * i;
					po.clipped_side_correlation = 0.1 * j;
					double nll = 0;
					for (const auto& sm : samples)
					{
						const Eigen::Matrix4d C =
							po.primaryCovariance(sm.P_true) +
							po.clippedSidesCovariance(sm.clipped) +
							po.alignedEdgesCovariance(sm.P_true, sm.rows_top, sm.rows_bottom);
						const Eigen::LDLT<Eigen::Matrix4d> ldlt(C);
						nll += sm.e_P.dot(ldlt.solve(sm.e_P)) + ldlt.vectorD().array().log().sum();
					}
					if (nll < best)
					{
						best = nll;
						best_s = po.clipped_side_sigma_px;
						best_r = po.clipped_side_correlation;
					}
				}
			std::printf(
				"  all of P: clipped_side_sigma_px %.3f clipped_side_correlation %.1f\n", best_s,
				best_r);
			if (!averaged_arg.getValue())
			{
				fitted.clipped_side_sigma_px = best_s;
				fitted.clipped_side_correlation = best_r;
			}
			else
				fitted.clipped_side_sigma_px = 0;  // averaged into the sigmas
			if (!out_arg.getValue().empty())
			{
				std::string command = "codemark-bench-pose-calib";
				for (int a = 1; a < argc; ++a) command += std::string(" ") + argv[a];
				char data[400];
				std::snprintf(
					data, sizeof data,
					"data: %s renderer, %s, camera preset%s %s, %d renders at %.1f-%.1f m, "
					"view angles up to %.0f deg each; %zu detections, %d missed",
					renderer_arg.getValue().c_str(),
					realistic_arg.getValue()
						? (vary_arg.getValue()
							   ? "realistic scene (textured wall) with prints and lights varied"
							   : "realistic scene (textured wall, light gradient)")
						: "plain background scene",
					presets.size() > 1 ? "s" : "",
					preset_arg.getValue().empty() ? "none" : preset_arg.getValue().c_str(),
					n_arg.getValue(), dmin_arg.getValue(), dmax_arg.getValue(), amax_arg.getValue(),
					samples.size(), missed);
				pose::saveCalibration(
					out_arg.getValue(), fitted,
					{"codemark calibration: the noise model of P for codemark's detector",
					 "made by: " + command, data,
					 "date: " + mrpt::system::dateTimeToString(mrpt::Clock::now())});
				std::printf("wrote %s\n", out_arg.getValue().c_str());
			}
		}
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
