// Innovation consistency on rendered room loops: every filter's NIS verdict
// tells sightings whose covariances are 5x too small (C_P / 25) or 3x too
// large (C_P x 9) from those of the calibration fitted on the same image
// source (realistic: the simulated renders' linear light), and
// codemark-calibrate-noise's fit, started from either wrong model, gives
// the filter back its accuracy and an honest NIS.
//
// The loops' odometry is a fine wheel odometry (0.5% of the distance,
// floors 0.5 mm and 0.02 deg per reading): the innovations see the
// sightings' noise only where the odometry's prediction is tighter than the
// sightings (Innovation::sighting_share); with codemark-simul's coarser
// default odometry the prediction dominates S and the verdict is blind to a
// factor of 9 in C_P (docs/design.md).
#include <codemark/filters/noise_fit.h>
#include <codemark/eval/localization.h>
#include <codemark/pipeline/annotate.h>
#include <codemark/pose/calibration.h>
#include <codemark/sim/dataset.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <regex>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace codemark;
using namespace codemark::filters;
using namespace codemark::eval;

namespace
{
constexpr int kSeeds = 3;

struct Loop
{
	fs::path dir;
	std::string rawlog, map, gt;
};

// Seed \a seed's loop, annotated with the realistic calibration (images
// dropped), written once per process.
const Loop& loop(unsigned seed)
{
	static std::map<unsigned, Loop> loops;
	if (auto it = loops.find(seed); it != loops.end()) return it->second;
	Loop l;
	l.dir = fs::temp_directory_path() /
			("codemark_test_nis_" + std::to_string(getpid()) + "_seed" + std::to_string(seed));
	fs::create_directories(l.dir);
	sim::DatasetOptions o;
	o.seed = seed;
	auto& g = o.motion.gaussianModel;
	g.a1 = 0.005, g.a2 = 0.001, g.a3 = 0.005, g.a4 = 0.01;
	g.minStdXY = 0.0005, g.minStdPHI = 0.02 * M_PI / 180.0;
	sim::writeDataset(o, l.dir.string(), false);
	pipeline::AnnotateOptions ao;
	ao.pipeline.pose = pipeline::calibratedPoseOptions("realistic");
	ao.drop_images = true;
	ao.threads = 2;
	l.rawlog = (l.dir / "annotated.rawlog").string();
	pipeline::annotateRawlog((l.dir / "dataset.rawlog").string(), l.rawlog, ao);
	l.map = (l.dir / "map.txt").string();
	l.gt = (l.dir / "gt_path.txt").string();
	return loops[seed] = l;
}

// The realistic calibration with every sigma multiplied by \a factor, as a
// file.
std::string scaledCalibration(double factor)
{
	const auto path = fs::temp_directory_path() / ("codemark_test_nis_" + std::to_string(getpid()) +
												   "_x" + std::to_string(factor) + ".ini");
	pose::saveCalibration(
		path.string(),
		pose::scaledNoiseModel(
			pose::loadCalibration(pose::shippedCalibrationPath("realistic")), factor),
		{"realistic x " + std::to_string(factor)});
	return path.string();
}

LocalizeSummary localize(const Loop& l, const std::string& method, const std::string& calibration)
{
	LocalizeRequest req;
	req.config_file = std::string(CODEMARK_SOURCE_SHARE_DIR) + "/config/" + method + ".ini";
	req.rawlog = l.rawlog;
	req.map_file = l.map;
	req.gt_file = l.gt;
	req.method = method;
	req.calibration = calibration;
	return runLocalization(req);
}

bool startsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }
}  // namespace

class NisVerdict : public ::testing::TestWithParam<std::string>
{
};

