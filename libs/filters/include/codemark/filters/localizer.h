#pragma once
/** \file localizer.h
 * The common face of codemark's filters (EKF localization, the paper's
 * pose-fix EKF, EKF-SLAM, particle filter): one step per processed camera
 * frame, with the odometry since the previous step and the frame's
 * observations. Filter cores hold no I/O and no middleware beyond MRPT's
 * data types.
 */
#include <codemark/landmark/map.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace codemark::filters
{
/** The robot's pose estimate in the map frame. */
struct PoseEstimate
{
	/** false until the first fix: the first estimate whose position and yaw
	 * standard deviations are below the filter's converged_std_xy_m and
	 * converged_std_yaw_deg (converged(); every localization filter), or a
	 * known initial pose. The path and the metrics start there. */
	bool initialized = false;
	mrpt::poses::CPose2D mean;	//!< x, y [m], yaw [rad]
	Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();	//!< covariance of (x, y, yaw)
};

/** One sighting tested against the filter's predicted measurement: the
 * evidence of whether the sightings' covariances are honest without ground
 * truth (docs/design.md, the NIS verdict). */
struct Innovation
{
	/** Normalised innovation squared nu^T S^-1 nu, S the innovation
	 * covariance (the prediction's spread plus the sighting's covariance). */
	double nis = 0;
	int dof = 3;  //!< its degrees of freedom: 3 for L, 2 for range-bearing
	double log_det_s = 0;  //!< log det S, the Gaussian likelihood's normaliser
	bool gated = false;	 //!< beyond the gate: not fused (counted in StepStats::rejected)
	int id = -1;  //!< the sighted landmark's ID
	/** The sighting's own share of S, tr(S^-1 R) / dof in [0, 1] (R the
	 * sighting's covariance; the rest is the prediction's): near 0 the
	 * innovation shows the prediction's error and says little of R. NaN
	 * when the filter does not report it. */
	double sighting_share = std::numeric_limits<double>::quiet_NaN();
	/** Each component's normalised squared innovation nu_i^2 / S_ii, in the
	 * measurement's order (kInnovationComponents: range, bearing and, for L,
	 * relative orientation; ekf-pose's pose fix: kPoseFixComponents; NaN
	 * beyond dof, and where the filter tests the innovation in another
	 * basis: EKF-SLAM whitens it): which of them reads larger or smaller than
	 * predicted. Each averages 1 with honest covariances. */
	std::array<double, 3> component_nis = nanComponents();
	/** The sighting's share of each component's variance, R_ii / S_ii (NaN
	 * where the filter does not report R): near 0 that component's
	 * innovation shows the prediction's error and says little of the
	 * sighting's noise. */
	std::array<double, 3> component_share = nanComponents();

	static std::array<double, 3> nanComponents()
	{
		const double nan = std::numeric_limits<double>::quiet_NaN();
		return {nan, nan, nan};
	}
};

/** Names of the innovation's components (Innovation::component_nis): L =
 * [l2 phi1 phi2] and a range-bearing sighting share the first two. */
inline constexpr std::array<const char*, 3> kInnovationComponents = {
	"range", "bearing", "orientation"};
/** The same for the pose fix that ekf-pose fuses: the robot's map pose. */
inline constexpr std::array<const char*, 3> kPoseFixComponents = {"x", "y", "yaw"};
/** The component names of \a method's innovations (Localizer::method()). */
inline const std::array<const char*, 3>& innovationComponentNames(const std::string& method)
{
	return method == "ekf-pose" ? kPoseFixComponents : kInnovationComponents;
}

/** What one step did with the frame's sightings. */
struct StepStats
{
	/** The frame's sightings tested against a prediction, fused and gated
	 * alike (not those that (re)initialised the filter, which had none). */
	std::vector<Innovation> innovations;
	int used = 0;  //!< sightings fused
	int rejected = 0;  //!< sightings gated out (chi-square) or otherwise rejected
	int unknown_id = 0;	 //!< sightings of IDs not in the map (localization only)
	bool reinitialized = false;	 //!< the filter (re)initialised from landmarks in this step
};

/** A landmark of a SLAM map with its covariance. */
struct MappedLandmark
{
	MapLandmark landmark;  //!< id, x, y, z, yaw
	Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();	//!< covariance of (x, y, yaw) [m, rad]
};

/** The Innovation of a measurement whose innovation is \a nu (angles
 * wrapped) with covariance \a S (of which \a R, when given, is the
 * measurement's own: sighting_share), gated when its NIS exceeds \a gate (a
 * chi-square quantile). An S that is not positive definite gives an infinite
 * NIS (gated). */
Innovation makeInnovation(
	const Eigen::VectorXd& nu, const Eigen::MatrixXd& S, double gate,
	const Eigen::MatrixXd* R = nullptr);

/** A run's innovations summarised (Innovation per sighting, one list per
 * step). A landmark's visit starts with a sighting of an ID that the step
 * before did not test: its innovation carries the whole of the sighting's
 * error, while those of the visit's next sightings show only how the error
 * changed since, since the filter has absorbed the rest. */
struct InnovationSummary
{
	long tested = 0;  //!< sightings tested against a prediction
	long gated = 0;	 //!< of them, beyond the gate
	long count = 0;	 //!< of them, with a finite NIS (the means' count)
	double nis_mean = 0;  //!< mean NIS
	double nis_dof = 0;	 //!< mean degrees of freedom
	double sighting_share = std::numeric_limits<double>::quiet_NaN();  //!< mean sighting_share
	/** Per component, the means of Innovation::component_nis and
	 * Innovation::component_share over the sightings that have it (NaN:
	 * none). */
	std::array<double, 3> component_nis = Innovation::nanComponents();
	std::array<double, 3> component_share = Innovation::nanComponents();
	double neg_log_likelihood = 0;	//!< sum of (log det S + NIS) / 2 (infinite NIS: +inf)
	long visits = 0;  //!< first sightings of a visit (finite NIS, inside the gate)
	double visit_ratio = 0;	 //!< their mean NIS / DoF
	double other_ratio = 0;	 //!< the other sightings' (inside the gate) mean NIS / DoF
	/** The visits' NIS exceed the others' beyond chance (their sum, over
	 * other_ratio, above chi2inv(0.99) of their degrees of freedom): the
	 * sightings' errors persist from frame to frame, and the NIS over all
	 * sightings understates them. */
	bool persistent_errors = false;
};

/** Summarises \a steps (each step's innovations, in order). */
InnovationSummary summariseInnovations(const std::vector<const std::vector<Innovation>*>& steps);

/** One filter. */
class Localizer
{
   public:
	virtual ~Localizer() = default;

	/** Name of the method: "ekf", "ekf-pose", "ekf-slam" or "pf". */
	virtual std::string method() const = 0;

	/** One step. \a odometry: the robot's motion since the previous step
	 * (its poseChange PDF carries the motion model's uncertainty), or null
	 * when there is none (first step). \a observations: the frame's
	 * codemark::CObservationCodedLandmarks and/or
	 * mrpt::obs::CObservationBearingRange (other classes are ignored). */
	virtual StepStats step(
		const mrpt::obs::CActionRobotMovement2D* odometry,
		const mrpt::obs::CSensoryFrame& observations) = 0;

	/** The current estimate. */
	virtual PoseEstimate estimate() const = 0;

	/** SLAM methods: the estimated landmark map; empty for localization. */
	virtual std::vector<MappedLandmark> landmarks() const { return {}; }
};

/** The names of the localization methods: "ekf", "ekf-pose", "ekf-slam",
 * "pf". */
const std::vector<std::string>& localizationMethods();

/** Throws std::invalid_argument "unknown localization method 'M' (expected
 * ...)" unless \a method is one of localizationMethods(). */
void requireLocalizationMethod(const std::string& method);

/** Creates the filter \a method ("ekf", "ekf-pose", "ekf-slam", "pf") from
 * the ini \a cfg (share/codemark/config/<method>.ini) and the landmark map
 * (required for localization, optional prior for SLAM). \a initial, when
 * given, is the initial pose estimate; otherwise the filter initialises
 * itself from its first sightings (global initialisation). Throws
 * std::invalid_argument naming the method or key on bad configuration. */
std::unique_ptr<Localizer> makeLocalizer(
	const std::string& method, const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial = std::nullopt);

/** The initial pose of a config's [localize] section (initial_pose_known,
 * initial_x, initial_y [m], initial_yaw_deg, initial_std_xy [m],
 * initial_std_yaw_deg), or none (global initialisation). Throws
 * std::invalid_argument on a non-positive standard deviation. */
std::optional<PoseEstimate> initialPose(const mrpt::config::CConfigFileBase& cfg);

/** The band of nis_mean / nis_dof that reads as consistent: wide, because
 * consecutive sightings of one landmark share the prediction's error and
 * are correlated. */
constexpr double kNisConsistentLow = 0.5, kNisConsistentHigh = 2.0;

/** The verdict on a run's innovations: "consistent" when K = \a nis_mean /
 * \a nis_dof lies in [kNisConsistentLow, kNisConsistentHigh], else
 * "covariances too small by about Kx" (K > 2) or "covariances too large by
 * about (1/K)x" (K < 0.5), K with 2 significant digits; "no sightings tested"
 * when \a count is 0. */
std::string nisVerdict(double nis_mean, double nis_dof, long count);

/** Below this share of the sightings in a component's innovation variance
 * (InnovationSummary::component_share) the component is the prediction's:
 * its NIS tests the motion noise (and, in the particle filter, whatever
 * else widens the cloud), whatever the sightings' covariance. */
constexpr double kPredictionComponentShare = 0.1;

/** The check of the prediction by the components the sightings barely
 * inform (the bearing: the image pins phi1 far tighter than an odometry). */
struct PredictionCheck
{
	std::string components;	 //!< their names joined by " and " (empty: none)
	double ratio = std::numeric_limits<double>::quiet_NaN();  //!< their mean NIS / DoF
	/** "consistent" when ratio lies in [kNisConsistentLow,
	 * kNisConsistentHigh], else "too large by about Kx" or "too small by
	 * about Kx" (the prediction's covariance); empty without components. */
	std::string verdict;
	/** Whether the components read outside the band (a verdict other than
	 * "consistent"). */
	bool off() const
	{
		return std::isfinite(ratio) && (ratio < kNisConsistentLow || ratio > kNisConsistentHigh);
	}
};

/** The check of \a s by its components under kPredictionComponentShare,
 * named by \a names (innovationComponentNames()). */
PredictionCheck predictionCheck(
	const InnovationSummary& s, const std::array<const char*, 3>& names);

/** Whether a pose covariance \a cov of (x, y, yaw) is a fix: the largest
 * position standard deviation (the x-y block's largest eigenvalue) below
 * \a std_xy_m and the yaw's below \a std_yaw_rad. */
bool converged(const Eigen::Matrix3d& cov, double std_xy_m, double std_yaw_rad);

}  // namespace codemark::filters
