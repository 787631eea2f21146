#include <codemark/landmark/random.h>
#include <codemark/landmark/text.h>
#include <codemark/sim/dataset.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/random/RandomGenerators.h>
#include <mrpt/serialization/CArchive.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace codemark::sim
{
using mrpt::poses::CPose2D;
using mrpt::poses::CPose3D;

mrpt::poses::CPose3D DatasetOptions::cameraPoseOnRobot() const
{
	return CPose3D(camera_x_m, camera_y_m, camera_z_m, camera_yaw_deg * M_PI / 180.0, 0, 0) +
		   CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
}

RenderOptions DatasetOptions::realisticRender()
{
	RenderOptions r;
	r.background = Background::Textured;
	r.distractors = 6;
	r.gradient = 0.3;
	r.noise_sigma = 2.0;
	r.blur_sigma_px = 0.8;
	return r;
}

namespace
{
void require(bool ok, const std::string& what)
{
	if (!ok) throw std::invalid_argument("dataset options: " + what);
}
}  // namespace

void DatasetOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string&)
{
	// MRPT's readers take "six" as 0 and "0.5m" as 0.5: check the numbers first.
	requireIniNumbers(c, "map", {"room_width_m", "room_depth_m", "landmark_height_m"});
	requireIniNumbers(c, "map", {"room_landmarks", "first_id"}, true);
	requireIniNumbers(c, "trajectory", {"loop_margin_m", "corner_radius_m", "speed_mps"});
	requireIniNumbers(c, "trajectory", {"loops"}, true);
	requireIniNumbers(c, "dataset", {"frame_rate_hz", "odometry_rate_hz", "start_time"});
	requireIniNumbers(c, "dataset", {"seed"}, true);
	requireIniNumbers(
		c, "odometry",
		{"gaussian_alpha_1", "gaussian_alpha_2", "gaussian_alpha_3", "gaussian_alpha_4",
		 "gaussian_min_std_xy", "gaussian_min_std_phi_deg", "thrun_alfa1_rot_rot",
		 "thrun_alfa2_rot_trans", "thrun_alfa3_trans_trans", "thrun_alfa4_trans_rot",
		 "thrun_additional_std_xy", "thrun_additional_std_phi", "odometry_scale_error"});
	requireIniNumbers(c, "camera", {"camera_x_m", "camera_y_m", "camera_z_m", "camera_yaw_deg"});
	map_file = c.read_string("map", "map_file", map_file);
	MRPT_LOAD_CONFIG_VAR(room_width_m, double, c, "map");
	MRPT_LOAD_CONFIG_VAR(room_depth_m, double, c, "map");
	MRPT_LOAD_CONFIG_VAR(room_landmarks, int, c, "map");
	MRPT_LOAD_CONFIG_VAR(landmark_height_m, double, c, "map");
	MRPT_LOAD_CONFIG_VAR(first_id, int, c, "map");

	trajectory_file = c.read_string("trajectory", "trajectory_file", trajectory_file);
	MRPT_LOAD_CONFIG_VAR(loop_margin_m, double, c, "trajectory");
	MRPT_LOAD_CONFIG_VAR(corner_radius_m, double, c, "trajectory");
	MRPT_LOAD_CONFIG_VAR(speed_mps, double, c, "trajectory");
	MRPT_LOAD_CONFIG_VAR(loops, int, c, "trajectory");

	MRPT_LOAD_CONFIG_VAR(frame_rate_hz, double, c, "dataset");
	MRPT_LOAD_CONFIG_VAR(odometry_rate_hz, double, c, "dataset");
	MRPT_LOAD_CONFIG_VAR(start_time, double, c, "dataset");
	seed = static_cast<unsigned int>(c.read_uint64_t("dataset", "seed", seed));

	const std::string model = c.read_string("odometry", "motion_model", "gaussian");
	if (model == "gaussian")
		motion.modelSelection = mrpt::obs::CActionRobotMovement2D::mmGaussian;
	else if (model == "thrun")
		motion.modelSelection = mrpt::obs::CActionRobotMovement2D::mmThrun;
	else
		throw std::invalid_argument(
			"[odometry] motion_model must be 'gaussian' or 'thrun', got '" + model + "'");
	auto& g = motion.gaussianModel;
	g.a1 = c.read_double("odometry", "gaussian_alpha_1", g.a1);
	g.a2 = c.read_double("odometry", "gaussian_alpha_2", g.a2);
	g.a3 = c.read_double("odometry", "gaussian_alpha_3", g.a3);
	g.a4 = c.read_double("odometry", "gaussian_alpha_4", g.a4);
	g.minStdXY = c.read_double("odometry", "gaussian_min_std_xy", g.minStdXY);
	g.minStdPHI = c.read_double("odometry", "gaussian_min_std_phi_deg", g.minStdPHI * 180 / M_PI) *
				  M_PI / 180;
	auto& t = motion.thrunModel;
	t.alfa1_rot_rot = c.read_float("odometry", "thrun_alfa1_rot_rot", t.alfa1_rot_rot);
	t.alfa2_rot_trans = c.read_float("odometry", "thrun_alfa2_rot_trans", t.alfa2_rot_trans);
	t.alfa3_trans_trans = c.read_float("odometry", "thrun_alfa3_trans_trans", t.alfa3_trans_trans);
	t.alfa4_trans_rot = c.read_float("odometry", "thrun_alfa4_trans_rot", t.alfa4_trans_rot);
	t.additional_std_XY = c.read_float("odometry", "thrun_additional_std_xy", t.additional_std_XY);
	t.additional_std_phi =
		c.read_float("odometry", "thrun_additional_std_phi", t.additional_std_phi);
	MRPT_LOAD_CONFIG_VAR(odometry_scale_error, double, c, "odometry");

	camera_file = c.read_string("camera", "camera_file", camera_file);
	sensor_label = c.read_string("camera", "sensor_label", sensor_label);
	MRPT_LOAD_CONFIG_VAR(camera_x_m, double, c, "camera");
	MRPT_LOAD_CONFIG_VAR(camera_y_m, double, c, "camera");
	MRPT_LOAD_CONFIG_VAR(camera_z_m, double, c, "camera");
	MRPT_LOAD_CONFIG_VAR(camera_yaw_deg, double, c, "camera");

	if (c.sectionExists("render")) render.loadFromConfigFile(c, "render");

	require(
		room_width_m > 0 && room_depth_m > 0, "[map] room_width_m and room_depth_m must be > 0");
	require(
		room_landmarks >= 0 && first_id >= 0 && first_id + room_landmarks <= 256,
		"[map] first_id + room_landmarks must stay within the 256 IDs");
	require(speed_mps > 0, "[trajectory] speed_mps must be > 0");
	require(loops >= 1, "[trajectory] loops must be >= 1");
	require(
		loop_margin_m > 0 && corner_radius_m > 0,
		"[trajectory] loop_margin_m and corner_radius_m must be > 0");
	require(frame_rate_hz > 0 && odometry_rate_hz > 0, "[dataset] rates must be > 0");
	require(
		std::isfinite(start_time) && start_time >= 0,
		"[dataset] start_time must be a UNIX time >= 0");
	require(
		std::abs(odometry_scale_error) < 0.5,
		"[odometry] odometry_scale_error must be within +-0.5");
	require(!sensor_label.empty(), "[camera] sensor_label must not be empty");
}

void DatasetOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string&) const
{
	c.write("map", "map_file", map_file);
	c.write("map", "room_width_m", room_width_m);
	c.write("map", "room_depth_m", room_depth_m);
	c.write("map", "room_landmarks", room_landmarks);
	c.write("map", "landmark_height_m", landmark_height_m);
	c.write("map", "first_id", first_id);
	c.write("trajectory", "trajectory_file", trajectory_file);
	c.write("trajectory", "loop_margin_m", loop_margin_m);
	c.write("trajectory", "corner_radius_m", corner_radius_m);
	c.write("trajectory", "speed_mps", speed_mps);
	c.write("trajectory", "loops", loops);
	c.write("dataset", "frame_rate_hz", frame_rate_hz);
	c.write("dataset", "odometry_rate_hz", odometry_rate_hz);
	c.write("dataset", "start_time", start_time);
	c.write("dataset", "seed", static_cast<uint64_t>(seed));
	c.write(
		"odometry", "motion_model",
		motion.modelSelection == mrpt::obs::CActionRobotMovement2D::mmGaussian ? "gaussian"
																			   : "thrun");
	c.write("odometry", "gaussian_alpha_1", motion.gaussianModel.a1);
	c.write("odometry", "gaussian_alpha_2", motion.gaussianModel.a2);
	c.write("odometry", "gaussian_alpha_3", motion.gaussianModel.a3);
	c.write("odometry", "gaussian_alpha_4", motion.gaussianModel.a4);
	c.write("odometry", "gaussian_min_std_xy", motion.gaussianModel.minStdXY);
	c.write("odometry", "gaussian_min_std_phi_deg", motion.gaussianModel.minStdPHI * 180 / M_PI);
	c.write("odometry", "odometry_scale_error", odometry_scale_error);
	c.write("camera", "camera_file", camera_file);
	c.write("camera", "sensor_label", sensor_label);
	c.write("camera", "camera_x_m", camera_x_m);
	c.write("camera", "camera_y_m", camera_y_m);
	c.write("camera", "camera_z_m", camera_z_m);
	c.write("camera", "camera_yaw_deg", camera_yaw_deg);
	render.saveToConfigFile(c, "render");
}

