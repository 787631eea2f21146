#pragma once
/** \file predict.h
 * Prediction before imaging (the paper's use ii, section 3): from the
 * robot's pose estimate and the map, predict what a landmark would look like
 * (corners, P, L, C_L), whether the detector could see it, and how much a fix
 * from it would shrink the robot's uncertainty; rank landmarks by that.
 */
#include <codemark/landmark/camera.h>
#include <codemark/landmark/map.h>
#include <codemark/pose/measurement.h>
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>
#include <array>
#include <vector>

namespace codemark::pose
{
/** Limits on what the detector can use. */
struct VisibilityOptions : public mrpt::config::CLoadableOptions
{
	double max_range_m = 6.0;  //!< maximum horizontal distance l2 [m]
	/** Maximum angle between the line of sight (landmark to camera) and the
	 * landmark's outward normal [deg] (the paper's map goes to 70 deg). */
	double max_view_angle_deg = 70.0;
	/** Minimum vertical size of the reference square in the image,
	 * min(2 y1, 2 y2) [px]: the detector needs the code cells resolved. */
	double min_size_px = 30.0;
	/** The outer frame must lie this far inside the image borders [px]. */
	double image_margin_px = 1.0;

	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;
};

/** The predicted sighting of one landmark. */
struct Prediction
{
	int id = -1;
	/** Projected reference points, raw pixels, TL TR BR BL (valid when in_front). */
	std::array<Eigen::Vector2d, 4> corners_px;
	bool in_front = false;	//!< every outer frame corner in front of the camera
	bool in_fov = false;  //!< every outer frame corner inside the image (with the margin)
	bool facing = false;  //!< the camera is on the printed side (X_L > 0)
	bool in_range = false;	//!< l2 <= max_range_m
	bool angle_ok = false;	//!< view angle <= max_view_angle_deg
	bool big_enough = false;  //!< min(2 y1, 2 y2) >= min_size_px
	/** All of the above. */
	bool visible() const
	{
		return in_front && in_fov && facing && in_range && angle_ok && big_enough;
	}

	double view_angle_rad = 0;	//!< line of sight vs outward normal, CCW positive
	double size_px = 0;	 //!< min(2 y1, 2 y2) [px]
	/** The predicted measurement (closed form at the predicted P; valid when
	 * in_front and facing). */
	Measurement measurement;
	/** Covariance of the robot's world pose from this fix alone. */
	Eigen::Matrix3d C_fix_world = Eigen::Matrix3d::Zero();
	/** The robot's covariance after fusing the fix with the prior (Kalman
	 * update with H = I, symmetrised). */
	Eigen::Matrix3d posterior = Eigen::Matrix3d::Zero();
	/** Ranking score: trace of the posterior's position block [m^2]; lower
	 * is better. */
	double score = 0;
};

/** The camera's optical frame in the world for a planar robot pose (robot
 * frame at floor level, z = 0). */
mrpt::poses::CPose3D worldTCamera(
	const mrpt::poses::CPose2D& world_T_robot, const mrpt::poses::CPose3D& robot_T_camera);

/** Kalman update of a prior (covariance \a prior) with a direct measurement
 * of the same state with covariance \a C_fix: (I - K) prior, K = prior
 * (prior + C_fix)^-1, symmetrised. */
Eigen::Matrix3d fuseCovariance(const Eigen::Matrix3d& prior, const Eigen::Matrix3d& C_fix);

/** Predicts the sighting of \a landmark by a camera \a robot_T_camera
 * (MRPT optical-frame convention) on a robot at \a world_T_robot with
 * covariance \a robot_cov (x, y, yaw). The measurement uses the closed form
 * (options.sigma_px), so the camera should be level. */
Prediction predictSighting(
	const mrpt::poses::CPose2D& world_T_robot, const Eigen::Matrix3d& robot_cov,
	const mrpt::poses::CPose3D& robot_T_camera, const CameraModel& camera,
	const MapLandmark& landmark, const PoseOptions& options = PoseOptions(),
	const VisibilityOptions& visibility = VisibilityOptions());

/** The visible landmarks of \a map, best (lowest score) first. */
std::vector<Prediction> rankLandmarks(
	const mrpt::poses::CPose2D& world_T_robot, const Eigen::Matrix3d& robot_cov,
	const mrpt::poses::CPose3D& robot_T_camera, const CameraModel& camera, const LandmarkMap& map,
	const PoseOptions& options = PoseOptions(),
	const VisibilityOptions& visibility = VisibilityOptions());

}  // namespace codemark::pose