TEST_P(NisVerdict, TellsWrongSightingCovariancesFromTheSourcesOwn)
{
	const std::string method = GetParam();
	const std::string own = pose::shippedCalibrationPath("realistic");
	const std::string small = scaledCalibration(1.0 / 5.0), large = scaledCalibration(3.0);
	std::array<double, 3> log_ratio_sum{};
	std::array<int, 3> prediction_dominated{};
	for (unsigned seed = 1; seed <= kSeeds; ++seed)
	{
		const Loop& l = loop(seed);
		const LocalizeSummary s0 = localize(l, method, own), s_small = localize(l, method, small),
							  s_large = localize(l, method, large);
		std::cout << method << " seed " << seed << ": own " << s0.nis_mean / s0.nis_dof << " ("
				  << s0.nis_verdict << "), C_P/25 " << s_small.nis_mean / s_small.nis_dof << " ("
				  << s_small.nis_verdict << "), C_P*9 " << s_large.nis_mean / s_large.nis_dof
				  << " (" << s_large.nis_verdict << ")\n";
		const auto& names = innovationComponentNames(method);
		std::cout << "  per component, own / C_P*9 (sightings' share):";
		for (size_t i = 0; i < 3; ++i)
			std::cout << ' ' << names[i] << ' ' << s0.nis_component_mean[i] << " / "
					  << s_large.nis_component_mean[i] << " (" << s0.nis_component_share[i] << ")";
		std::cout << '\n';
		// Per component: sightings 3x too wide lower the NIS of a component
		// the sightings dominate, and hardly that of one the prediction
		// dominates (L's bearing), which dilutes the mean. The latter over
		// the seeds (below): one run's mean NIS of a component that the
		// prediction's spread dominates varies by a quarter from run to run.
		for (size_t i = 0; i < 3; ++i)
		{
			const double share = s0.nis_component_share[i];
			if (!std::isfinite(share)) continue;
			const double ratio = s_large.nis_component_mean[i] / s0.nis_component_mean[i];
			if (share >= 0.3)
			{
				EXPECT_LT(ratio, 0.6) << method << " seed " << seed << ' ' << names[i];
			}
			if (share < 0.01)
			{
				log_ratio_sum[i] += std::log(ratio);
				++prediction_dominated[i];
			}
		}
		EXPECT_GT(s0.nis_count, 50);
		EXPECT_EQ(s0.nis_verdict, "consistent") << method << " seed " << seed;
		EXPECT_TRUE(startsWith(s_small.nis_verdict, "covariances too small"))
			<< method << " seed " << seed << ": " << s_small.nis_verdict;
		EXPECT_TRUE(startsWith(s_large.nis_verdict, "covariances too large"))
			<< method << " seed " << seed << ": " << s_large.nis_verdict;
		// Over-confident sightings are gated in every filter and counted.
		EXPECT_GT(s_small.gated_fraction, s0.gated_fraction);
		long gated = 0;
		for (const auto& r : s_small.rows)
			for (const auto& in : r.stats.innovations) gated += in.gated ? 1 : 0;
		EXPECT_GT(gated, 0);
		EXPECT_GE(s_small.sightings_rejected, gated);
	}
	const auto& names = innovationComponentNames(method);
	for (size_t i = 0; i < 3; ++i)
		if (prediction_dominated[i] > 0)
		{
			EXPECT_GT(std::exp(log_ratio_sum[i] / prediction_dominated[i]), 0.8)
				<< method << ' ' << names[i] << ": geometric mean over " << prediction_dominated[i]
				<< " seeds";
		}
}

INSTANTIATE_TEST_SUITE_P(
	EveryFilter, NisVerdict, ::testing::Values("ekf", "ekf-pose", "ekf-slam", "pf"),
	[](const auto& info)
	{
		std::string n = info.param;
		for (auto& c : n)
			if (c == '-') c = '_';
		return n;
	});

