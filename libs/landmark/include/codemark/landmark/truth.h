#pragma once
/** \file truth.h
 * The landmark measurement L = [l2 phi1 phi2] and the camera's planar pose
 * in the landmark frame, computed directly from scene geometry (not from the
 * image): the ground truth that the closed form of the pose library must
 * reproduce (docs/spec.md section 4).
 */
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>

namespace codemark
{
/** Geometric ground truth of one sighting. */
struct SightingTruth
{
	/** [l2 phi1 phi2]: horizontal distance from the optical centre to the
	 * landmark centre [m]; bearing of the landmark centre from the optical
	 * axis, counter-clockwise positive [rad]; angle from the landmark's
	 * inward normal (-X_L) to the optical axis, counter-clockwise positive
	 * [rad]. Angles in the horizontal plane. */
	Eigen::Vector3d L = Eigen::Vector3d::Zero();
	/** Camera's planar pose in frame L: x, y [m], theta [rad] the heading of
	 * the (horizontal projection of the) optical axis, wrapped to (-pi, pi]. */
	Eigen::Vector3d pose_in_landmark = Eigen::Vector3d::Zero();
};

/** Ground truth from the camera's optical frame expressed in frame L
 * (MRPT camera convention: z optical axis, x right, y down). */
SightingTruth sightingTruth(const mrpt::poses::CPose3D& landmark_T_camera);

/** Wraps an angle to (-pi, pi]. */
double wrapToPi(double a);

}  // namespace codemark
