#pragma once
/** \file closed_form.h
 * The paper's closed form (Baczyk, Kasinski, Skrzypczynski 2003, section 2.3
 * and 3) in the conventions of docs/spec.md section 4:
 * P = [x1 y1 x2 y2] -> L = [l2 phi1 phi2] -> the camera's planar pose in the
 * landmark frame, with analytic Jacobians, covariance propagation and the
 * composition with the landmark's map pose and the camera's mounting on the
 * robot. Valid for a camera whose optical axis is horizontal.
 */
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>
#include <cmath>

namespace codemark::pose
{
/** L = [l2 phi1 phi2] from P = [x1 y1 x2 y2] (paper eq. 1-3, the spec's
 * signs; docs/design.md, "The measurement"):
 *   xm   = (x1 y2 + x2 y1) / (y1 + y2)
 *   l2   = h (y1 + y2) / (2 y1 y2) * sqrt(lambda^2 + xm^2)
 *   phi1 = -atan2(xm, lambda)
 *   phi2 =  atan2(lambda (y2 - y1), x2 y1 - x1 y2)
 * \param P primary measurement [px of focal length lambda, relative to the
 *        principal point; x right]; needs y1, y2 > 0.
 * \param lambda_px focal length [px] (fx).
 * \param h_m half-length of the vertical inner edge [m]
 *        (LandmarkGeometry::innerHalf(), scaled with the landmark).
 * \param J_P if not null, receives the 3x4 Jacobian dL/dP (paper eq. 4-8,
 *        derived analytically from the forms above).
 * \return [l2 [m], phi1 [rad], phi2 [rad]]. Throws std::invalid_argument when
 *         y1 or y2 is not positive. */
Eigen::Vector3d landmarkFromPrimary(
	const Eigen::Vector4d& P, double lambda_px, double h_m,
	Eigen::Matrix<double, 3, 4>* J_P = nullptr);

/** The inverse of landmarkFromPrimary(): the P = [x1 y1 x2 y2] that a
 * landmark at L = [l2 phi1 phi2] gives (level camera, the vertical edges
 * at the landmark centre -+ h along Y_L, each imaged at x_i = -lambda
 * left_i / forward_i and y_i = lambda h / forward_i in the camera's
 * horizontal (forward, left) frame). \param J_L if not null, receives the
 * 4x3 Jacobian dP/dL. Throws std::invalid_argument when an edge is not in
 * front of the camera. */
Eigen::Vector4d primaryFromLandmark(
	const Eigen::Vector3d& L, double lambda_px, double h_m,
	Eigen::Matrix<double, 4, 3>* J_L = nullptr);

/** primaryFromLandmark() from l2 and the cosines and sines of phi1 and
 * phi2, without trigonometry and without throwing: false (and \a P, \a J_L
 * untouched) when an edge is not in front of the camera. For hot loops (the
 * particle filter's likelihood, once per particle and sighting). */
bool primaryFromLandmark(
	double l2, double cos_phi1, double sin_phi1, double cos_phi2, double sin_phi2, double lambda_px,
	double h_m, Eigen::Vector4d& P, Eigen::Matrix<double, 4, 3>* J_L = nullptr);

/** L from P by weighted least squares: the closed form's four equations
 * have three unknowns, and its formulas combine them unweighted (phi2 from
 * y2 - y1 alone, wasting the square's foreshortened width x2 - x1, which
 * carries most of phi2 at oblique views). Gauss-Newton on (P -
 * primaryFromLandmark(L))^T C_P^-1 (P - primaryFromLandmark(L)) from \a L0
 * (the closed form's L); P alone, so the same data as the paper's path.
 * Returns L; \a C_L, if not null, receives (J^T C_P^-1 J)^-1, J = dP/dL at
 * the solution (first order). Throws std::invalid_argument if C_P is not
 * positive definite. */
Eigen::Vector3d refineLandmarkOnPrimary(
	const Eigen::Vector4d& P, const Eigen::Matrix4d& C_P, double lambda_px, double h_m,
	const Eigen::Vector3d& L0, Eigen::Matrix3d* C_L = nullptr);

/** The viewing angle of a sighting L [rad]: between the line of sight and
 * the landmark's outward normal, |phi1 + phi2| wrapped to [0, pi] (0 seen
 * squarely). */
inline double viewAngle(const Eigen::Vector3d& L)
{
	return std::abs(std::remainder(L[1] + L[2], 2 * M_PI));
}

/** The camera's planar pose in frame L from L (paper eq. 12-14 in the spec's
 * convention): x = l2 cos(phi1 + phi2), y = l2 sin(phi1 + phi2),
 * theta = pi + phi2 wrapped to (-pi, pi]. x, y [m] of the optical centre,
 * theta [rad] the heading of the optical axis in L.
 * \param J_L if not null, receives the 3x3 Jacobian d(x, y, theta)/dL. */
Eigen::Vector3d poseFromLandmark(const Eigen::Vector3d& L, Eigen::Matrix3d* J_L = nullptr);

/** The covariance of the camera's planar pose (poseFromLandmark()) from that
 * of L to second order: J_L C_L J_L^T (the spec's first order, paper eq.
 * 15-16) plus 1/2 tr(H_i C_L H_j C_L), H_i the Hessian of pose component i
 * (the exact covariance of a quadratic function of a Gaussian L). One
 * landmark fixes the bearing phi1 far better than phi2, so the first-order
 * C_R is nearly singular along "sideways position minus l2 times heading";
 * beyond about 2 m the products of the l2 and phi2 errors and the curvature
 * l2 dphi2^2 / 2 exceed that smallest sigma, and only this term keeps C_R
 * honest there (docs/benchmarks/pose.md). */
Eigen::Matrix3d poseCovarianceSecondOrder(const Eigen::Vector3d& L, const Eigen::Matrix3d& C_L);

/** C_P = diag(sx^2, sy^2, sx^2, sy^2): \a sigma_x_px, \a sigma_y_px are the
 * standard deviations of each component of P (not of each corner) [px]. */
Eigen::Matrix4d primaryCovariance(double sigma_x_px, double sigma_y_px);

/** The planar pose of a camera mounted on the robot: the position of its
 * optical centre (x, y in the robot frame [m]) and the heading of its
 * optical axis's horizontal projection [rad]. \a robot_T_camera is MRPT's
 * camera convention (optical frame: z forward, x right, y down), e.g.
 * CPose3D(0, 0, h, -pi/2, 0, -pi/2) for a level forward camera. */
mrpt::poses::CPose2D cameraPlanarPose(const mrpt::poses::CPose3D& robot_T_camera);

/** Planar pose of a landmark in the world from its 3D map pose
 * (world_T_landmark = CPose3D(x, y, z, yaw, 0, 0)): (x, y, yaw). */
mrpt::poses::CPose2D landmarkPlanarPose(const mrpt::poses::CPose3D& world_T_landmark);

/** The robot's planar pose in the world from the camera's planar pose in
 * frame L and its covariance:
 *   world_T_robot = world_T_landmark (+) landmark_T_camera (+) camera_T_robot
 * (planar parts; the landmark pose and the camera mounting are exact).
 * \param cam_in_landmark (x, y, theta) of the camera in L [m, m, rad].
 * \param C_R its 3x3 covariance.
 * \param world_T_landmark planar pose of L in the world.
 * \param robot_T_camera planar pose of the camera on the robot (cameraPlanarPose()).
 * \param C_world if not null, receives the 3x3 covariance of the result.
 * \param J if not null, receives d(world pose)/d(cam_in_landmark). */
mrpt::poses::CPose2D robotPoseInWorld(
	const Eigen::Vector3d& cam_in_landmark, const Eigen::Matrix3d& C_R,
	const mrpt::poses::CPose2D& world_T_landmark, const mrpt::poses::CPose2D& robot_T_camera,
	Eigen::Matrix3d* C_world = nullptr, Eigen::Matrix3d* J = nullptr);

/** The inverse of robotPoseInWorld() for the mean: the camera's planar pose
 * in L of a robot at \a world_T_robot. */
Eigen::Vector3d cameraInLandmark(
	const mrpt::poses::CPose2D& world_T_robot, const mrpt::poses::CPose2D& world_T_landmark,
	const mrpt::poses::CPose2D& robot_T_camera);

}  // namespace codemark::pose
