// The EKF on simulated datasets with rendered images (sim::writeDataset),
// detected on the fly: a room loop with 5 Hz images and a 3% odometry scale
// error, both rawlog formats, with the shipped share/codemark/config/ekf.ini.
#include <codemark/filters/outputs.h>
#include <codemark/sim/dataset.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

namespace fs = std::filesystem;
using namespace codemark;
using namespace codemark::filters;

namespace
{
LocalizeSummary runOn(
	bool obs_only, int max_frames, const std::string& method, const std::string& ini,
	bool slam_no_map = false)
{
	sim::DatasetOptions o;
	o.odometry_scale_error = 0.03;
	o.seed = 3;
	const auto dir = fs::temp_directory_path() /
					 ("codemark_test_sim_" + std::to_string(getpid()) + (obs_only ? "_oo" : "_ao"));
	if (!fs::exists(dir / "dataset.rawlog"))
		sim::writeDataset(o, dir.string(), obs_only, {}, max_frames);
	LocalizeRequest req;
	req.config_file = std::string(CODEMARK_SOURCE_SHARE_DIR) + "/config/" + ini;
	req.rawlog = (dir / "dataset.rawlog").string();
	req.map_file = slam_no_map ? "" : (dir / "map.txt").string();
	if (slam_no_map) req.gt_map_file = (dir / "map.txt").string();
	req.gt_file = (dir / "gt_path.txt").string();
	req.method = method;
	return runLocalization(req);
}

// Known shortfall (docs/benchmarks/filters.md): on this dataset (seed 3)
// the ATE is about 4 cm (5 cm observations-only) against the 3 cm:
// the first fix, from one landmark 4 m away whose phi2 is good to ~13 deg,
// is 24 cm off (inside its covariance), which alone adds 2.2 cm to the RMS.
// The mean NEES is about 1.9 (1.6 observations-only), below the 95% band:
// the pipeline's calibrated C_L is conservative on these renders (phi2's
// normalised squared error averages about 0.1, the whole L's d2 about 2.5
// against 3); the filters pass that on honestly rather than rescale it.
// \a nees_factor widens the band by a factor on both sides, so the test
// still fails on overconfidence (the plain EKF's one linearisation gave 15)
// or on covariances inflated further.
void expectConsistent(const LocalizeSummary& s, double max_ate_m, double nees_factor)
{
	ASSERT_TRUE(s.metrics);
	const auto& m = *s.metrics;
	EXPECT_EQ(
		s.first_fix_step, 0);  // first fix at the first sighting (landmarks in view at the start)
	EXPECT_EQ(m.matched, s.steps);
	EXPECT_LE(m.ate_rmse_m, max_ate_m);
	EXPECT_GT(m.nees_mean, m.nees_band_low / nees_factor)
		<< "mean NEES below the 95% band: too pessimistic";
	EXPECT_LT(m.nees_mean, m.nees_band_high * nees_factor)
		<< "mean NEES above the 95% band: overconfident";
	EXPECT_GT(s.sightings_used, s.steps / 2);
	std::cout << s.method << ": " << s.steps << " steps, ATE " << m.ate_rmse_m << " m, max "
			  << m.max_error_m << " m, yaw RMSE " << m.yaw_rmse_deg << " deg, NEES " << m.nees_mean
			  << " in [" << m.nees_band_low << ", " << m.nees_band_high << "], used "
			  << s.sightings_used << ", rejected " << s.sightings_rejected << "\n";
}
}  // namespace

TEST(FiltersSim, EkfAndEkfPoseFullLoopActionsObservations)
{
	expectConsistent(runOn(false, 0, "ekf", "ekf.ini"), 0.045, 1.6);
	expectConsistent(runOn(false, 0, "ekf-pose", "ekf-pose.ini"), 0.045, 1.6);
}

TEST(FiltersSim, EkfObservationsOnlyWithInterpolatedOdometry)
{
	// Odometry noise drawn per 20 Hz reading, interpolated to 5 Hz images.
	expectConsistent(runOn(true, 50, "ekf", "ekf.ini"), 0.06, 1.7);
}

// EKF-SLAM from scratch (no map) on the rendered loop: almost nothing gated,
// landmark yaws and positions close to the truth after the SE(2) alignment
// (they used to drift by hundreds of degrees with most sightings gated).
TEST(FiltersSim, EkfSlamMapsTheRoomWithSmallLandmarkYawErrors)
{
	const LocalizeSummary s = runOn(false, 0, "ekf-slam", "ekf-slam.ini", true);
	ASSERT_TRUE(s.metrics);
	const auto& m = *s.metrics;
	EXPECT_TRUE(m.aligned);
	EXPECT_LE(s.sightings_rejected, s.sightings_used / 50) << "at most 2% gated";
	EXPECT_GE(m.landmarks_matched, 6);
	EXPECT_LT(m.landmark_yaw_rmse_deg, 2.0);
	EXPECT_LT(m.landmark_rmse_m, 0.08);
	EXPECT_LT(m.ate_rmse_m, 0.08);
	std::cout << "ekf-slam: ATE " << m.ate_rmse_m << " m (aligned), NEES " << m.nees_mean
			  << ", landmarks " << m.landmarks_matched << ", landmark RMSE " << m.landmark_rmse_m
			  << " m, yaw RMSE " << m.landmark_yaw_rmse_deg << " deg, used " << s.sightings_used
			  << ", rejected " << s.sightings_rejected << "\n";
}
