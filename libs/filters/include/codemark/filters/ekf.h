#pragma once
/** \file ekf.h
 * EKF localization with a known landmark map on MRPT's
 * mrpt::bayes::CKalmanFilterCapable<3,3,0,3> (state: the robot's x, y [m]
 * and yaw [rad] in the map frame), in two variants:
 *  - "ekf": each sighting's L = [l2 phi1 phi2] with C_L, through
 *    h(x) = the L predicted from the robot pose, the camera's planar pose on
 *    the robot and the landmark's planar map pose (analytic Jacobian);
 *  - "ekf-pose" (the paper's own fusion): each sighting's pose fix, the
 *    robot's pose in the world from pose_in_landmark, the landmark's map
 *    pose and the camera mounting, with C_R propagated, as a direct
 *    measurement h(x) = x.
 * Prediction from the CActionRobotMovement2D's pose change (mean and
 * covariance, the covariance rotated into the world frame). Chi-square
 * gating with 3 degrees of freedom (both measurements have 3 components),
 * global initialisation from the first sighting and re-initialisation after
 * K consecutive gated-out sightings (kidnapping).
 */
#include <codemark/filters/localizer.h>
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/poses/CPose2D.h>

#include <Eigen/Core>
#include <memory>
#include <optional>

namespace codemark::filters
{
/** What one Kalman update fuses. */
enum class EkfMeasurement
{
	Landmark,  //!< L = [l2 phi1 phi2] with C_L ("ekf")
	PoseFix	 //!< the robot pose from one landmark with C_R propagated ("ekf-pose")
};

/** Options of both EKF variants (ini section `[ekf]`). */
struct EkfOptions : public mrpt::config::CLoadableOptions
{
	/** Chi-square gate: a sighting is fused when its squared Mahalanobis
	 * innovation distance is below chi2inv(gate_probability, 3) (3 DoF: the
	 * measurement has 3 components in both variants). 0.999 gives 16.27. */
	double gate_probability = 0.999;
	/** Re-initialise from the landmarks after this many consecutive gated-out
	 * sightings (kidnapping); 0 disables recovery. */
	int kidnap_rejections = 6;
	/** Multiplies every measurement covariance (C_L or the fix's) before
	 * fusing [-]; > 1 makes the filter trust the camera less. */
	double measurement_cov_scale = 1.0;
	/** Added to the diagonal of the motion noise per step: x, y [m^2] and yaw
	 * [rad^2], for unmodelled odometry errors (e.g. a scale error). */
	double extra_motion_var_xy_m2 = 1e-6;
	double extra_motion_var_yaw_rad2 = 1e-6;  //!< see extra_motion_var_xy_m2
	/** ekf (L measurements): Gauss-Newton iterations of each update (the
	 * iterated EKF, h re-linearised at the updated estimate); 1 = the plain
	 * EKF update. Each iteration must lower the MAP cost (prior plus
	 * measurement terms), else the iterations stop; they also stop once a step
	 * is below 1e-7 m / 1e-8 rad. */
	int iterations = 10;
	/** Relative tolerance of the covariance check: the smallest eigenvalue
	 * must be >= -tol * max(1, largest); smaller negative ones throw. Tiny
	 * eigenvalues in between are raised to min_eigenvalue. */
	double pd_tolerance = 1e-9;
	double min_eigenvalue = 1e-12;	//!< floor of the covariance's eigenvalues [m^2 or rad^2]
	/** The first fix (PoseEstimate::initialized): once the largest position
	 * standard deviation is below converged_std_xy_m [m] and the yaw's below
	 * converged_std_yaw_deg [deg], as the particle filter's; the filter
	 * itself runs from its first sighting. */
	double converged_std_xy_m = 0.15;
	double converged_std_yaw_deg = 5;  //!< see converged_std_xy_m

	/** Throws std::invalid_argument naming the bad key. */
	void validate() const;
	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;
};

/** The L = [l2 phi1 phi2] (docs/spec.md section 4) that a camera
 * mounted at \a robot_T_camera (planar: optical centre and optical-axis
 * heading, pose::cameraPlanarPose()) on a robot at \a world_T_robot = (x, y,
 * yaw) sees of a landmark at planar pose \a world_T_landmark. phi1, phi2
 * wrapped to (-pi, pi]. \a H, if not null, receives dL/d(x, y, yaw)
 * (analytic; the observation Jacobian of "ekf"). */
Eigen::Vector3d predictLandmarkMeasurement(
	const Eigen::Vector3d& world_T_robot, const mrpt::poses::CPose2D& robot_T_camera,
	const mrpt::poses::CPose2D& world_T_landmark, Eigen::Matrix3d* H = nullptr);

/** The motion x' = x (+) u (planar pose composition). \a F receives
 * d x'/d x, \a G receives d x'/d u (both optional). */
Eigen::Vector3d composeMotion(
	const Eigen::Vector3d& x, const Eigen::Vector3d& u, Eigen::Matrix3d* F = nullptr,
	Eigen::Matrix3d* G = nullptr);

/** Symmetrises \a P in place and checks it: finite, and positive definite
 * within \a tolerance (smallest eigenvalue >= -tolerance * max(1, largest));
 * eigenvalues below \a min_eigenvalue are raised to it. Throws
 * std::runtime_error describing the failure (with \a what) otherwise. */
void symmetriseAndCheckCovariance(
	Eigen::Matrix3d& P, double tolerance, double min_eigenvalue, const std::string& what);

/** An EKF localizer (see the file comment). \a initial: the initial pose
 * estimate; none: global initialisation from the first sighting. */
std::unique_ptr<Localizer> makeEkfLocalizer(
	EkfMeasurement measurement, const EkfOptions& options, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial = std::nullopt);

}  // namespace codemark::filters
