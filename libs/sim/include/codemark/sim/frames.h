#pragma once
/** \file frames.h
 * Sequences of rendered frames with ground truth, as written by
 * codemark-render: camera poses (generated around a map's landmarks or read
 * from a file) and one JSON line of ground truth per frame.
 */
#include <codemark/landmark/camera.h>
#include <codemark/landmark/map.h>
#include <codemark/sim/render.h>
#include <mrpt/poses/CPose3D.h>

#include <cstdint>
#include <string>
#include <vector>

namespace codemark::sim
{
/** How generated viewpoints look at the map's landmarks. */
struct ViewpointOptions
{
	double min_distance_m = 0.8;  //!< horizontal distance to the landmark centre, lower bound [m]
	double max_distance_m = 4.0;  //!< upper bound [m]
	double max_view_angle_rad = 50.0 * M_PI / 180;	//!< |angle| from the landmark's normal [rad]
	double max_bearing_rad =
		0.15;  //!< |bearing| of the landmark centre from the optical axis [rad]
	double camera_height_m = 0.6;  //!< height of the optical centre in the world [m]
};

/** \a count level camera poses (world_T_camera, optical frame): frame i
 * looks at landmark i mod N of \a map with levelCameraLookingAt, distance,
 * view angle and bearing drawn uniformly within \a vp from \a seed.
 * Throws std::invalid_argument when the map is empty or \a vp is
 * inconsistent. */
std::vector<mrpt::poses::CPose3D> viewpointsAroundLandmarks(
	const LandmarkMap& map, int count, uint64_t seed, const ViewpointOptions& vp = {});

/** The optical frame of a camera whose body frame (x forward, y left, z up,
 * MRPT's robot convention) has pose \a world_T_body. */
mrpt::poses::CPose3D opticalFromBody(const mrpt::poses::CPose3D& world_T_body);
/** The body frame (x forward, y left, z up) of optical frame \a world_T_camera. */
mrpt::poses::CPose3D bodyFromOptical(const mrpt::poses::CPose3D& world_T_camera);

/** Reads a camera poses file: one pose per line, `x y z yaw pitch roll`,
 * metres and degrees, of the camera's body frame (x forward, y left, z up)
 * in the world; `#` starts a comment. Returns world_T_camera (optical
 * frame) per line. Throws std::runtime_error naming the file and line. */
std::vector<mrpt::poses::CPose3D> loadCameraPoses(const std::string& path);

/** A landmark worth listing for a frame: in front, facing, every reference
 * corner in front of the camera and the reference square at least partly
 * inside the image. */
bool isInView(const LandmarkTruth& truth, const CameraModel& camera);

/** One JSON object (no newline) with the ground truth of a frame:
 * {"image", "width", "height", "camera_pose": [x, y, z, yaw, pitch, roll]
 * of the body frame (m, rad), "landmarks": [{"id", "corners" [[u, v] x 4,
 * raw pixels, TL TR BR BL], "P", "L", "pose_in_landmark", "fully_visible",
 * "area_px", "occluded_fraction"}]} for the landmarks isInView() accepts. */
std::string frameTruthJson(
	const std::string& image, const mrpt::poses::CPose3D& world_T_camera,
	const std::vector<LandmarkTruth>& truth, const CameraModel& camera);

}  // namespace codemark::sim
