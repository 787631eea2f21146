#pragma once
/** \file general.h
 * The general path, beyond the paper: the full 6-DoF pose of the camera from
 * the four reference points (planar PnP), for any camera orientation and
 * lens distortion, with its covariance from the corner noise and the
 * reduction to the planar measurement L and pose_in_landmark.
 *
 * OpenCV 4.6's SOLVEPNP_IPPE_SQUARE returns a wrong pose while reporting
 * success for many exactly-180-degree configurations (a level camera squarely
 * facing a wall landmark; see tests/pose/test_general.cpp), and so does
 * SOLVEPNP_IPPE with that model: the camera's rotation is then exactly pi.
 * This path puts the model frame so that such a camera has the identity
 * rotation instead, and uses SOLVEPNP_IPPE (both solutions) plus
 * SOLVEPNP_SQPNP as candidates, each refined by cv::solvePnPRefineLM on the
 * raw-pixel reprojection error.
 */
#include <codemark/landmark/camera.h>
#include <codemark/landmark/geometry.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>
#include <array>
#include <vector>

namespace codemark::pose
{
/** One refined PnP solution. */
struct PnPSolution
{
	mrpt::poses::CPose3D landmark_T_camera;	 //!< optical frame in frame L
	/** OpenCV's parameters of the landmark model in the camera frame: rvec
	 * (Rodrigues, rad) and tvec [m], model frame M = (Y_L, -Z_L, -X_L)
	 * (identity rotation for a level camera squarely facing the landmark). */
	Eigen::Matrix<double, 6, 1> rvec_tvec = Eigen::Matrix<double, 6, 1>::Zero();
	double rms_px = 0;	//!< RMS reprojection error over the 8 corner coordinates [px]
	/** Covariance of rvec_tvec from the corner noise: sigma^2 (J^T J)^-1, J the
	 * 8x6 Jacobian of the raw-pixel projections (cv::projectPoints). */
	Eigen::Matrix<double, 6, 6> cov = Eigen::Matrix<double, 6, 6>::Zero();
};

/** Result of the general path. */
struct GeneralPose
{
	/** Distinct refined solutions, best (lowest RMS) first; one or two. */
	std::vector<PnPSolution> solutions;
	/** solutions[1].rms / solutions[0].rms (infinity when solutions[0] is
	 * exact or alone): the ambiguity of the planar pose, large = clear. */
	double ambiguity_ratio = 0;
	Eigen::Vector3d L = Eigen::Vector3d::Zero();  //!< [l2 phi1 phi2] of the best solution
	Eigen::Matrix3d C_L = Eigen::Matrix3d::Zero();
	Eigen::Vector3d pose_in_landmark = Eigen::Vector3d::Zero();	 //!< (x, y, theta) in L
	Eigen::Matrix3d C_R = Eigen::Matrix3d::Zero();
};

/** Solves the general path.
 * \param corners_raw_px raw pixels, order TL, TR, BR, BL as seen from the front.
 * \param corner_sigma_px standard deviation of each corner coordinate [px].
 * \param lm_max_iterations iterations of each LM refinement.
 * The reduction to L and pose_in_landmark (as sightingTruth() of the pose)
 * has its Jacobian by central differences (numeric: the reduction is a
 * composition of atan2/hypot of the pose, with no closed form worth the
 * risk). Throws std::runtime_error when no solution is found. */
GeneralPose solveGeneralPose(
	const std::array<Eigen::Vector2d, 4>& corners_raw_px, const CameraModel& camera,
	const LandmarkGeometry& geometry, double corner_sigma_px, int lm_max_iterations = 30);

/** The landmark_T_camera of OpenCV's (rvec, tvec) of the model frame
 * M = (Y_L, -Z_L, -X_L) in the camera frame. */
mrpt::poses::CPose3D landmarkTCameraFromRvecTvec(const Eigen::Matrix<double, 6, 1>& rvec_tvec);

/** The reference points in the model frame M = (Y_L, -Z_L, -X_L) used for
 * PnP: (s, -t, 0) with s right and t up as seen from the front, in the order
 * TL, TR, BR, BL. */
std::array<Eigen::Vector3d, 4> modelPoints(const LandmarkGeometry& geometry);

}  // namespace codemark::pose