// codemark-calibrate-noise's fit from C_P / 9 and from C_P x 9: both end
// at the same model within its uncertainty, with a consistent NIS verdict,
// the EKF's ATE within 10% of the ATE with the source's own calibration and
// its NEES near the band.
TEST(CalibrateNoise, FitFromWrongModelsRestoresTheFilter)
{
	for (unsigned seed = 1; seed <= kSeeds; ++seed)
	{
		const Loop& l = loop(seed);
		const LocalizeSummary own = localize(l, "ekf", pose::shippedCalibrationPath("realistic"));
		std::vector<NoiseFitResult> fits;
		for (const double factor : {1.0 / 3.0, 3.0})
		{
			NoiseFitRequest req;
			req.rawlog = l.rawlog;
			req.map_file = l.map;
			req.config_file = std::string(CODEMARK_SOURCE_SHARE_DIR) + "/config/ekf.ini";
			req.calibration = scaledCalibration(factor);
			const NoiseFitResult r = fitSightingNoise(req);
			const auto out = l.dir / ("fit_" + std::to_string(factor) + ".ini");
			pose::saveCalibration(out.string(), r.fitted, {"test fit"});
			const LocalizeSummary s = localize(l, "ekf", out.string());
			ASSERT_TRUE(s.metrics && own.metrics);
			std::cout << "seed " << seed << " from x" << factor << ": NIS/dof "
					  << r.before.nis_mean / r.before.nis_dof << " -> "
					  << r.after.nis_mean / r.after.nis_dof << ", ATE " << s.metrics->ate_rmse_m
					  << " m (own calibration " << own.metrics->ate_rmse_m << " m), NEES "
					  << s.metrics->nees_mean << " (own " << own.metrics->nees_mean << ", band ["
					  << s.metrics->nees_band_low << ", " << s.metrics->nees_band_high << "])\n";
			EXPECT_EQ(s.nis_verdict, "consistent") << "seed " << seed << " from x" << factor;
			EXPECT_LE(s.metrics->ate_rmse_m, 1.10 * own.metrics->ate_rmse_m)
				<< "seed " << seed << " from x" << factor;
			EXPECT_LT(r.after.neg_log_likelihood, r.before.neg_log_likelihood);
			EXPECT_GE(r.after.sighting_share, 0.25) << "the run identifies the sightings' noise";
			EXPECT_TRUE(r.relative_std.allFinite() && (r.relative_std.array() > 0).all())
				<< "every scale has an uncertainty: " << r.relative_std.transpose();
			// NEES against the truth near its band: the innovations miss the
			// part of the sightings' error that persists from frame to frame
			// (docs/design.md), so the band is widened by 1.5 on both sides
			// (the source's own calibration is below the band on these loops).
			EXPECT_GT(s.metrics->nees_mean, s.metrics->nees_band_low / 1.5);
			EXPECT_LT(s.metrics->nees_mean, s.metrics->nees_band_high * 1.5);
			fits.push_back(r);
		}
		// Both starts identify the same model: each scale within three of
		// its standard deviations (the prior ties the scales' ratios to the
		// start's, which differ by a common factor only).
		const auto a = fits[0].fitted_scales, b = fits[1].fitted_scales;
		const double ra[4] = {a.sigma_x_px, a.growth_x_px, a.sigma_y_px, a.growth_y_px};
		const double rb[4] = {b.sigma_x_px, b.growth_x_px, b.sigma_y_px, b.growth_y_px};
		for (int i = 0; i < 4; ++i)
			EXPECT_LT(std::abs(std::log(ra[i] / rb[i])), 3 * fits[0].relative_std[i])
				<< "seed " << seed << " scale " << i;
	}
}

// The bearing's innovation is nearly all the odometry's prediction on these
// loops (the image pins phi1 far tighter), so its NIS tests the motion
// noise the fit holds fixed: codemark-calibrate-noise warns when a config
// adds far more motion noise per step than the fine odometry has, and not
// when the config adds none.
TEST(CalibrateNoise, WarnsOfAMotionNoiseThePredictionsComponentContradicts)
{
	const Loop& l = loop(1);
	std::ifstream in(std::string(CODEMARK_SOURCE_SHARE_DIR) + "/config/ekf.ini");
	const std::string shipped{std::istreambuf_iterator<char>(in), {}};
	auto motionWarnings = [&](const std::string& var)
	{
		const std::regex key(R"(\n(extra_motion_var_(xy_m2|yaw_rad2)) *= *[^\n]*)");
		EXPECT_TRUE(std::regex_search(shipped, key)) << "the shipped ekf.ini sets the key";
		const auto path = l.dir / ("ekf_motion_" + var + ".ini");
		std::ofstream(path) << std::regex_replace(shipped, key, "\n$1 = " + var);
		NoiseFitRequest req;
		req.rawlog = l.rawlog;
		req.map_file = l.map;
		req.config_file = path.string();
		req.calibration = pose::shippedCalibrationPath("realistic");
		const NoiseFitResult r = fitSightingNoise(req);
		std::vector<std::string> found;
		for (const auto& w : r.warnings)
			if (w.find("motion noise") != std::string::npos) found.push_back(w);
		std::cout << "extra motion variance " << var << ": bearing NIS " << r.after.component_nis[1]
				  << " (sightings' share " << r.after.component_share[1] << "), " << found.size()
				  << " warning(s)\n";
		for (const auto& w : found) std::cout << "  " << w << "\n";
		return found;
	};
	const auto none = motionWarnings("0");
	const auto large = motionWarnings("1e-4");
	EXPECT_TRUE(none.empty());
	ASSERT_EQ(large.size(), 1u);
	EXPECT_NE(large[0].find("bearing"), std::string::npos) << large[0];
	EXPECT_NE(large[0].find("too large"), std::string::npos) << large[0];
}
