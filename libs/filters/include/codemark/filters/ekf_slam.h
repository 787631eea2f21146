#pragma once
/** \file ekf_slam.h
 * EKF-SLAM on MRPT's mrpt::bayes::CKalmanFilterCapable<3,3,3,3>, following
 * mrpt::slam::CRangeBearingKFSLAM2D: state = the robot's (x, y, yaw) and
 * every mapped landmark's (x, y, yaw) in the map frame [m, m, rad].
 *
 * - Measurements: each coded-landmark sighting's L = [l2 phi1 phi2] with its
 *   own C_L (docs/spec.md section 4), and each
 *   mrpt::obs::CObservationBearingRange reading with a landmark ID as
 *   z = [range, yaw, 0] (the reading's covariance when validCovariances,
 *   else the ini's std_sensor_range / std_sensor_yaw). A point landmark has
 *   the same (x, y, yaw) block; its yaw is never observed by range-bearing
 *   readings: it gets a fixed variance point_yaw_sigma^2 with no correlation
 *   to anything, and the zero column of the Jacobian keeps it untouched.
 * - Range-bearing-only data (MRPT's kf-slam_demo) runs by default in a
 *   second instantiation with point landmarks, CKalmanFilterCapable<3,2,2,3>
 *   (ini `landmarks`): two thirds of the state and of the scalar updates, so
 *   the same cost per step as CRangeBearingKFSLAM2D's model. Coded sightings
 *   fed to it contribute their range and bearing (l2, phi1) only.
 * - Per-sighting covariances in MRPT's single-R template: each observation is
 *   whitened (z' = W z with W = chol(C)^-1, so R = I), exact for a linear(ised)
 *   model and what lets MRPT's scalar-at-once update (kfEKFAlaDavison, O(n^2)
 *   per scalar instead of the full O(n^3) (I-KH)P) run with per-sighting
 *   covariances. Angle components of the innovation are wrapped to (-pi, pi]
 *   before whitening.
 * - Association by ID; landmarks are added on first sight through the
 *   inverse observation model with its Jacobians. Only the landmarks
 *   sighted in the step are predicted. Chi-square gating on the whitened
 *   innovation (3 DoF for L, 2 for range-bearing).
 * - The map frame is the robot's start (origin, zero covariance) unless an
 *   initial pose is given, or a prior map anchors it: prior entries enter the
 *   state with diagonal covariance (ini prior sigmas) and, with no initial
 *   pose, the robot stays uninitialised until its first coded sighting of a
 *   prior landmark fixes its pose.
 * - The covariance is symmetrised after every prediction and update and its
 *   diagonal checked (OnNormalizeStateVector).
 */
#include <codemark/filters/localizer.h>
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/poses/CPose2D.h>

#include <Eigen/Core>
#include <memory>
#include <string>

namespace codemark::filters
{
/** Which observations of a sensory frame EKF-SLAM fuses. */
enum class SlamInput
{
	/** Coded-landmark sightings when the frame has any
	 * CObservationCodedLandmarks, else its CObservationBearingRange readings
	 * (so a rawlog annotated with both, twins of each other, is not fused
	 * twice). */
	Auto,
	Coded,	//!< only CObservationCodedLandmarks
	BearingRange,  //!< only CObservationBearingRange
	Both  //!< everything (only for independent sensors)
};

/** The landmark state of EKF-SLAM. */
enum class SlamLandmarks
{
	/** Full when the first frame with sightings has a coded sighting, else
	 * Point. */
	Auto,
	Full,  //!< (x, y, yaw) per landmark, CKalmanFilterCapable<3,3,3,3>
	Point  //!< (x, y) per landmark, CKalmanFilterCapable<3,2,2,3>
};

/** Options of EKF-SLAM (ini section `[ekf_slam]`; the Kalman template's own
 * options, e.g. `method`, `enable_profiler`, in `[ekf_slam_kf]`). */
struct EkfSlamOptions : public mrpt::config::CLoadableOptions
{
	SlamInput input = SlamInput::Auto;	//!< which observations to fuse
	SlamLandmarks landmarks = SlamLandmarks::Auto;	//!< landmark state (ini: auto, full, point)
	/** Chi-square gate: a sighting of a mapped landmark is fused when its
	 * squared Mahalanobis innovation distance is below
	 * chi2inv(gate_probability, dof), dof = 3 for L, 2 for range-bearing.
	 * 1 disables gating. */
	double gate_probability = 0.9999;
	/** Range-bearing readings without a valid per-reading covariance (or
	 * validCovariances = false): range sigma [m]. */
	double std_sensor_range = 0.01;
	double std_sensor_yaw_deg = 0.1;  //!< as std_sensor_range: bearing sigma [deg]
	/** Range-bearing only: use the reading's own covariance when the
	 * observation has validCovariances. */
	bool use_reading_covariance = true;
	/** Multiplies every coded sighting's C_L before fusing [-]. */
	double measurement_cov_scale = 1.0;
	/** Fixed standard deviation of the never-observed yaw of a point
	 * landmark (added from a range-bearing reading) [deg]. */
	double point_yaw_sigma_deg = 180.0;
	/** Added to the odometry's covariance per step: x, y [m^2], yaw [rad^2]. */
	double extra_motion_var_xy_m2 = 0.0;
	double extra_motion_var_yaw_rad2 = 0.0;	 //!< see extra_motion_var_xy_m2
	/** A step without odometry keeps the robot still with this noise: x, y
	 * sigma [m] and yaw sigma [deg] (0: no noise, as when it stands still). */
	double std_no_odo_xy = 0.0;
	double std_no_odo_yaw_deg = 0.0;  //!< see std_no_odo_xy
	/** Optional prior map (spec section 3 format, or MRPT's 7-column
	 * landmark files) used when the factory is given an empty map; relative
	 * paths are relative to the working directory. */
	std::string prior_map_file;
	double prior_sigma_xy = 0.01;  //!< prior map entries: x, y sigma [m]
	double prior_sigma_yaw_deg = 2.0;  //!< prior map entries: yaw sigma [deg]
	/** The covariance check: a diagonal entry below -pd_tolerance throws
	 * std::runtime_error, one in [-pd_tolerance, 0] is raised to 0 [m^2 or rad^2]. */
	double pd_tolerance = 1e-9;

