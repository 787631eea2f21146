// filters_sim: the filters on simulated datasets with images (room loop,
// 5 Hz images, 3% odometry scale error, several seeds and image-noise
// levels): ATE, yaw RMSE, mean NEES, time to a first fix from an unknown
// start, time per step; and the EKF's time per step against the number of
// landmarks in view. Prints Markdown (docs/benchmarks/filters.md, written by
// scripts/bench-filters.sh). Images are detected once per dataset and every
// filter runs on the same steps.
#include <codemark/filters/ekf.h>
#include <codemark/eval/ground_truth.h>
#include <codemark/filters/mrpt_landmarks.h>
#include <codemark/eval/localization.h>
#include <codemark/filters/stepper.h>
#include <codemark/pose/closed_form.h>
#include <codemark/sim/dataset.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/slam/CRangeBearingKFSLAM2D.h>
#include <tclap/CmdLine.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <random>

namespace fs = std::filesystem;
using namespace codemark;
using namespace codemark::filters;
using namespace codemark::eval;
using Clock = std::chrono::steady_clock;

namespace
{
struct Result
{
	int runs = 0, failed = 0;
	double ate = 0, yaw = 0, nees = 0, first_fix_s = 0, ms = 0, max_err = 0;
	long used = 0, rejected = 0;
	int nees_in_band = 0;
};

struct Noise
{
	std::string name;
	double noise_sigma, blur_sigma_px;
	std::string preset;	 // a camera preset in place of the noise and blur ("" = none)
	std::string dataset_dir;  // an existing dataset (codemark-simul's output) in place of one
};

/** The map and ground truth of a dataset folder written by codemark-simul
 * (map.txt, gt_path.txt: `timestamp x y yaw` per image). */
sim::DatasetSummary loadDataset(const fs::path& dir)
{
	sim::DatasetSummary ds;
	ds.map = LandmarkMap::load((dir / "map.txt").string());
	const std::string gt_path = (dir / "gt_path.txt").string();
	const auto gt = eval::GroundTruth::load(gt_path);
	if (gt.form() != eval::GroundTruth::Form::Timestamped)
		throw std::runtime_error(gt_path + ": expected 'timestamp x y yaw' rows");
	for (size_t i = 0; i < gt.size(); ++i)
		ds.ground_truth.push_back({gt.times()[i], gt.poses()[i]});
	ds.frames = static_cast<int>(ds.ground_truth.size());
	return ds;
}

std::vector<RawlogStep> readSteps(
	const std::string& rawlog, const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
	const std::string& calibration)
{
	StepperOptions so;
	so.loadFromConfigFile(cfg, "stepper");
	pipeline::PipelineOptions po;
	po.detector.loadFromConfigFile(cfg, "detector");
	po.pose = pipeline::calibratedPoseOptions(calibration);
	po.pose.loadFromConfigFile(cfg, "pose");
	po.map = map;
	RawlogStepper st(rawlog, so, po);
	std::vector<RawlogStep> steps;
	RawlogStep s;
	while (st.next(s)) steps.push_back(s);
	return steps;
}

LocalizeSummary runSteps(
	const std::vector<RawlogStep>& steps, const std::string& method,
	const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map, const sim::DatasetSummary& ds,
	bool align_se2 = false)
{
	LocalizeSummary s;
	s.method = method;
	auto f = makeLocalizer(method, cfg, map);
	double secs = 0;
	for (const auto& st : steps)
	{
		const auto t0 = Clock::now();
		const auto stats = f->step(st.odometry.get(), st.observations);
		secs += std::chrono::duration<double>(Clock::now() - t0).count();
		PathRow r;
		r.step = st.index;
		r.timestamp = st.timestamp;
		r.estimate = f->estimate();
		r.stats = stats;
		r.truth = ds.ground_truth.at(st.index).pose;
		if (r.estimate.initialized && s.first_fix_step < 0)
		{
			s.first_fix_step = st.index;
			s.first_fix_time_s = st.timestamp - steps.front().timestamp;
		}
		s.sightings_used += stats.used;
		s.sightings_rejected += stats.rejected;
		s.rows.push_back(r);
		++s.steps;
	}
	s.time_per_step_ms = 1000 * secs / std::max<long>(1, s.steps);
	s.slam_map = f->landmarks();
	s.metrics = computeMetrics(s.rows, align_se2);
	if (s.metrics && !s.slam_map.empty()) addLandmarkErrors(*s.metrics, s.slam_map, ds.map);
	return s;
}

// The steps with each coded observation replaced by its
// CObservationBearingRange twin (label CAM_BR): range and bearing of each
// landmark centre with their covariance block, no phi2. What stock kf-slam
// reads from an annotated rawlog.
std::vector<RawlogStep> bearingRangeTwin(std::vector<RawlogStep> steps)
{
	for (auto& st : steps)
	{
		mrpt::obs::CSensoryFrame sf;
		for (const auto& o : st.observations)
			if (const auto c = std::dynamic_pointer_cast<CObservationCodedLandmarks>(o))
				sf.insert(c->toBearingRange());
		st.observations = sf;
	}
	return steps;
}

// MRPT's CRangeBearingKFSLAM2D, the filter stock kf-slam runs, with \a cfg
// (share/codemark/kf-slam-codemark.ini) on \a twin; errors after the same
// SE(2) alignment as codemark's SLAM.
LocalizeSummary runKfSlam(
	const std::vector<RawlogStep>& twin, const mrpt::config::CConfigFileBase& cfg,
	const sim::DatasetSummary& ds)
{
	mrpt::slam::CRangeBearingKFSLAM2D kf;
	kf.loadOptions(cfg);
	// The ini turns kf-slam's profiler on (its time per step); here it would
	// print its report on stdout, into the Markdown.
	kf.KF_options.enable_profiler = false;
	kf.setVerbosityLevel(mrpt::system::LVL_ERROR);
	LocalizeSummary s;
	s.method = "kf-slam";
	double secs = 0;
	for (const auto& st : twin)
	{
		auto acts = mrpt::obs::CActionCollection::Create();
		if (st.odometry) acts->insert(*st.odometry);
		auto sf = mrpt::obs::CSensoryFrame::Create(st.observations);
		const auto t0 = Clock::now();
		kf.processActionObservation(acts, sf);
		secs += std::chrono::duration<double>(Clock::now() - t0).count();
		mrpt::poses::CPosePDFGaussian p;
		kf.getCurrentRobotPose(p);
		PathRow r;
		r.step = st.index;
		r.timestamp = st.timestamp;
		r.estimate.initialized = true;
		r.estimate.mean = p.mean;
		r.estimate.cov = p.cov.asEigen();
		r.truth = ds.ground_truth.at(st.index).pose;
		s.rows.push_back(r);
		++s.steps;
	}
	s.time_per_step_ms = 1000 * secs / std::max<long>(1, s.steps);
	for (const auto& [id, xy] : rangeBearingSlamLandmarks(kf))
	{
		MappedLandmark l;
		l.landmark.id = id;
		l.landmark.x_m = xy.x();
		l.landmark.y_m = xy.y();
		s.slam_map.push_back(l);
	}
	s.metrics = computeMetrics(s.rows, true);
	if (s.metrics) addLandmarkErrors(*s.metrics, s.slam_map, ds.map);
	return s;
}

// SLAM from scratch (no prior map) on the same steps, with and without the
// orientation measurement: codemark's EKF-SLAM on the coded sightings
// (landmark poses x, y, yaw), the same filter on the BearingRange twin
// (point landmarks), and MRPT's kf-slam filter on that twin.
struct SlamRow
{
	int runs = 0;
	double ate = 0, ate_anchored = 0, yaw = 0, lm = 0, lm_yaw = 0, nees = 0;
	bool has_yaw = false;
	void add(const LocalizeSummary& s, bool landmark_yaw)
	{
		if (!s.metrics) return;
		++runs;
		ate += s.metrics->ate_rmse_m;
		ate_anchored += s.metrics->ate_rmse_anchored_m;
		yaw += s.metrics->yaw_rmse_deg;
		lm += s.metrics->landmark_rmse_m;
		lm_yaw += s.metrics->landmark_yaw_rmse_deg;
		nees += s.metrics->nees_mean;
		has_yaw = landmark_yaw;
	}
};

// EKF cost against the number of landmarks in view: synthetic sightings of
// n landmarks on a circle around the robot, perfect odometry.
void costTable(const std::string& share)
{
	std::printf("\n### EKF time per step against the landmarks in view\n\n");
	std::printf(
		"Synthetic frames (no images): n landmarks on a 3 m circle around the robot, "
		"2000 steps each, one Kalman iteration per landmark (FEAT = 0).\n\n");
	std::printf("| landmarks in view | ekf [us/step] | ekf-pose [us/step] |\n|---:|---:|---:|\n");
	for (int n : {1, 2, 4, 8, 16, 32})
	{
		LandmarkMap map;
		for (int i = 0; i < n; ++i)
		{
			MapLandmark l;
			l.id = i;
			const double a = 2 * M_PI * i / n;
			l.x_m = 3 * std::cos(a), l.y_m = 3 * std::sin(a), l.z_m = 0.6, l.yaw_rad = a + M_PI;
			map.landmarks.push_back(l);
		}
		std::printf("| %d", n);
		for (auto kind : {EkfMeasurement::Landmark, EkfMeasurement::PoseFix})
		{
			PoseEstimate init;
			init.initialized = true;
			init.cov = Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal();
			auto f = makeEkfLocalizer(kind, EkfOptions(), map, init);
			const auto cam = mrpt::poses::CPose3D(0, 0, 0.6, 0, 0, 0) +
							 mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
			auto obs = CObservationCodedLandmarks::Create();
			obs->cameraPose = cam;
			for (const auto& l : map.landmarks)
			{
				CObservationCodedLandmarks::TSighting s;
				s.id = l.id;
				s.L = predictLandmarkMeasurement(
					Eigen::Vector3d::Zero(), pose::cameraPlanarPose(cam),
					pose::landmarkPlanarPose(l.world_T_landmark()));
				s.C_L = Eigen::Vector3d(1e-4, 1e-6, 1e-4).asDiagonal();
				Eigen::Matrix3d J;
				s.pose_in_landmark = pose::poseFromLandmark(s.L, &J);
				s.C_R = J * s.C_L * J.transpose();
				obs->sightings.push_back(s);
			}
			mrpt::obs::CSensoryFrame sf;
			sf.insert(obs);
			mrpt::obs::CActionRobotMovement2D odo;
			mrpt::poses::CPosePDFGaussian g;
			g.cov.setIdentity();
			g.cov *= 1e-6;
			odo.poseChange = mrpt::poses::CPosePDFGaussian::Create(g);
			const int N = 2000;
			const auto t0 = Clock::now();
			for (int k = 0; k < N; ++k) f->step(&odo, sf);
			std::printf(
				" | %.1f", 1e6 * std::chrono::duration<double>(Clock::now() - t0).count() / N);
		}
		std::printf(" |\n");
	}
	(void)share;
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd(
			"Benchmarks codemark's filters on simulated datasets (Markdown on stdout).", ' ',
			"0.1");
		TCLAP::ValueArg<std::string> work(
			"w", "work", "folder for the datasets", false, "/tmp/codemark_bench_filters", "DIR",
			cmd);
		TCLAP::ValueArg<std::string> share(
			"s", "share", "share/codemark folder", false, CODEMARK_SOURCE_SHARE_DIR, "DIR", cmd);
		TCLAP::ValueArg<int> seeds("n", "seeds", "number of seeds", false, 3, "N", cmd);
		TCLAP::ValueArg<int> frames(
			"f", "max-frames", "frames per dataset (0: the whole loop)", false, 0, "N", cmd);
		TCLAP::ValueArg<std::string> methods(
			"m", "methods", "comma-separated methods", false, "ekf,ekf-pose,ekf-slam,pf", "LIST",
			cmd);
		TCLAP::ValueArg<std::string> presets(
			"", "preset",
			"comma-separated camera presets (docs/camera-pipeline.md): one row of images per "
			"preset in place of the two noise levels",
			false, "", "LIST", cmd);
		TCLAP::MultiArg<std::string> datasets(
			"", "dataset",
			"NAME=DIR: also run every method on an existing dataset of codemark-simul (e.g. the "
			"POV-Ray room loop of scripts/povray-sets.sh), one row named NAME; repeatable",
			false, "NAME=DIR", cmd);
		TCLAP::ValueArg<std::string> calibration(
			"", "calibration",
			"C_P's calibration for the images detected on the fly: a file (docs/calibration.md) "
			"or a shipped calibration's name. Default realistic, the one fitted on "
			"codemark-simul's "
			"linear-light renders; --preset rows call for family (the tools' default).",
			false, "realistic", "FILE|NAME", cmd);
		TCLAP::SwitchArg no_phi2(
			"", "no-phi2-table",
			"skip the SLAM comparison with the BearingRange twin (codemark ekf-slam and MRPT's "
			"kf-slam filter without the orientation phi2)",
			cmd);
		cmd.parse(argc, argv);
		const bool phi2_table = !no_phi2.getValue();

		std::vector<std::string> ms;
		{
			std::stringstream ss(methods.getValue());
			for (std::string m; std::getline(ss, m, ',');) ms.push_back(m);
		}
		std::vector<Noise> noises = {
			{"noise 2, blur 0.8 px", 2.0, 0.8, "", ""}, {"noise 6, blur 1.2 px", 6.0, 1.2, "", ""}};
		if (presets.isSet())
		{
			noises.clear();
			std::stringstream ss(presets.getValue());
			for (std::string p; std::getline(ss, p, ',');)
			{
				(void)sim::RenderOptions::presetKeys(p);  // an unknown name throws
				noises.push_back({"preset " + p, 0, 0, p, ""});
			}
		}
		for (const auto& d : datasets.getValue())
		{
			const auto eq = d.find('=');
			if (eq == std::string::npos || eq == 0 || eq + 1 == d.size())
				throw std::invalid_argument("--dataset: expected NAME=DIR, got '" + d + "'");
			noises.push_back({d.substr(0, eq), 0, 0, "", d.substr(eq + 1)});
		}
		std::map<std::pair<std::string, std::string>, Result> results;
		std::map<std::string, std::string> skipped;
		std::map<std::pair<std::string, std::string>, SlamRow> slam_rows;
		for (const auto& nz : noises)
			for (int seed = 1; seed <= seeds.getValue(); ++seed)
			{
				if (!nz.dataset_dir.empty() && seed > 1) continue;	// one recorded run
				sim::DatasetOptions o;
				o.odometry_scale_error = 0.03;
				o.seed = seed;
				o.render.noise_sigma = nz.noise_sigma;
				o.render.blur_sigma_px = nz.blur_sigma_px;
				if (!nz.preset.empty()) o.render.applyPreset(nz.preset);
				const auto dir =
					!nz.dataset_dir.empty()
						? fs::path(nz.dataset_dir)
						: fs::path(work.getValue()) /
							  ("seed" + std::to_string(seed) +
							   (nz.preset.empty() ? "_noise" + std::to_string(int(nz.noise_sigma))
												  : "_" + nz.preset));
				std::fprintf(stderr, "filters_sim: dataset %s\n", dir.c_str());
				sim::DatasetSummary ds;
				if (nz.dataset_dir.empty())
				{
					fs::create_directories(dir);
					ds = sim::writeDataset(o, dir.string(), false, {}, frames.getValue());
				}
				else
					ds = loadDataset(dir);
				std::vector<RawlogStep> steps;
				for (const auto& m : ms)
				{
					const std::string ini = share.getValue() + "/config/" + m + ".ini";
					if (!fs::exists(ini))
					{
						skipped[m] = ini + " missing";
						continue;
					}
					mrpt::config::CConfigFile cfg(ini);
					if (steps.empty())
						steps = readSteps(
							(dir / "dataset.rawlog").string(), cfg, ds.map, calibration.getValue());
					auto& r = results[{nz.name, m}];
					try
					{
						const auto s = runSteps(steps, m, cfg, ds.map, ds);
						++r.runs;
						if (!s.metrics)
						{
							++r.failed;
							continue;
						}
						r.ate += s.metrics->ate_rmse_m;
						r.max_err = std::max(r.max_err, s.metrics->max_error_m);
						r.yaw += s.metrics->yaw_rmse_deg;
						r.nees += s.metrics->nees_mean;
						r.nees_in_band += s.metrics->nees_mean >= s.metrics->nees_band_low &&
										  s.metrics->nees_mean <= s.metrics->nees_band_high;
						r.first_fix_s += s.first_fix_time_s;
						r.ms += s.time_per_step_ms;
						r.used += s.sightings_used;
						r.rejected += s.sightings_rejected;
					}
					catch (const std::exception& e)
					{
						skipped[m] = e.what();
						results.erase({nz.name, m});
					}
				}
				const std::string slam_ini = share.getValue() + "/config/ekf-slam.ini";
				const std::string kf_ini = share.getValue() + "/kf-slam-codemark.ini";
				if (!phi2_table || !fs::exists(slam_ini) || !fs::exists(kf_ini)) continue;
				mrpt::config::CConfigFile slam_cfg(slam_ini), kf_cfg(kf_ini);
				if (steps.empty())
					steps = readSteps(
						(dir / "dataset.rawlog").string(), slam_cfg, ds.map,
						calibration.getValue());
				const auto twin = bearingRangeTwin(steps);
				slam_rows[{nz.name, "codemark ekf-slam, coded sightings (L with phi2)"}].add(
					runSteps(steps, "ekf-slam", slam_cfg, LandmarkMap(), ds, true), true);
				slam_rows[{nz.name, "codemark ekf-slam, BearingRange twin (no phi2)"}].add(
					runSteps(twin, "ekf-slam", slam_cfg, LandmarkMap(), ds, true), false);
				slam_rows[{nz.name, "MRPT kf-slam filter, BearingRange twin"}].add(
					runKfSlam(twin, kf_cfg, ds), false);
			}
		std::printf("### Simulated room loops with images\n\n");
		std::printf(
			"codemark-simul's default room (6 x 4 m, 12 landmarks), one loop, 5 Hz images detected "
			"on the fly, odometry with MRPT's Gaussian model and a 3%% scale error, "
			"actions-observations format; %d seeds per image-noise level; every filter starts with "
			"no initial pose (global initialisation) and reads its shipped ini "
			"(share/codemark/config/<method>.ini). Means over the seeds; max error is the largest "
			"over the seeds. NEES in band: runs whose mean NEES lies in the two-sided 95%% "
			"chi-square band (3 DoF).\n\n",
			seeds.getValue());
		std::printf(
			"| images | method | ATE [m] | max error [m] | yaw RMSE [deg] | mean NEES | NEES in "
			"band | "
			"first fix [s] | used / rejected sightings | time per step [ms] |\n");
		std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
		for (const auto& [key, r] : results)
		{
			const int ok = r.runs - r.failed;
			if (ok <= 0) continue;
			std::printf(
				"| %s | %s | %.4f | %.4f | %.3f | %.2f | %d/%d | %.2f | %ld / %ld | %.3f |\n",
				key.first.c_str(), key.second.c_str(), r.ate / ok, r.max_err, r.yaw / ok,
				r.nees / ok, r.nees_in_band, r.runs, r.first_fix_s / ok, r.used, r.rejected,
				r.ms / ok);
		}
		for (const auto& [m, why] : skipped)
			std::printf("\n%s not run: %s\n", m.c_str(), why.c_str());
		if (!slam_rows.empty())
		{
			std::printf("\n### What phi2 adds: SLAM from scratch with and without it\n\n");
			std::printf(
				"The same datasets and detections, no prior map, each sighting either as our "
				"coded observation (L = [l2 phi1 phi2] with C_L; landmarks estimated as x, y, yaw) "
				"or as its CObservationBearingRange twin (range and bearing only; point "
				"landmarks): codemark's EKF-SLAM (share/codemark/config/ekf-slam.ini) on both, and "
				"MRPT's CRangeBearingKFSLAM2D, the filter stock kf-slam runs, with "
				"share/codemark/kf-slam-codemark.ini on the twin. The maps are in the frame of the "
				"robot's start: errors after the SE(2) least-squares alignment of the path (ATE "
				"anchored: the estimate's frame put at the true first pose, no fit; NEES taken "
				"there). Means over the seeds.\n\n");
			std::printf(
				"| images | filter | ATE aligned [m] | ATE anchored [m] | yaw RMSE [deg] | "
				"landmark RMSE [m] | landmark yaw RMSE [deg] | mean NEES |\n");
			std::printf("|---|---|---:|---:|---:|---:|---:|---:|\n");
			for (const auto& [key, r] : slam_rows)
			{
				if (r.runs == 0) continue;
				const double n = r.runs;
				char yaw[32] = "-";
				if (r.has_yaw) std::snprintf(yaw, sizeof yaw, "%.2f", r.lm_yaw / n);
				std::printf(
					"| %s | %s | %.4f | %.4f | %.3f | %.4f | %s | %.2f |\n", key.first.c_str(),
					key.second.c_str(), r.ate / n, r.ate_anchored / n, r.yaw / n, r.lm / n, yaw,
					r.nees / n);
			}
		}
		costTable(share.getValue());
		return 0;
	}
	catch (const std::exception& e)
	{
		std::cerr << "filters_sim: " << e.what() << "\n";
		return 1;
	}
}
