// Ground-truth files, metrics and the whole codemark-localize run on a
// synthetic rawlog of landmark observations (no images).
#include <codemark/eval/ground_truth.h>
#include <codemark/eval/localization.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <nlohmann/json.hpp>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/serialization/CArchive.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "../filters/common.h"

using namespace codemark;
using namespace codemark::filters;
using namespace codemark::eval;
using namespace codemark::filters::test;
using mrpt::poses::CPose2D;
namespace fs = std::filesystem;

namespace
{
fs::path tempDir()
{
	const auto dir =
		fs::temp_directory_path() / ("codemark_test_outputs_" + std::to_string(getpid()));
	fs::create_directories(dir);
	return dir;
}

std::string writeText(const std::string& name, const std::string& text)
{
	const auto p = (tempDir() / name).string();
	std::ofstream(p) << text;
	return p;
}
}  // namespace

TEST(GroundTruth, TimestampedRowsMatchByTimestamp)
{
	const auto gt = GroundTruth::load(
		writeText("gt.txt", "# t x y yaw\n100.000000 1 2 0.5\n100.200000 1.1 2 0.6\n"));
	EXPECT_EQ(gt.form(), GroundTruth::Form::Timestamped);
	ASSERT_TRUE(gt.poseAt(7, 100.2000004));
	EXPECT_DOUBLE_EQ(gt.poseAt(7, 100.2000004)->x(), 1.1);
	EXPECT_FALSE(gt.poseAt(0, 100.1));
}

TEST(GroundTruth, MrptPathStepIMatchesRowIPlusOne)
{
	const auto gt = GroundTruth::load(writeText(
		"path.txt", "% x y z yaw pitch roll\n0 0 0 0 0 0\n1 0 0 0.1 0 0\n2 0 0 0.2 0 0\n"));
	EXPECT_EQ(gt.form(), GroundTruth::Form::MrptPath);
	ASSERT_TRUE(gt.poseAt(0, 12345.0));
	EXPECT_DOUBLE_EQ(gt.poseAt(0, 0)->x(), 1.0);
	EXPECT_NEAR(gt.poseAt(1, 0)->phi(), 0.2, 1e-12);
	EXPECT_FALSE(gt.poseAt(2, 0));
}

TEST(GroundTruth, MrptPathRowIsTheActionCountWhenGiven)
{
	const auto gt = GroundTruth::load(writeText(
		"path_actions.txt", "% x y z yaw pitch roll\n0 0 0 0 0 0\n1 0 0 0.1 0 0\n2 0 0 0.2 0 0\n"));
	// A frame ahead of the first action: row 0, whatever its step index.
	ASSERT_TRUE(gt.poseAt(0, 0, 1e-3, 0));
	EXPECT_DOUBLE_EQ(gt.poseAt(0, 0, 1e-3, 0)->x(), 0.0);
	// Step 1 after 1 action (the leading frame was step 0): row 1, not 2.
	EXPECT_DOUBLE_EQ(gt.poseAt(1, 0, 1e-3, 1)->x(), 1.0);
	EXPECT_DOUBLE_EQ(gt.poseAt(1, 0, 1e-3, 2)->x(), 2.0);
	EXPECT_FALSE(gt.poseAt(0, 0, 1e-3, 3));
	// The timestamped form ignores the action count.
	const auto ts = GroundTruth::load(writeText("gt_actions.txt", "100.0 1 2 0.5\n"));
	EXPECT_TRUE(ts.poseAt(5, 100.0, 1e-3, 0));
}

TEST(GroundTruth, BadRowsNameFileAndLine)
{
	try
	{
		GroundTruth::load(writeText("bad.txt", "1 2 3 4\n1 2 x 4\n"));
		FAIL();
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("bad.txt:2"), std::string::npos) << e.what();
	}
	EXPECT_THROW(GroundTruth::load(writeText("cols.txt", "1 2 3\n")), std::runtime_error);
	EXPECT_THROW(
		GroundTruth::load(writeText("mixed.txt", "1 2 3 4\n1 2 3 4 5 6\n")), std::runtime_error);
}

TEST(Metrics, KnownErrors)
{
	std::vector<PathRow> rows(2);
	for (auto& r : rows)
	{
		r.estimate.initialized = true;
		r.estimate.cov = Eigen::Vector3d(0.01, 0.01, 0.01).asDiagonal();
	}
	rows[0].estimate.mean = CPose2D(0.3, 0.4, 0.1);
	rows[0].truth = CPose2D(0, 0, 0);
	rows[1].estimate.mean = CPose2D(1, 1, M_PI - 0.05);
	rows[1].truth = CPose2D(1, 1, -M_PI + 0.05);  // 0.1 rad across the cut
	const auto m = computeMetrics(rows);
	ASSERT_TRUE(m);
	EXPECT_EQ(m->matched, 2);
	EXPECT_NEAR(m->ate_rmse_m, std::sqrt(0.25 / 2), 1e-12);
	EXPECT_NEAR(m->max_error_m, 0.5, 1e-12);
	EXPECT_NEAR(m->yaw_rmse_deg, 0.1 * 180 / M_PI, 1e-9);
	EXPECT_NEAR(m->nees_mean, ((0.25 + 0.01) / 0.01 + 0.01 / 0.01) / 2, 1e-9);
	EXPECT_LT(m->nees_band_low, 3.0);
	EXPECT_GT(m->nees_band_high, 3.0);
}