	/** Throws std::invalid_argument naming the bad key. */
	void validate() const;
	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;
};

/** The measurement model for one landmark, shared by coded sightings and
 * range-bearing readings: the sensor's planar pose in the world is
 * s = robot (+) sensor_on_robot, d = landmark_xy - s_xy, and
 *   h = [ |d|, wrap(atan2(d) - s_yaw), wrap(s_yaw - landmark_yaw - pi) ]
 * i.e. [l2 phi1 phi2] of docs/spec.md section 4 (for range-bearing data
 * the first two are range and yaw; the third is not used).
 * \param robot (x, y, yaw) of the robot in the map [m, m, rad].
 * \param sensor_on_robot planar pose of the sensor (camera: optical centre
 *        and optical-axis heading) on the robot.
 * \param landmark (x, y, yaw) of the landmark in the map.
 * \param Hx, Hy if not null, receive dh/drobot and dh/dlandmark. */
Eigen::Vector3d slamObservation(
	const Eigen::Vector3d& robot, const mrpt::poses::CPose2D& sensor_on_robot,
	const Eigen::Vector3d& landmark, Eigen::Matrix3d* Hx = nullptr, Eigen::Matrix3d* Hy = nullptr);

/** The inverse of slamObservation(): the landmark (x, y, yaw) from the robot
 * pose and z = [l2 phi1 phi2]:
 *   landmark_xy = s_xy + l2 (cos, sin)(s_yaw + phi1),
 *   landmark_yaw = wrap(s_yaw - phi2 - pi).
 * \param Jx, Jz if not null, receive d(landmark)/drobot and d(landmark)/dz. */
Eigen::Vector3d slamInverseObservation(
	const Eigen::Vector3d& robot, const mrpt::poses::CPose2D& sensor_on_robot,
	const Eigen::Vector3d& z, Eigen::Matrix3d* Jx = nullptr, Eigen::Matrix3d* Jz = nullptr);

/** EKF-SLAM as a Localizer (method "ekf-slam"). */
class EkfSlam : public Localizer
{
   public:
	/** \a prior: prior map entries (may be empty); \a initial: the robot's
	 * initial pose and covariance (default: the origin, zero covariance,
	 * unless a prior map is given, see the file comment). \a kf_options_cfg
	 * / \a kf_section: where to read the Kalman template's options (method,
	 * enable_profiler, ...); null keeps MRPT's defaults except the method,
	 * which is kfEKFAlaDavison. */
	EkfSlam(
		const EkfSlamOptions& options, const LandmarkMap& prior,
		const std::optional<PoseEstimate>& initial,
		const mrpt::config::CConfigFileBase* kf_options_cfg = nullptr,
		const std::string& kf_section = "ekf_slam_kf");
	~EkfSlam() override;

	std::string method() const override { return "ekf-slam"; }
	StepStats step(
		const mrpt::obs::CActionRobotMovement2D* odometry,
		const mrpt::obs::CSensoryFrame& observations) override;
	PoseEstimate estimate() const override;
	std::vector<MappedLandmark> landmarks() const override;

	/** Landmark state dimension: 3 (x, y, yaw), 2 (points), 0 before the
	 * filter is built (SlamLandmarks::Auto before the first sighting). */
	std::size_t landmarkDimension() const;
	/** Number of landmarks in the state. */
	std::size_t landmarkCount() const;
	/** The full state covariance (3 + D N square, D = landmarkDimension()). */
	Eigen::MatrixXd fullCovariance() const;
	/** Mean time of one Kalman iteration [ms] from MRPT's profiler ("KF:complete_step"),
	 * 0 unless the Kalman options enable the profiler. */
	double meanKalmanIterationMs() const;
	/** Kalman iterations run so far (a step runs one, plus one per repeated
	 * sighting of the same landmark in a frame). */
	std::size_t kalmanIterations() const;

   private:
	class Impl;
	std::unique_ptr<Impl> impl_;
};

}  // namespace codemark::filters