LandmarkMap generateRoomMap(const DatasetOptions& o)
{
	const double W = o.room_width_m, D = o.room_depth_m, per = 2 * (W + D);
	LandmarkMap map;
	for (int i = 0; i < o.room_landmarks; ++i)
	{
		// Arc length along the walls, counter-clockwise from the origin corner.
		double s = (i + 0.5) * per / o.room_landmarks;
		MapLandmark l;
		l.id = o.first_id + i;
		l.z_m = o.landmark_height_m;
		if (s < W)
		{
			l.x_m = s, l.y_m = 0, l.yaw_rad = M_PI / 2;	 // wall y = 0 faces +y
		}
		else if ((s -= W) < D)
		{
			l.x_m = W, l.y_m = s, l.yaw_rad = M_PI;	 // wall x = W faces -x
		}
		else if ((s -= D) < W)
		{
			l.x_m = W - s, l.y_m = D, l.yaw_rad = -M_PI / 2;
		}
		else
		{
			s -= W;
			l.x_m = 0, l.y_m = D - s, l.yaw_rad = 0;
		}
		map.landmarks.push_back(l);
	}
	return map;
}

namespace
{
// A piece of a planar path: a straight line (curvature 0) or a left arc.
struct Piece
{
	double x0, y0, h0, length, curvature;
};

std::vector<Piece> loopPieces(const DatasetOptions& o)
{
	const double x0 = o.loop_margin_m, x1 = o.room_width_m - o.loop_margin_m;
	const double y0 = o.loop_margin_m, y1 = o.room_depth_m - o.loop_margin_m;
	const double a = x1 - x0, b = y1 - y0, r = o.corner_radius_m;
	if (!(a >= 2 * r && b >= 2 * r))
		throw std::invalid_argument(
			"dataset options: the loop does not fit: the room minus twice loop_margin_m must be at "
			"least twice corner_radius_m in both directions");
	const double q = M_PI / 2 * r;
	return {{x0 + r, y0, 0, a - 2 * r, 0},		   {x1 - r, y0, 0, q, 1 / r},
			{x1, y0 + r, M_PI / 2, b - 2 * r, 0},  {x1, y1 - r, M_PI / 2, q, 1 / r},
			{x1 - r, y1, M_PI, a - 2 * r, 0},	   {x0 + r, y1, M_PI, q, 1 / r},
			{x0, y1 - r, -M_PI / 2, b - 2 * r, 0}, {x0, y0 + r, -M_PI / 2, q, 1 / r}};
}

CPose2D poseOnPiece(const Piece& p, double s)
{
	if (p.curvature == 0)
		return CPose2D(p.x0 + s * std::cos(p.h0), p.y0 + s * std::sin(p.h0), p.h0);
	const double r = 1 / p.curvature;
	const double cx = p.x0 - r * std::sin(p.h0), cy = p.y0 + r * std::cos(p.h0);
	const double h = p.h0 + s / r;
	return CPose2D(cx + r * std::sin(h), cy - r * std::cos(h), h);
}

std::vector<TimedPose2D> readTrajectoryFile(const std::string& path)
{
	std::ifstream f(path);
	if (!f) throw std::runtime_error(path + ": cannot open trajectory file");
	std::vector<TimedPose2D> out;
	std::string line;
	int n = 0;
	while (std::getline(f, line))
	{
		++n;
		const std::vector<double> v = parseNumberRow(line, path, n, "#%");
		if (v.empty()) continue;
		if (v.size() != 4)
			throw std::runtime_error(
				path + ":" + std::to_string(n) + ": expected 't x y yaw_rad', found " +
				std::to_string(v.size()) + " fields");
		if (!out.empty() && !(v[0] > out.back().t))
			throw std::runtime_error(path + ":" + std::to_string(n) + ": times must increase");
		out.push_back({v[0], CPose2D(v[1], v[2], v[3])});
	}
	if (out.size() < 2) throw std::runtime_error(path + ": a trajectory needs at least 2 poses");
	return out;
}
}  // namespace