TEST(Localize, EndToEndOnLandmarkObservationsWritesEveryOutput)
{
	// A robot turning on a circle in the test room, actions-observations
	// format, sightings of the landmarks it faces.
	const LandmarkMap map = roomMap();
	const auto dir = tempDir() / "run";
	fs::create_directories(dir);
	map.save((dir / "map.txt").string());
	const std::string rawlog = (dir / "in.rawlog").string();
	std::ofstream gt(dir / "gt.txt");
	gt << std::fixed;
	std::mt19937 rng(5);
	{
		mrpt::io::CFileGZOutputStream f(rawlog);
		auto ar = mrpt::serialization::archiveFrom(f);
		const auto cam = cameraOnRobot();
		// A circle of radius 1 m about (3, 2.1): truth_k = truth_{k-1} (+) u.
		const CPose2D u(0.05, 0, 0.05);
		CPose2D truth(3, 1.1, 0);
		for (int k = 0; k < 120; ++k)
		{
			if (k > 0) truth = truth + u;
			mrpt::obs::CActionCollection acts;
			acts.insert(odometry(k ? u : CPose2D(), 0.002, 0.002));
			ar << acts;
			std::vector<CObservationCodedLandmarks::TSighting> s;
			for (const auto& l : map.landmarks)
			{
				const auto sg = sighting(truth, cam, l, Eigen::Vector3d(0.01, 0.002, 0.01), &rng);
				if (std::abs(sg.L[1]) < 0.4 && std::abs(sg.L[2]) < 1.0) s.push_back(sg);
			}
			auto sf = frameOf(s);
			const double t = 1700000000.0 + 0.2 * k;
			for (auto& o : sf) o->timestamp = mrpt::Clock::fromDouble(t);
			ar << sf;
			gt << std::setprecision(6) << t << ' ' << truth.x() << ' ' << truth.y() << ' '
			   << truth.phi() << '\n';
		}
	}
	gt.close();
	LocalizeRequest req;
	req.config_file =
		writeText("ekf.ini", "[localize]\nmethod = ekf\n[ekf]\ngate_probability = 0.999\n");
	req.rawlog = rawlog;
	req.map_file = (dir / "map.txt").string();
	req.gt_file = (dir / "gt.txt").string();
	req.out_dir = (dir / "out").string();
	const auto s = runLocalization(req);
	EXPECT_EQ(s.method, "ekf");
	EXPECT_EQ(s.steps, 120);
	EXPECT_GT(s.sightings_used, 100);
	ASSERT_TRUE(s.metrics);
	EXPECT_LT(s.metrics->ate_rmse_m, 0.02);
	for (const char* f :
		 {"estimated_path.txt", "estimated_path.tum", "covariances.txt", "innovations.txt",
		  "trajectory.png", "trajectory.3Dscene", "summary.json"})
	{
		EXPECT_TRUE(fs::exists(fs::path(req.out_dir) / f)) << f;
		EXPECT_GT(fs::file_size(fs::path(req.out_dir) / f), 100u) << f;
	}
	// The plot: an image with drawn content, not a blank canvas.
	const cv::Mat plot = cv::imread((fs::path(req.out_dir) / "trajectory.png").string());
	ASSERT_FALSE(plot.empty());
	cv::Mat grey;
	cv::cvtColor(plot, grey, cv::COLOR_BGR2GRAY);
	EXPECT_GT(cv::countNonZero(grey < 128), 1000) << "lines, labels and the path";
	std::ifstream path(fs::path(req.out_dir) / "estimated_path.txt");
	std::string line;
	std::getline(path, line);
	std::getline(path, line);
	double t, x, y, yaw;
	ASSERT_TRUE(std::istringstream(line) >> t >> x >> y >> yaw);
	EXPECT_NE(line.find(".000000 "), std::string::npos) << line;  // >= 6 decimals
	std::ifstream js(fs::path(req.out_dir) / "summary.json");
	const std::string json((std::istreambuf_iterator<char>(js)), {});
	const auto parsed = nlohmann::json::parse(json);  // valid JSON, or it throws
	for (const char* k :
		 {"steps", "sightings_used", "sightings_rejected", "sightings_unknown_id",
		  "time_per_step_ms", "ate_rmse_m", "max_error_m", "yaw_rmse_deg", "nees_mean",
		  "nees_band_95", "nis_mean", "nis_dof", "nis_count", "gated_fraction", "nis_verdict"})
		EXPECT_TRUE(parsed.contains(k)) << k;
	EXPECT_EQ(parsed["nees_band_95"].size(), 2u);
	// Per component of L, by name, with the sighting's share of its variance.
	for (size_t i = 0; i < 3; ++i)
	{
		const auto& c = parsed["nis_components"][kInnovationComponents[i]];
		EXPECT_NEAR(c["nis"].get<double>(), s.nis_component_mean[i], 1e-4);
		EXPECT_NEAR(c["sighting_share"].get<double>(), s.nis_component_share[i], 1e-4);
		EXPECT_GT(s.nis_component_share[i], 0.0);
		EXPECT_LE(s.nis_component_share[i], 1.0);
	}
	EXPECT_TRUE(parsed["calibration"].is_null()) << "no --calibration: stored covariances";
	// With a calibration, summary.json names the file that measured.
	LocalizeSummary with_cal;
	with_cal.method = "ekf";
	with_cal.calibration = "/some/where/plain.ini";
	EXPECT_EQ(nlohmann::json::parse(summaryJson(with_cal))["calibration"], with_cal.calibration);

	// Bad input: one error naming the file.
	req.map_file = writeText("badmap.txt", "1 2 3\n");
	try
	{
		runLocalization(req);
		FAIL();
	}
	catch (const std::exception& e)
	{
		EXPECT_NE(std::string(e.what()).find("badmap.txt"), std::string::npos) << e.what();
	}

	// A refused value in the config file: its file, line, section and key,
	// for every filter's options and the stepper's.
	req.map_file = (dir / "map.txt").string();
	for (const auto& [text, where] : std::vector<std::pair<std::string, std::string>>{
			 {"[localize]\nmethod = ekf\n[ekf]\n\ngate_probability = 2\n",
			  ":5: [ekf] gate_probability: must be in (0, 1)"},
			 {"[localize]\nmethod = ekf-pose\n[ekf]\nconverged_std_xy_m = 0\n",
			  ":4: [ekf] converged_std_xy_m: must be > 0"},
			 {"[localize]\nmethod = ekf\n[stepper]\nmax_view_angle_deg = -3\n",
			  ":4: [stepper] max_view_angle_deg: must be > 0"},
			 {"[localize]\nmethod = ekf-slam\n[ekf_slam]\nstd_sensor_range = 0\n",
			  ":4: [ekf_slam] std_sensor_range: must be > 0"},
			 {"[localize]\nmethod = pf\n[ParticleFilter]\nparticles_count = 0\n",
			  ":4: [ParticleFilter] particles_count: must be > 0"}})
	{
		req.config_file = writeText("bad-key.ini", text);
		try
		{
			runLocalization(req);
			ADD_FAILURE() << "accepted: " << text;
		}
		catch (const std::invalid_argument& e)
		{
			EXPECT_NE(std::string(e.what()).find(req.config_file + where), std::string::npos)
				<< e.what();
		}
	}
	// An unknown method is the config file's error only when the file names it.
	for (const bool from_file : {true, false})
	{
		req.config_file =
			writeText("method.ini", from_file ? "[localize]\nmethod = ekff\n" : "[localize]\n");
		req.method = from_file ? "" : "ekff";
		try
		{
			runLocalization(req);
			ADD_FAILURE() << "accepted method 'ekff'";
		}
		catch (const std::invalid_argument& e)
		{
			const std::string m = e.what();
			EXPECT_NE(m.find("unknown localization method 'ekff'"), std::string::npos) << m;
			EXPECT_EQ(m.find(req.config_file) != std::string::npos, from_file) << m;
		}
	}
}

