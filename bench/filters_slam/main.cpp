// bench_filters_slam: codemark EKF-SLAM on MRPT's kf-slam_demo.rawlog beside
// MRPT's own CRangeBearingKFSLAM2D (the filter stock kf-slam runs, with the
// same ini), and EKF-SLAM's time per step against the map size on
// synthetic data. Prints `key = value` lines for
// scripts/bench-filters-slam.sh.
#include <codemark/filters/ekf_slam.h>
#include <codemark/filters/mrpt_landmarks.h>
#include <codemark/landmark/truth.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/math/CMatrixDynamic.h>
#include <mrpt/math/TPoint2D.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/random/RandomGenerators.h>
#include <mrpt/slam/CRangeBearingKFSLAM2D.h>
#include <tclap/CmdLine.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

using namespace codemark;
using namespace codemark::filters;
using Clock = std::chrono::steady_clock;

namespace
{
struct Result
{
	double path_rmse = 0, lm_rmse = 0, lm_mean = 0, step_ms = 0, kf_ms = 0;
	std::size_t steps = 0, landmarks = 0;
};

// MRPT robot-path file: x y z yaw pitch roll rows, '%' comments.
std::vector<Eigen::Vector2d> loadPath(const std::string& path)
{
	std::ifstream f(path);
	if (!f) throw std::runtime_error("cannot open ground-truth path '" + path + "'");
	std::vector<Eigen::Vector2d> out;
	int line = 0;
	for (std::string s; std::getline(f, s);)
	{
		++line;
		if (auto c = s.find('%'); c != std::string::npos) s.erase(c);
		std::istringstream ss(s);
		double v[6];
		int n = 0;
		while (n < 6 && ss >> v[n]) ++n;
		if (n == 0) continue;
		if (n != 6)
			throw std::runtime_error(path + ":" + std::to_string(line) + ": expected 6 columns");
		out.emplace_back(v[0], v[1]);
	}
	return out;
}

double rmsePath(const std::vector<Eigen::Vector2d>& est, const std::vector<Eigen::Vector2d>& gt)
{
	// Step i against ground-truth row i + 1 (row 0 is the start pose).
	double s = 0;
	std::size_t n = 0;
	for (std::size_t i = 0; i < est.size() && i + 1 < gt.size(); ++i, ++n)
		s += (est[i] - gt[i + 1]).squaredNorm();
	return n ? std::sqrt(s / n) : NAN;
}

void landmarkErrors(const std::map<int, Eigen::Vector2d>& est, const LandmarkMap& gt, Result& r)
{
	double s = 0, m = 0;
	std::size_t n = 0;
	for (const auto& [id, p] : est)
	{
		const MapLandmark* g = gt.find(id);
		if (!g) continue;
		const double e = (p - Eigen::Vector2d(g->x_m, g->y_m)).norm();
		s += e * e;
		m += e;
		++n;
	}
	r.lm_rmse = n ? std::sqrt(s / n) : NAN;
	r.lm_mean = n ? m / n : NAN;
	r.landmarks = n;
}

Result runOurs(
	const mrpt::obs::CRawlog& log, const mrpt::config::CConfigFileBase& cfg,
	const std::vector<Eigen::Vector2d>& gt_path, const LandmarkMap& gt_map)
{
	EkfSlamOptions o;
	o.loadFromConfigFile(cfg, "ekf_slam");
	EkfSlam slam(o, LandmarkMap{}, std::nullopt, &cfg, "ekf_slam_kf");
	std::vector<Eigen::Vector2d> path;
	double total = 0;
	mrpt::obs::CActionCollection::Ptr acts;
	mrpt::obs::CSensoryFrame::Ptr sf;
	for (std::size_t i = 0; i < log.size() && log.getActionObservationPair(acts, sf, i);)
	{
		const auto odo = acts->getBestMovementEstimation();
		const auto t0 = Clock::now();
		slam.step(odo.get(), *sf);
		total += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
		const auto e = slam.estimate();
		path.emplace_back(e.mean.x(), e.mean.y());
	}
	Result r;
	r.steps = path.size();
	r.path_rmse = rmsePath(path, gt_path);
	std::map<int, Eigen::Vector2d> lms;
	for (const auto& m : slam.landmarks())
		lms[m.landmark.id] = Eigen::Vector2d(m.landmark.x_m, m.landmark.y_m);
	landmarkErrors(lms, gt_map, r);
	r.step_ms = total / std::max<std::size_t>(1, r.steps);
	r.kf_ms =
		slam.meanKalmanIterationMs() * slam.kalmanIterations() / std::max<std::size_t>(1, r.steps);
	return r;
}

Result runMrpt(
	const mrpt::obs::CRawlog& log, const mrpt::config::CConfigFileBase& cfg,
	const std::vector<Eigen::Vector2d>& gt_path, const LandmarkMap& gt_map)
{
	mrpt::slam::CRangeBearingKFSLAM2D kf;
	kf.loadOptions(cfg);
	kf.KF_options.enable_profiler = true;
	kf.setVerbosityLevel(mrpt::system::LVL_ERROR);
	std::vector<Eigen::Vector2d> path;
	double total = 0;
	mrpt::obs::CActionCollection::Ptr acts;
	mrpt::obs::CSensoryFrame::Ptr sf;
	for (std::size_t i = 0; i < log.size() && log.getActionObservationPair(acts, sf, i);)
	{
		const auto t0 = Clock::now();
		kf.processActionObservation(acts, sf);
		total += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
		mrpt::poses::CPosePDFGaussian p;
		kf.getCurrentRobotPose(p);
		path.emplace_back(p.mean.x(), p.mean.y());
	}
	Result r;
	r.steps = path.size();
	r.path_rmse = rmsePath(path, gt_path);
	landmarkErrors(rangeBearingSlamLandmarks(kf), gt_map, r);
	r.step_ms = total / std::max<std::size_t>(1, r.steps);
	r.kf_ms = 1e3 * kf.getProfiler().getMeanTime("KF:complete_step");
	return r;
}

void print(const char* who, const Result& r)
{
	std::printf("%s_steps = %zu\n", who, r.steps);
	std::printf("%s_path_rmse_m = %.6f\n", who, r.path_rmse);
	std::printf("%s_landmark_rmse_m = %.6f\n", who, r.lm_rmse);
	std::printf("%s_landmark_mean_m = %.6f\n", who, r.lm_mean);
	std::printf("%s_landmarks = %zu\n", who, r.landmarks);
	std::printf("%s_step_ms = %.4f\n", who, r.step_ms);
	std::printf("%s_kf_ms = %.4f\n", who, r.kf_ms);
}

// Best (smallest) timings of \a reps runs; accuracy from the first.
template <class F>
Result repeat(int reps, F run)
{
	Result best = run();
	for (int k = 1; k < reps; ++k)
	{
		const Result r = run();
		best.step_ms = std::min(best.step_ms, r.step_ms);
		best.kf_ms = std::min(best.kf_ms, r.kf_ms);
	}
	return best;
}

// Synthetic map of \a n coded landmarks on a ring facing its centre; the
// robot drives a circle inside it with a forward camera and sees the
// landmarks within 4 m and +-0.5 rad. One lap maps everything; the second
// lap is timed.
void scaling(int n, unsigned seed, const std::string& method, double& step_ms, double& visible)
{
	auto& rng = mrpt::random::getRandomGenerator();
	rng.randomize(seed);
	const double R_lm = std::max(5.0, n * 0.35 / (2 * M_PI)), R_robot = R_lm - 2.5;
	std::vector<Eigen::Vector3d> lms;
	for (int i = 0; i < n; ++i)
	{
		const double a = 2 * M_PI * i / n;
		lms.emplace_back(R_lm * std::cos(a), R_lm * std::sin(a), wrapToPi(a + M_PI));
	}
	EkfSlamOptions o;
	const Eigen::Vector3d start(R_robot, 0, M_PI / 2);
	PoseEstimate init;
	init.initialized = true;
	init.mean = mrpt::poses::CPose2D(start[0], start[1], start[2]);
	mrpt::config::CConfigFileMemory kf_cfg;
	kf_cfg.write("kf", "method", method);
	EkfSlam slam(o, LandmarkMap{}, init, &kf_cfg, "kf");
	// A level camera 0.2 m ahead of the robot centre looking 1 rad to the
	// right, towards the ring (the robot drives counter-clockwise).
	const mrpt::poses::CPose3D cam_pose = mrpt::poses::CPose3D(0.2, 0, 0.5, -1.0, 0, 0) +
										  mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
	const mrpt::poses::CPose2D cam2d(0.2, 0, -1.0);
	const int per_lap = 400;
	const double dth = 2 * M_PI / per_lap, ds = R_robot * dth;
	Eigen::Vector3d robot = start;
	double total = 0;
	long seen = 0;
	for (int k = 0; k < 2 * per_lap; ++k)
	{
		// Move: an arc of ds with turn dth.
		const mrpt::poses::CPose2D inc(ds, 0, dth);
		const mrpt::poses::CPose2D r2 = mrpt::poses::CPose2D(robot[0], robot[1], robot[2]) + inc;
		robot = Eigen::Vector3d(r2.x(), r2.y(), r2.phi());
		mrpt::obs::CActionRobotMovement2D act;
		mrpt::poses::CPosePDFGaussian g;
		g.mean = mrpt::poses::CPose2D(
			ds + rng.drawGaussian1D(0, 0.002), rng.drawGaussian1D(0, 0.002),
			dth + rng.drawGaussian1D(0, 0.002));
		g.cov.setDiagonal(std::vector<double>{4e-6, 4e-6, 4e-6});
		act.poseChange = mrpt::poses::CPosePDF::Ptr(new mrpt::poses::CPosePDFGaussian(g));
		auto obs = std::make_shared<CObservationCodedLandmarks>();
		obs->cameraPose = cam_pose;
		for (int i = 0; i < n; ++i)
		{
			const Eigen::Vector3d z = slamObservation(robot, cam2d, lms[i]);
			if (z[0] > 4.0 || std::abs(z[1]) > 0.5 || std::abs(z[2]) > 1.0) continue;
			CObservationCodedLandmarks::TSighting s;
			s.id = i;
			s.C_L = Eigen::Vector3d(1e-6 * z[0] * z[0], 1e-6, 1e-4).asDiagonal();
			s.L = z + Eigen::Vector3d(
						  rng.drawGaussian1D(0, 1e-3 * z[0]), rng.drawGaussian1D(0, 1e-3),
						  rng.drawGaussian1D(0, 1e-2));
			obs->sightings.push_back(s);
		}
		mrpt::obs::CSensoryFrame sf;
		const std::size_t m = obs->sightings.size();
		sf.insert(obs);
		const auto t0 = Clock::now();
		slam.step(&act, sf);
		const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
		if (k >= per_lap)
		{
			total += ms;
			seen += static_cast<long>(m);
		}
	}
	step_ms = total / per_lap;
	visible = static_cast<double>(seen) / per_lap;
	if (slam.landmarkCount() != static_cast<std::size_t>(n))
		std::fprintf(stderr, "warning: %zu of %d landmarks mapped\n", slam.landmarkCount(), n);
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd(
			"codemark EKF-SLAM benchmark: MRPT's kf-slam_demo against CRangeBearingKFSLAM2D, "
			"and the time per step against the map size",
			' ', "1.0");
		TCLAP::ValueArg<std::string> rawlog(
			"", "rawlog", "MRPT kf-slam_demo.rawlog", false,
			"/usr/share/mrpt/datasets/kf-slam_demo.rawlog", "FILE", cmd);
		TCLAP::ValueArg<std::string> gt_path(
			"", "gt-path", "ground-truth robot path", false,
			"/usr/share/mrpt/datasets/kf-slam_demo_ground_truth_robot_path.txt", "FILE", cmd);
		TCLAP::ValueArg<std::string> gt_map(
			"", "gt-map", "ground-truth landmarks (x y z type 0 0 id)", false,
			"/usr/share/mrpt/datasets/kf-slam_demo_ground_truth.txt", "FILE", cmd);
		TCLAP::ValueArg<std::string> config(
			"", "config", "codemark ekf-slam.ini", true, "", "FILE", cmd);
		TCLAP::ValueArg<std::string> kfslam(
			"", "kf-slam-ini", "stock kf-slam ini (for CRangeBearingKFSLAM2D)", true, "", "FILE",
			cmd);
		TCLAP::ValueArg<int> reps("", "reps", "timing repetitions (best kept)", false, 5, "N", cmd);
		TCLAP::ValueArg<std::string> sizes(
			"", "sizes", "map sizes for the scaling run, comma separated", false, "10,50,256",
			"LIST", cmd);
		cmd.parse(argc, argv);

		mrpt::obs::CRawlog log;
		if (!log.loadFromRawLogFile(rawlog.getValue()))
			throw std::runtime_error("cannot read rawlog '" + rawlog.getValue() + "'");
		const auto path = loadPath(gt_path.getValue());
		const LandmarkMap map = loadMrptLandmarksFile(gt_map.getValue());
		const mrpt::config::CConfigFile ours_cfg(config.getValue());
		const mrpt::config::CConfigFile mrpt_cfg(kfslam.getValue());

		print("ours", repeat(reps.getValue(), [&] { return runOurs(log, ours_cfg, path, map); }));
		print("mrpt", repeat(reps.getValue(), [&] { return runMrpt(log, mrpt_cfg, path, map); }));

		std::stringstream ss(sizes.getValue());
		for (std::string tok; std::getline(ss, tok, ',');)
		{
			const int n = std::stoi(tok);
			for (const char* method : {"kfEKFAlaDavison", "kfEKFNaive"})
			{
				double best = 1e300, vis = 0;
				for (int k = 0; k < std::max(1, reps.getValue() / 2); ++k)
				{
					double ms = 0;
					scaling(n, 1234, method, ms, vis);
					best = std::min(best, ms);
				}
				std::printf(
					"scaling_%d_%s_step_ms = %.4f\nscaling_%d_visible = %.2f\n", n, method, best, n,
					vis);
			}
		}
		return 0;
	}
	catch (const std::exception& e)
	{
		std::cerr << "bench_filters_slam: " << e.what() << "\n";
		return 1;
	}
}