namespace
{
// The robot's pose as a function of time since the start of the trajectory.
class Trajectory
{
   public:
	explicit Trajectory(const DatasetOptions& o) : o_(o)
	{
		if (o.trajectory_file.empty())
		{
			pieces_ = loopPieces(o);
			for (const auto& p : pieces_) lap_ += p.length;
			duration_ = lap_ * o.loops / o.speed_mps;
		}
		else
		{
			keys_ = readTrajectoryFile(o.trajectory_file);
			duration_ = keys_.back().t - keys_.front().t;
		}
	}
	double duration() const { return duration_; }

	CPose2D poseAt(double t) const
	{
		if (keys_.empty())
		{
			double s = std::fmod(t * o_.speed_mps, lap_);
			std::size_t i = 0;
			while (i + 1 < pieces_.size() && s > pieces_[i].length) s -= pieces_[i++].length;
			return poseOnPiece(pieces_[i], std::min(s, pieces_[i].length));
		}
		const double ta = keys_.front().t + t;
		std::size_t i = 0;
		while (i + 2 < keys_.size() && keys_[i + 1].t < ta) ++i;
		const auto &a = keys_[i], &b = keys_[i + 1];
		const double u = std::clamp((ta - a.t) / (b.t - a.t), 0.0, 1.0);
		const double dyaw = mrpt::math::wrapToPi(b.pose.phi() - a.pose.phi());
		return CPose2D(
			a.pose.x() + u * (b.pose.x() - a.pose.x()), a.pose.y() + u * (b.pose.y() - a.pose.y()),
			mrpt::math::wrapToPi(a.pose.phi() + u * dyaw));
	}

	// Poses at start_time + offset + k / rate_hz within the trajectory.
	std::vector<TimedPose2D> sample(double rate_hz, double offset_s) const
	{
		std::vector<TimedPose2D> out;
		for (int k = 0;; ++k)
		{
			const double t = offset_s + k / rate_hz;
			if (t > duration_ + 1e-9) break;
			out.push_back({o_.start_time + t, poseAt(t)});
		}
		return out;
	}

   private:
	const DatasetOptions& o_;
	std::vector<Piece> pieces_;
	double lap_ = 0;
	std::vector<TimedPose2D> keys_;
	double duration_ = 0;
};
}  // namespace

std::vector<TimedPose2D> generateLoop(const DatasetOptions& o, double rate_hz)
{
	DatasetOptions loop = o;
	loop.trajectory_file.clear();
	return Trajectory(loop).sample(rate_hz, 0.0);
}

std::vector<TimedPose2D> sampleTrajectory(const DatasetOptions& o, double rate_hz)
{
	return Trajectory(o).sample(rate_hz, 0.0);
}

namespace
{
// The odometry reading of a true increment: the systematic scale error, then
// a sample of the motion model's noise.
CPose2D noisyIncrement(const CPose2D& truth, const DatasetOptions& o)
{
	const double s = 1.0 + o.odometry_scale_error;
	const CPose2D scaled(truth.x() * s, truth.y() * s, truth.phi());
	mrpt::obs::CActionRobotMovement2D act;
	act.computeFromOdometry(scaled, o.motion);
	CPose2D sample;
	act.drawSingleSample(sample);
	return sample;
}

mrpt::obs::CActionRobotMovement2D::Ptr odometryAction(
	const CPose2D& reading, const DatasetOptions& o, mrpt::Clock::time_point t)
{
	auto act = mrpt::obs::CActionRobotMovement2D::Create();
	act->computeFromOdometry(reading, o.motion);
	act->timestamp = t;
	return act;
}
}  // namespace