// SLAM's frame is its own start: the metrics align it to the truth (SE(2)
// least squares). A rotated and shifted copy of the truth has zero error
// after alignment, and the recovered transform is the inverse shift.
TEST(Metrics, AlignSE2RecoversARigidTransform)
{
	const CPose2D truth_T_est(1.5, -0.7, 0.4);
	std::vector<PathRow> rows(20);
	for (std::size_t i = 0; i < rows.size(); ++i)
	{
		const double a = 0.3 * static_cast<double>(i);
		const CPose2D truth(2 * std::cos(a), std::sin(a), a + 0.1);
		rows[i].truth = truth;
		rows[i].estimate.initialized = true;
		rows[i].estimate.mean = CPose2D() - truth_T_est + truth;
		rows[i].estimate.cov = Eigen::Matrix3d::Identity() * 1e-4;
	}
	const auto plain = computeMetrics(rows);
	ASSERT_TRUE(plain);
	EXPECT_GT(plain->ate_rmse_m, 0.5);
	const auto m = computeMetrics(rows, true);
	ASSERT_TRUE(m);
	EXPECT_TRUE(m->aligned);
	EXPECT_LT(m->ate_rmse_m, 1e-9);
	EXPECT_LT(m->yaw_rmse_deg, 1e-7);
	EXPECT_NEAR(m->truth_T_estimate.x(), truth_T_est.x(), 1e-9);
	EXPECT_NEAR(m->truth_T_estimate.y(), truth_T_est.y(), 1e-9);
	EXPECT_NEAR(m->truth_T_estimate.phi(), truth_T_est.phi(), 1e-9);
	// Anchored at the true first pose, a rigid copy has no error either...
	EXPECT_LT(m->ate_rmse_anchored_m, 1e-9);
	// ...but a yaw error at the start swings the anchored path away, which
	// the least-squares fit partly absorbs.
	auto bent = rows;
	bent[0].estimate.mean = bent[0].estimate.mean + CPose2D(0, 0, 0.05);
	const auto mb = computeMetrics(bent, true);
	ASSERT_TRUE(mb);
	EXPECT_GT(mb->ate_rmse_anchored_m, mb->ate_rmse_m);
	LocalizeSummary ls;
	ls.method = "ekf-slam";
	ls.metrics = m;
	EXPECT_NE(summaryJson(ls).find("\"alignment\": \"se2_least_squares\""), std::string::npos);
	EXPECT_NE(summaryJson(ls).find("\"ate_rmse_anchored_m\""), std::string::npos);
}

