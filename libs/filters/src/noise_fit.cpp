// codemark-calibrate-noise's logic: the sighting noise model that maximises
// the likelihood of the EKF's innovations over a recorded run (noise_fit.h).
#include <codemark/filters/ekf.h>
#include <codemark/filters/mrpt_landmarks.h>
#include <codemark/filters/noise_fit.h>
#include <codemark/filters/stepper.h>
#include <codemark/landmark/text.h>
#include <codemark/pipeline/pipeline.h>
#include <mrpt/config/CConfigFile.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace codemark::filters
{
namespace
{
/** The prior's spread of the ratios of the four scales to one another
 * around the starting calibration's: one standard deviation is this factor. */
constexpr double kShapePriorFactor = 2.0;
/** Below this mean share of the sightings in the innovations' covariance
 * (Innovation::sighting_share) the run cannot tell their noise. */
constexpr double kMinSightingShare = 0.25;

// The least-squares fit a^2 + b^2 (ref / w)^2 of a sigma table (exponent
// 1), a^2 and b^2 kept >= 0.
std::pair<double, double> fitTable(const pose::SigmaTable& t, double ref)
{
	double suu = 0, su = 0, sus = 0, ss = 0;
	const double n = static_cast<double>(t.size());
	for (const auto& [w, s] : t)
	{
		const double u = (ref / w) * (ref / w), v = s * s;
		suu += u * u, su += u, sus += u * v, ss += v;
	}
	const double det = n * suu - su * su;
	double A = det > 0 ? (suu * ss - su * sus) / det : ss / n;
	double B = det > 0 ? (n * sus - su * ss) / det : 0.0;
	if (A < 0) A = 0, B = sus / suu;
	if (B < 0) B = 0, A = ss / n;
	return {std::sqrt(A), std::sqrt(B)};
}

// The fit's objective over a run held in memory: the EKF run again with
// every sighting measured under a candidate model.
class RunLikelihood
{
   public:
	RunLikelihood(
		std::vector<RawlogStep> steps, pipeline::PipelineOptions po, EkfOptions ekf,
		LandmarkMap map, std::optional<PoseEstimate> initial)
		: steps_(std::move(steps)),
		  po_(std::move(po)),
		  ekf_(std::move(ekf)),
		  map_(std::move(map)),
		  initial_(std::move(initial))
	{
	}

	InnovationSummary evaluate(const pose::PoseOptions& o) const
	{
		pipeline::PipelineOptions po = po_;
		po.pose = o;
		auto filter = makeEkfLocalizer(EkfMeasurement::Landmark, ekf_, map_, initial_);
		std::vector<std::vector<Innovation>> innovations;
		innovations.reserve(steps_.size());
		for (const auto& step : steps_)
		{
			mrpt::obs::CSensoryFrame sf;
			for (const auto& obs : step.observations)
			{
				if (const auto c = std::dynamic_pointer_cast<CObservationCodedLandmarks>(obs))
					sf.insert(pipeline::remeasure(*c, po));
				else
					sf.insert(obs);
			}
			innovations.push_back(filter->step(step.odometry.get(), sf).innovations);
		}
		std::vector<const std::vector<Innovation>*> steps;
		steps.reserve(innovations.size());
		for (const auto& v : innovations) steps.push_back(&v);
		return summariseInnovations(steps);
	}

   private:
	std::vector<RawlogStep> steps_;
	pipeline::PipelineOptions po_;
	EkfOptions ekf_;
	LandmarkMap map_;
	std::optional<PoseEstimate> initial_;
};

Eigen::Vector4d logOf(const NoiseScales& s)
{
	return {
		std::log(s.sigma_x_px), std::log(s.growth_x_px), std::log(s.sigma_y_px),
		std::log(s.growth_y_px)};
}

NoiseScales scalesOf(const Eigen::Vector4d& v)
{
	return {std::exp(v[0]), std::exp(v[1]), std::exp(v[2]), std::exp(v[3])};
}

// Nelder-Mead's downhill simplex (Lagarias et al. 1998 coefficients) over
// the log-scales. By hand: four parameters and an objective that re-runs a
// filter (no derivatives), and neither MRPT nor Eigen ships a
// derivative-free minimiser.
Eigen::Vector4d nelderMead(
	const std::function<double(const Eigen::Vector4d&)>& f, const Eigen::Vector4d& x0, double step,
	int max_evals, int& evals, const std::function<void(double)>& progress)
{
	constexpr int n = 4;
	std::vector<Eigen::Vector4d> x(n + 1, x0);
	std::vector<double> fx(n + 1);
	for (int i = 0; i < n; ++i) x[i + 1][i] += step;
	auto eval = [&](const Eigen::Vector4d& p)
	{
		++evals;
		if (progress) progress(std::min(1.0, double(evals) / max_evals));
		return f(p);
	};
	for (int i = 0; i <= n; ++i) fx[i] = eval(x[i]);
	while (evals < max_evals)
	{
		std::vector<int> idx(n + 1);
		for (int i = 0; i <= n; ++i) idx[i] = i;
		std::sort(idx.begin(), idx.end(), [&](int a, int b) { return fx[a] < fx[b]; });
		const int best = idx[0], worst = idx[n], second = idx[n - 1];
		double size = 0;
		for (int i = 1; i <= n; ++i)
			size = std::max(size, (x[idx[i]] - x[best]).cwiseAbs().maxCoeff());
		if (std::abs(fx[worst] - fx[best]) < 1e-4 * (1 + std::abs(fx[best])) && size < 0.01) break;
		Eigen::Vector4d c = Eigen::Vector4d::Zero();
		for (int i = 0; i < n; ++i) c += x[idx[i]];
		c /= n;
		const Eigen::Vector4d xr = c + (c - x[worst]);
		const double fr = eval(xr);
		if (fr < fx[best])
		{
			const Eigen::Vector4d xe = c + 2.0 * (c - x[worst]);
			const double fe = eval(xe);
			if (fe < fr)
				x[worst] = xe, fx[worst] = fe;
			else
				x[worst] = xr, fx[worst] = fr;
			continue;
		}
		if (fr < fx[second])
		{
			x[worst] = xr, fx[worst] = fr;
			continue;
		}
		const bool outside = fr < fx[worst];
		const Eigen::Vector4d xc = outside ? c + 0.5 * (xr - c) : c + 0.5 * (x[worst] - c);
		const double fc = eval(xc);
		if (fc < std::min(fr, fx[worst]))
		{
			x[worst] = xc, fx[worst] = fc;
			continue;
		}
		for (int i = 1; i <= n; ++i)  // shrink towards the best
		{
			x[idx[i]] = x[best] + 0.5 * (x[idx[i]] - x[best]);
			fx[idx[i]] = eval(x[idx[i]]);
		}
	}
	const auto it = std::min_element(fx.begin(), fx.end());
	return x[static_cast<size_t>(it - fx.begin())];
}
}  // namespace

pose::PoseOptions parametricNoiseModel(const pose::PoseOptions& in)
{
	pose::PoseOptions o = in;
	const double ref = o.size_reference_px;
	// The scatter model (band_ratio_x) follows the corners' error from
	// camera to camera; a run holds one camera, whose noise the constant
	// and size-dependent parts below describe.
	o.band_ratio_x = o.band_ratio_y = 0;
	o.band_floor_x_table.clear();
	o.band_floor_y_table.clear();
	if (!o.sigma_x_table.empty())
	{
		const auto [a, b] = fitTable(o.sigma_x_table, ref);
		o.sigma_px = a, o.growth_x_px = b, o.size_exponent_x = 1;
		o.corr_x12 = o.corr_growth_x12;
		o.sigma_x_table.clear();
	}
	if (!o.sigma_y_table.empty())
	{
		const auto [a, b] = fitTable(o.sigma_y_table, ref);
		o.sigma_y_px = a, o.growth_y_px = b, o.size_exponent_y = 1;
		o.corr_y12 = o.corr_growth_y12;
		o.sigma_y_table.clear();
	}
	else if (!(o.sigma_y_px > 0))
		o.sigma_y_px = o.sigma_px;
	// A part that is zero cannot be scaled: start it at a quarter of the
	// other (the likelihood decides whether it stays small).
	auto seed = [](double& a, double& b)
	{
		if (!(a > 0) && b > 0) a = 0.25 * b;
		if (!(b > 0) && a > 0) b = 0.25 * a;
		if (!(a > 0)) a = b = 0.05;
	};
	seed(o.sigma_px, o.growth_x_px);
	seed(o.sigma_y_px, o.growth_y_px);
	return o;
}

NoiseScales noiseScales(const pose::PoseOptions& o)
{
	return {o.sigma_px, o.growth_x_px, o.sigmaY(), o.growth_y_px};
}

pose::PoseOptions withNoiseScales(const pose::PoseOptions& in, const NoiseScales& s)
{
	pose::PoseOptions o = in;
	o.sigma_px = s.sigma_x_px;
	o.growth_x_px = s.growth_x_px;
	o.sigma_y_px = s.sigma_y_px;
	o.growth_y_px = s.growth_y_px;
	return o;
}

NoiseFitResult fitSightingNoise(
	const NoiseFitRequest& req, const std::function<void(double)>& progress)
{
	if (!std::ifstream(req.config_file).good())
		throw std::runtime_error(req.config_file + ": cannot open config file");
	mrpt::config::CConfigFile cfg(req.config_file);
	if (req.map_file.empty()) throw std::invalid_argument("a landmark map is required (--map)");
	const LandmarkMap map = loadAnyMap(req.map_file);
	if (map.landmarks.empty())
		throw std::invalid_argument(req.map_file + ": the map has no landmarks");

	// Annotated sightings are measured again: the fit changes C_P anyway.
	ReadingOptions reading;
	EkfOptions eo;
	std::optional<PoseEstimate> initial;
	try
	{
		reading = readingOptions(
			cfg, req.calibration.empty() ? pipeline::kDefaultCalibration : req.calibration,
			isMrptLandmarksFile(req.map_file) ? std::nullopt : std::optional(map));
		eo.loadFromConfigFile(cfg, "ekf");
		initial = initialPose(cfg);
	}
	catch (const std::exception&)
	{
		rethrowNamingIniFile(req.config_file);	// "FILE:LINE: [SECTION] KEY: ..."
	}
	auto& [so, po] = reading;
	if (!req.camera_file.empty()) po.camera_override = CameraModel::load(req.camera_file);

	NoiseFitResult r;
	std::vector<RawlogStep> steps;
	{
		RawlogStepper stepper(req.rawlog, so, po);
		RawlogStep s;
		while (stepper.next(s))
		{
			for (const auto& o : s.observations)
				if (const auto c = std::dynamic_pointer_cast<CObservationCodedLandmarks>(o))
					for (const auto& t : c->sightings)
					{
						if (!map.find(t.id)) continue;
						const double w = t.P[2] - t.P[0];
						r.width_min_px = r.sightings ? std::min(r.width_min_px, w) : w;
						r.width_max_px = r.sightings ? std::max(r.width_max_px, w) : w;
						++r.sightings;
					}
			steps.push_back(std::move(s));
			s = RawlogStep();
			if (progress) progress(0.5 * stepper.progress());
		}
	}
	r.steps = static_cast<long>(steps.size());
	if (r.sightings == 0)
		throw std::runtime_error(
			req.rawlog + ": no sighting of a landmark of " + req.map_file +
			" (nothing to calibrate from)");

	const RunLikelihood run(std::move(steps), po, eo, map, initial);
	r.before = run.evaluate(po.pose);
	r.start = parametricNoiseModel(po.pose);
	r.start_scales = noiseScales(r.start);
	// The objective: the innovations' negative log-likelihood plus a
	// log-normal prior on the model's shape only. The common level of the
	// four scales is free (the run sets it); their ratios to one another
	// keep the start's within about kShapePriorFactor unless the run says
	// otherwise. Without it a combination the run does not see (e.g. x's
	// constant part when the odometry's error dominates the bearing's
	// innovations) drifts to zero or infinity.
	const Eigen::Vector4d v0 = logOf(r.start_scales);
	const double tau = std::log(kShapePriorFactor);
	auto prior = [&](const Eigen::Vector4d& v)
	{
		const Eigen::Vector4d d = v - v0;
		return 0.5 * (d.array() - d.mean()).square().sum() / (tau * tau);
	};
	auto f = [&](const Eigen::Vector4d& v)
	{
		if ((v - v0).cwiseAbs().maxCoeff() > std::log(1000.0))
			return std::numeric_limits<double>::infinity();
		return run.evaluate(withNoiseScales(r.start, scalesOf(v))).neg_log_likelihood + prior(v);
	};
	const Eigen::Vector4d best = nelderMead(
		f, logOf(r.start_scales), std::log(2.0), req.max_evaluations, r.evaluations,
		progress ? std::function<void(double)>([&](double x) { progress(0.5 + 0.45 * x); })
				 : std::function<void(double)>());
	r.fitted_scales = scalesOf(best);
	r.fitted = withNoiseScales(r.start, r.fitted_scales);
	r.after = run.evaluate(r.fitted);

	// The curvature of the negative log-likelihood at the optimum (central
	// differences in the log-scales) gives each scale's uncertainty. A
	// sighting that crosses the gate between two evaluations makes the
	// likelihood step, not curve: when the differences at one step are not
	// a positive definite curvature, they are taken again at wider steps,
	// which average over such steps.
	const double f0 = r.after.neg_log_likelihood + prior(best);
	auto hessian = [&](double h)
	{
		Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
		for (int i = 0; i < 4; ++i)
			for (int j = i; j < 4; ++j)
			{
				auto at = [&](double di, double dj)
				{
					Eigen::Vector4d v = best;
					v[i] += di;
					v[j] += dj;
					++r.evaluations;
					return f(v);
				};
				H(i, j) = H(j, i) =
					i == j ? (at(h, 0) - 2 * f0 + at(-h, 0)) / (h * h)
						   : (at(h, h) - at(h, -h) - at(-h, h) + at(-h, -h)) / (4 * h * h);
			}
		return H;
	};
	auto positiveDefinite = [](const Eigen::Matrix4d& H)
	{
		return H.allFinite() &&
			   Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(H).eigenvalues().minCoeff() > 0;
	};
	Eigen::Matrix4d H;
	bool curved = false;
	for (const double h : {0.05, 0.15, 0.4})
		if ((curved = positiveDefinite(H = hessian(h)))) break;
	if (progress) progress(1.0);
	const char* names[4] = {"sigma_px", "growth_x_px", "sigma_y_px", "growth_y_px"};
	if (!curved)
	{
		r.relative_std.setConstant(std::numeric_limits<double>::infinity());
		r.warnings.emplace_back(
			"the likelihood is flat along some combination of the scales: the run does not "
			"identify the model (more sightings at more distances help)");
	}
	else
	{
		const Eigen::Matrix4d C = H.inverse();
		for (int i = 0; i < 4; ++i)
		{
			r.relative_std[i] = std::sqrt(C(i, i));
			if (r.relative_std[i] > 0.7 * tau)
			{
				std::ostringstream w;
				w << names[i] << " is barely informed by this run (+-"
				  << std::lround(100 * r.relative_std[i])
				  << "%): its ratio to the other scales stays near the starting calibration's";
				r.warnings.push_back(w.str());
			}
		}
	}
	if (r.after.sighting_share < kMinSightingShare)
	{
		std::ostringstream w;
		w << "the sightings make only " << std::lround(100 * r.after.sighting_share)
		  << "% of the innovations' covariance (the odometry's prediction the rest): the run "
			 "barely sees the sightings' noise (finer odometry, or more landmarks in view at once, "
			 "help)";
		r.warnings.push_back(w.str());
	}
	// The components the sightings barely inform (the bearing) test the
	// motion noise, which this fit holds fixed: their NIS reads the same
	// whatever C_P.
	const PredictionCheck pc = predictionCheck(r.after, kInnovationComponents);
	if (pc.off())
	{
		std::ostringstream w;
		w << std::setprecision(2) << "the " << pc.components
		  << " innovations are the odometry's prediction (the sightings under "
		  << std::lround(100 * kPredictionComponentShare)
		  << "% of their variance) and read NIS/DoF " << pc.ratio
		  << ": the motion noise, held fixed here, looks " << pc.verdict
		  << " (the odometry's model in the rawlog, the config's [ekf] extra_motion_var_*)";
		r.warnings.push_back(w.str());
	}
	if (r.after.persistent_errors)
	{
		std::ostringstream w;
		w << std::setprecision(2) << "the first sightings of each landmark visit read NIS/DoF "
		  << r.after.visit_ratio << " against " << r.after.other_ratio
		  << " for the others: the sightings' errors persist from frame to frame; the constant "
			 "noise found absorbs the jumps between landmarks, so the filter's state covariance "
			 "may be wider than its errors (docs/calibration.md)";
		r.warnings.push_back(w.str());
	}
	if (r.sightings < 30)
		r.warnings.push_back(
			"only " + std::to_string(r.sightings) +
			" sightings: too few to identify four scales (record a longer run)");
	if (r.width_max_px < 1.5 * r.width_min_px)
		r.warnings.emplace_back(
			"the landmarks were seen at one apparent size only: the constant and "
			"size-dependent parts cannot be told apart (drive nearer and farther)");
	return r;
}

}  // namespace codemark::filters
