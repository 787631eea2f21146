#pragma once
/** \file dataset.h
 * Simulated MRPT datasets: a map (a file, or a generated room with landmarks
 * on its walls), a trajectory (a file, or a generated loop), noisy odometry
 * from MRPT's motion models, and camera images rendered with exact ground
 * truth, written as an MRPT rawlog with external images.
 */
#include <codemark/landmark/camera.h>
#include <codemark/landmark/map.h>
#include <codemark/sim/render.h>
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>

#include <functional>
#include <string>
#include <vector>

namespace codemark::sim
{
/** A robot pose at a time. */
struct TimedPose2D
{
	double t = 0;  //!< UNIX time [s]
	mrpt::poses::CPose2D pose;	//!< world frame: x, y [m], yaw [rad]
};

/** Everything that defines a simulated dataset; loadable from an ini file
 * (sections [map], [trajectory], [odometry], [camera], [render], [dataset];
 * see share/codemark/simul.ini). */
struct DatasetOptions : public mrpt::config::CLoadableOptions
{
	// [map]
	std::string map_file;  //!< landmark map (spec section 3); empty: a generated room
	double room_width_m =
		6.0;  //!< generated room: extent along world x [m], walls at x = 0 and x = width
	double room_depth_m = 4.0;	//!< generated room: extent along world y [m]
	int room_landmarks = 12;  //!< generated room: landmarks spread evenly over the walls
	double landmark_height_m = 0.6;	 //!< generated room: height of the landmark centres [m]
	int first_id = 1;  //!< generated room: IDs first_id, first_id + 1, ...

	// [trajectory]
	std::string
		trajectory_file;  //!< `t x y yaw_rad` per line (t in s from the start); empty: a loop
	double loop_margin_m = 1.2;	 //!< generated loop: distance from the walls [m]
	double corner_radius_m = 0.6;  //!< generated loop: radius of its rounded corners [m]
	double speed_mps = 0.4;	 //!< generated loop: forward speed [m/s]
	int loops = 1;	//!< generated loop: number of laps

	// [dataset]
	double frame_rate_hz = 5.0;	 //!< camera frames per second
	double odometry_rate_hz = 20.0;	 //!< odometry readings per second (observations-only format)
	double start_time = 1700000000.0;  //!< UNIX time of the first frame [s]
	unsigned int seed = 1;	//!< seeds odometry noise and rendering: the dataset is a function of it

	// [odometry]
	/** MRPT's motion model (Gaussian or Thrun) used both to draw the odometry
	 * noise and to describe it in each CActionRobotMovement2D. */
	mrpt::obs::CActionRobotMovement2D::TMotionModelOptions motion;
	/** Systematic relative error of the odometry's translation (0.03: the
	 * odometry reports 3% more distance than travelled). */
	double odometry_scale_error = 0.0;

	// [camera]
	std::string camera_file;  //!< camera intrinsics (MRPT ini or YAML); empty: the paper's camera
	std::string sensor_label = "CAM";  //!< label of the image observations
	double camera_x_m = 0.1, camera_y_m = 0.0,
		   camera_z_m = 0.6;  //!< camera centre on the robot [m]
	double camera_yaw_deg = 0.0;  //!< heading of the optical axis on the robot (level camera) [deg]

	// [render]
	/** Defaults differ from RenderOptions' (all effects off): a textured
	 * wall, a light gradient, noise sigma 2 and blur 0.8 px, as a camera
	 * would see it. */
	RenderOptions render = realisticRender();
	static RenderOptions realisticRender();

	/** The camera's optical frame on the robot (MRPT camera convention). */
	mrpt::poses::CPose3D cameraPoseOnRobot() const;

	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;
};

/** A room of \a o.room_width_m x \a o.room_depth_m with o.room_landmarks
 * landmarks evenly spread over its four walls, facing into the room. */
LandmarkMap generateRoomMap(const DatasetOptions& o);

/** A counter-clockwise rounded-rectangle loop at o.loop_margin_m from the
 * walls, sampled at \a rate_hz, starting at o.start_time. */
std::vector<TimedPose2D> generateLoop(const DatasetOptions& o, double rate_hz);

/** The trajectory of \a o (file or loop) sampled at \a rate_hz: a file's
 * poses are interpolated linearly (yaw along the shortest arc). */
std::vector<TimedPose2D> sampleTrajectory(const DatasetOptions& o, double rate_hz);

/** What writeDataset() produced. */
struct DatasetSummary
{
	int frames = 0;	 //!< camera images written
	int odometry_readings = 0;	//!< odometry entries (actions or observations)
	int sightings = 0;	//!< fully visible landmarks over all frames
	LandmarkMap map;
	std::vector<TimedPose2D> ground_truth;	//!< robot pose at each image
};

/** Writes into \a out_dir: `dataset.rawlog` (actions-observations format,
 * or observations-only with \a obs_only), images in `dataset_Images/`,
 * `map.txt`, `gt_path.txt` (`timestamp x y yaw` per image). Calls
 * \a progress(done, total) after each frame; stops after \a max_frames
 * images when > 0. The images come from \a renderer (the project's own
 * render() by default; povrayRenderer() for POV-Ray's). Deterministic for
 * o.seed. Throws std::runtime_error on I/O errors or an unusable setup. */
DatasetSummary writeDataset(
	const DatasetOptions& o, const std::string& out_dir, bool obs_only,
	const std::function<void(int, int)>& progress = {}, int max_frames = 0,
	const Renderer& renderer = Renderer(render));

}  // namespace codemark::sim