DatasetSummary writeDataset(
	const DatasetOptions& o, const std::string& out_dir, bool obs_only,
	const std::function<void(int, int)>& progress, int max_frames, const Renderer& renderer)
{
	DatasetSummary sum;
	sum.map = o.map_file.empty() ? generateRoomMap(o) : LandmarkMap::load(o.map_file);
	if (sum.map.landmarks.empty())
		throw std::runtime_error(
			(o.map_file.empty() ? std::string("[map] room_landmarks = 0") : o.map_file) +
			": the map has no landmarks");
	const CameraModel camera =
		o.camera_file.empty() ? CameraModel::paperDefault() : CameraModel::load(o.camera_file);
	const CPose3D cam_on_robot = o.cameraPoseOnRobot();

	const std::string img_dir = out_dir + "/dataset_Images";
	createFolder(img_dir, "the output folder");

	reseedMrptRandom(o.seed);
	const Trajectory trajectory(o);
	auto frames = trajectory.sample(o.frame_rate_hz, 0.0);
	if (max_frames > 0 && frames.size() > static_cast<std::size_t>(max_frames))
		frames.resize(max_frames);
	// Observations-only: odometry at its own rate, offset by half a period so
	// that it never coincides with an image: filters must interpolate.
	std::vector<TimedPose2D> odo_truth;
	if (obs_only)
	{
		odo_truth.push_back({o.start_time, trajectory.poseAt(0.0)});
		for (const auto& q : trajectory.sample(o.odometry_rate_hz, 0.5 / o.odometry_rate_hz))
			odo_truth.push_back(q);
	}

	const std::string rawlog_path = out_dir + "/dataset.rawlog";
	mrpt::io::CFileGZOutputStream fout;
	if (!fout.open(rawlog_path)) throw std::runtime_error(rawlog_path + ": cannot write");
	auto ar = mrpt::serialization::archiveFrom(fout);

	std::ofstream gt(out_dir + "/gt_path.txt");
	if (!gt) throw std::runtime_error(out_dir + "/gt_path.txt: cannot write");
	gt << "# timestamp[UNIX s] x[m] y[m] yaw[rad]: the robot's true pose at each image\n";
	gt << std::fixed;

	CPose2D odo_accum(0, 0, 0);	 // the odometry's own integrated pose
	CPose2D prev_truth = frames.front().pose;
	std::size_t next_odo = 0;
	const int total = static_cast<int>(frames.size());
	for (int k = 0; k < total; ++k)
	{
		const auto& f = frames[k];
		const auto stamp = mrpt::Clock::fromDouble(f.t);
		if (obs_only)
		{
			// Every odometry reading up to this image's time.
			while (next_odo < odo_truth.size() && odo_truth[next_odo].t <= f.t)
			{
				const auto& q = odo_truth[next_odo];
				const CPose2D inc = next_odo == 0 ? CPose2D(0, 0, 0) : q.pose - prev_truth;
				if (next_odo > 0) odo_accum = odo_accum + noisyIncrement(inc, o);
				prev_truth = q.pose;
				auto odo = mrpt::obs::CObservationOdometry::Create();
				odo->sensorLabel = "ODOMETRY";
				odo->timestamp = mrpt::Clock::fromDouble(q.t);
				odo->odometry = odo_accum;
				ar << *odo;
				++sum.odometry_readings;
				++next_odo;
			}
		}
		else
		{
			const CPose2D inc = k == 0 ? CPose2D(0, 0, 0) : f.pose - prev_truth;
			const CPose2D reading = k == 0 ? CPose2D(0, 0, 0) : noisyIncrement(inc, o);
			prev_truth = f.pose;
			mrpt::obs::CActionCollection acts;
			acts.insert(*odometryAction(reading, o, stamp));
			ar << acts;
			++sum.odometry_readings;
		}

		Scene scene{sum.map, camera, CPose3D(f.pose) + cam_on_robot};
		const Render r = renderer(scene, o.render, static_cast<uint64_t>(o.seed) * 1000003ULL + k);
		for (const auto& t : r.truth) sum.sightings += t.fully_visible;
		std::ostringstream name;
		name << o.sensor_label << "_" << std::setw(6) << std::setfill('0') << k << ".png";
		if (!cv::imwrite(img_dir + "/" + name.str(), r.image))
			throw std::runtime_error(img_dir + "/" + name.str() + ": cannot write image");

		auto obs = mrpt::obs::CObservationImage::Create();
		obs->sensorLabel = o.sensor_label;
		obs->timestamp = stamp;
		obs->cameraPose = cam_on_robot;
		obs->cameraParams = camera.params();
		obs->image.setExternalStorage(name.str());
		if (obs_only)
			ar << *obs;
		else
		{
			mrpt::obs::CSensoryFrame sf;
			sf.insert(obs);
			ar << sf;
		}
		gt << std::setprecision(6) << f.t << ' ' << std::setprecision(6) << f.pose.x() << ' '
		   << f.pose.y() << ' ' << f.pose.phi() << '\n';
		sum.ground_truth.push_back(f);
		++sum.frames;
		if (progress) progress(k + 1, total);
	}
	sum.map.save(out_dir + "/map.txt");
	return sum;
}

}  // namespace codemark::sim