// alignPath(): the same rigid copy, through the rows' positions only.
TEST(Metrics, AlignPathRecoversARigidTransformAndNeedsTwoRows)
{
	const CPose2D truth_T_est(-0.4, 2.1, -1.2);
	std::vector<PathRow> rows(12);
	for (std::size_t i = 0; i < rows.size(); ++i)
	{
		const double a = 0.5 * static_cast<double>(i);
		const CPose2D truth(a, std::sin(a), 0.2 * a);
		rows[i].truth = truth;
		rows[i].estimate.initialized = true;
		rows[i].estimate.mean = CPose2D() - truth_T_est + truth;
	}
	const auto al = alignPath(rows);
	ASSERT_TRUE(al);
	EXPECT_LT(al->ate_m, 1e-9);
	EXPECT_NEAR(al->truth_T_estimate.x(), truth_T_est.x(), 1e-9);
	EXPECT_NEAR(al->truth_T_estimate.y(), truth_T_est.y(), 1e-9);
	EXPECT_NEAR(al->truth_T_estimate.phi(), truth_T_est.phi(), 1e-9);
	// A position error that no rigid motion explains stays.
	rows[3].estimate.mean = rows[3].estimate.mean + CPose2D(0.3, 0, 0);
	EXPECT_GT(alignPath(rows)->ate_m, 0.05);
	// Rows without truth or uninitialised do not count.
	std::vector<PathRow> few(rows.begin(), rows.begin() + 3);
	few[1].truth.reset();
	few[2].estimate.initialized = false;
	EXPECT_FALSE(alignPath(few));
}

// RPE: invariant to a rigid transform of the whole path; a path that moves
// 10% too far reads 10% of the motion over the interval.
TEST(Metrics, RelativePoseErrorOfKnownPaths)
{
	const CPose2D offset(3, -1, 0.7);
	std::vector<PathRow> rows(40);
	for (std::size_t i = 0; i < rows.size(); ++i)
	{
		const double k = static_cast<double>(i);
		rows[i].timestamp = 0.1 * k;
		rows[i].truth = CPose2D(0.1 * k, 0, 0);
		rows[i].estimate.initialized = true;
		rows[i].estimate.mean = offset + *rows[i].truth;
	}
	const auto rigid = relativePoseError(rows, 1.0);
	ASSERT_TRUE(rigid);
	EXPECT_GE(rigid->pairs, 29);  // j - i is 10 or 11 (0.1 s steps in floating point)
	EXPECT_LE(rigid->pairs, 30);
	EXPECT_LT(rigid->trans_rmse_m, 1e-9);
	EXPECT_LT(rigid->yaw_rmse_deg, 1e-7);
	for (auto& r : rows) r.estimate.mean = CPose2D(1.1 * r.truth->x(), 0, 0);
	const auto scaled = relativePoseError(rows, 1.0);
	ASSERT_TRUE(scaled);
	EXPECT_GE(scaled->trans_rmse_m, 0.1 - 1e-9);
	EXPECT_LE(scaled->trans_rmse_m, 0.11 + 1e-9);
	EXPECT_FALSE(relativePoseError(rows, 10.0));
}
