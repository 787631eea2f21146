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
	/** Covariance of rvec_tvec from the corner noise C_c (8x8):
	 * (J^T J)^-1 J^T C_c J (J^T J)^-1 (the unweighted LM estimate's
	 * covariance; sigma^2 (J^T J)^-1 for isotropic noise), J the 8x6
	 * Jacobian of the raw-pixel projections (cv::projectPoints). */
	Eigen::Matrix<double, 6, 6> cov = Eigen::Matrix<double, 6, 6>::Zero();
	/** The corners' squared Mahalanobis residual r^T C_c^-1 r at this
	 * solution. */
	double chi2 = 0;
	/** log det (J^T C_c^-1 J)^-1: the width of this solution in Laplace's
	 * approximation of its probability mass (pose::foldModes()). */
	double log_det_cov = 0;
	/** The solution reduced to the planar measurement (reducePnPSolution();
	 * solveGeneralPose() reduces solutions[0] only). [l2 phi1 phi2]: */
	Eigen::Vector3d L = Eigen::Vector3d::Zero();
	Eigen::Matrix3d C_L = Eigen::Matrix3d::Zero();	//!< first order, from cov
	Eigen::Vector3d pose_in_landmark = Eigen::Vector3d::Zero();	 //!< (x, y, theta) in L
	Eigen::Matrix3d C_R = Eigen::Matrix3d::Zero();	//!< first order, from cov
};

/** Fills \a s's L, C_L, pose_in_landmark and C_R from its rvec_tvec and cov
 * (as sightingTruth() of the pose; the Jacobian by central differences). */
void reducePnPSolution(PnPSolution& s);

/** Result of the general path. */
struct GeneralPose
{
	/** Distinct refined solutions, best (lowest RMS) first; one or two. */
	std::vector<PnPSolution> solutions;
	/** solutions[1].rms / solutions[0].rms (infinity when solutions[0] is
	 * exact or alone): the ambiguity of the planar pose, large = clear. */
	double ambiguity_ratio = 0;
	/** [l2 phi1 phi2] of the best solution and its local covariance (the
	 * other solution is not folded in here: pose::measure() does that). */
	Eigen::Vector3d L = Eigen::Vector3d::Zero();
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

/** The covariance of the 8 raw corner coordinates, order TL.u TL.v TR.u ...
 * BL.v [px^2]. */
using CornerCovariance = Eigen::Matrix<double, 8, 8>;

/** As above with correlated corner noise \a corner_cov (raw px^2, positive
 * definite). */
GeneralPose solveGeneralPose(
	const std::array<Eigen::Vector2d, 4>& corners_raw_px, const CameraModel& camera,
	const LandmarkGeometry& geometry, const CornerCovariance& corner_cov,
	int lm_max_iterations = 30);

/** A corner covariance whose image under P's Jacobian (P =
 * primaryMeasurement(), a function of the 8 coordinates) is exactly \a C_P.
 * The 8 coordinates are mapped one-to-one onto P and four more numbers: the
 * vertical position of each vertical edge's midpoint (m1, m2, in fx units)
 * and each edge's tilt (t1, t2: half the x difference of its ends). These
 * get independent variances \a midpoint_ratio^2 var(y_i) and \a tilt_ratio^2
 * var(x_i); ratios of 1 are independent corners of equal noise (the spec's
 * isotropic model); codemark's detector's are below 1 (its edge errors are
 * mostly shifts of whole lines; the calibration sets them,
 * PoseOptions::corner_midpoint_ratio). Mapped to raw pixels through the
 * distortion's Jacobian; \a tilt_extra_var is added to the tilts'
 * variances (PoseOptions::corner_tilt_noise_ratio; the sum is kept at least
 * 0). It lets the general path use the closed form's correlated edge
 * noise, which one isotropic corner sigma cannot carry (a common shift of
 * x1 and x2 is far less certain than their difference, which range and
 * phi2 use). */
CornerCovariance cornerCovarianceFromPrimary(
	const std::array<Eigen::Vector2d, 4>& corners_raw_px, const CameraModel& camera,
	const Eigen::Matrix4d& C_P, double midpoint_ratio = 1.0, double tilt_ratio = 1.0,
	const Eigen::Vector2d& tilt_extra_var = Eigen::Vector2d::Zero());

/** The landmark_T_camera of OpenCV's (rvec, tvec) of the model frame
 * M = (Y_L, -Z_L, -X_L) in the camera frame. */
mrpt::poses::CPose3D landmarkTCameraFromRvecTvec(const Eigen::Matrix<double, 6, 1>& rvec_tvec);

/** The reference points in the model frame M = (Y_L, -Z_L, -X_L) used for
 * PnP: (s, -t, 0) with s right and t up as seen from the front, in the order
 * TL, TR, BR, BL. */
std::array<Eigen::Vector3d, 4> modelPoints(const LandmarkGeometry& geometry);

}  // namespace codemark::pose
