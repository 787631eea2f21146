#pragma once
/** \file particle_filter.h
 * The particle filter localizer ("pf"): MRPT's CMonteCarloLocalization2D and
 * CParticleFilter over a codemark::CCodedLandmarksMap, with uniform global
 * initialisation and particles injected around single-landmark pose fixes
 * when the particle set stops explaining the sightings (kidnapping, or a
 * collapsed effective sample size).
 *
 * Ini sections (share/codemark/config/pf.ini): [PF_options] and
 * [KLD_options] as MRPT's pf-localization, [ParticleFilter] (below), and
 * [MetricMap_codedLandmarksMap_00_likelihoodOpts] (the map's likelihood,
 * same section name as in share/codemark/pf-localization.ini).
 */
#include <codemark/filters/localizer.h>
#include <codemark/mrpt/CCodedLandmarksMap.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <mrpt/bayes/CParticleFilter.h>
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/slam/CMonteCarloLocalization2D.h>

#include <Eigen/Core>
#include <memory>
#include <vector>

namespace codemark::filters
{
/** [ParticleFilter]: what MRPT's own option blocks do not cover. */
struct ParticleFilterOptions : public mrpt::config::CLoadableOptions
{
	int particles_count = 2000;	 //!< initial number of particles (KLD may change it)
	/** Uniform initialisation: the landmarks' bounding box grown by this
	 * margin on each side [m]. */
	double init_margin_m = 0.5;
	double initial_std_xy_m = 0.2;	//!< spread around a given initial pose [m]
	double initial_std_yaw_deg = 10.0;	//!< spread around a given initial pose [deg]

	/** Injection: fraction of the particles replaced by samples around the
	 * frame's single-landmark fixes, in (0, 1]. */
	double inject_fraction = 0.5;
	/** Inject when the effective sample size before resampling falls below
	 * this fraction of the particle count (0 disables). */
	double inject_ess_threshold = 0.02;
	/** Chi-square gate (3 DoF; 16.27 = 99.9%). Once converged, a sighting
	 * whose NIS against the predicted measurement distribution exceeds it
	 * is left out of the update and counted as rejected (as the EKFs gate);
	 * a frame whose sightings all fail it at the best particle after the
	 * update is "unexplained". */
	double gate_chi2 = 16.27;
	/** Inject after this many consecutive unexplained frames once converged
	 * (kidnapping); before the first convergence after one (0 disables). */
	int inject_after_unexplained = 2;
	double inject_min_std_xy_m = 0.02;	//!< floor of the injected spread (added to the fix's C) [m]
	double inject_min_std_yaw_deg = 1.0;  //!< floor of the injected spread [deg]

	/** estimate().initialized becomes true (and stays) once the particle
	 * cloud's largest position standard deviation and its yaw standard
	 * deviation are below these. */
	double converged_std_xy_m = 0.15;
	double converged_std_yaw_deg = 5.0;

	/** Regularisation (the post-regularised particle filter of Musso,
	 * Oudjane and Le Gland, 2001): after each update with sightings every
	 * particle moves by a draw from N(0, (roughening h)^2 C), C the cloud's
	 * weighted covariance and h = (4 / (N (d + 2)))^(1 / (d + 4)) the
	 * Gaussian kernel's optimal bandwidth for N particles in d = 3
	 * dimensions. Resampling copies particles, and a fine odometry barely
	 * separates the copies: without it the cloud collapses onto a few poses
	 * while a landmark's first sightings still agree in their error, and
	 * reports a fraction of the spread it has. >= 0; 0 disables. */
	double roughening = 0.3;

	/** Seeds MRPT's random generator at construction when >= 0 (tests and
	 * benchmarks); < 0 leaves it as it is. */
	int random_seed = -1;
	/** Motion noise used when a step has no odometry (first step). */
	double no_odometry_std_xy_m = 0.01;
	double no_odometry_std_yaw_deg = 1.0;

	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;
};

/** The particle filter localizer. */
class ParticleFilterLocalizer : public Localizer
{
   public:
	/** Reads [PF_options], [KLD_options], [ParticleFilter] and
	 * [MetricMap_codedLandmarksMap_00_likelihoodOpts] from \a cfg.
	 * Without \a initial: uniform over the map's bounding box (+ margin),
	 * all headings. Throws std::invalid_argument on an empty map or bad
	 * options. */
	ParticleFilterLocalizer(
		const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
		const std::optional<PoseEstimate>& initial = std::nullopt);

	std::string method() const override { return "pf"; }
	StepStats step(
		const mrpt::obs::CActionRobotMovement2D* odometry,
		const mrpt::obs::CSensoryFrame& observations) override;
	PoseEstimate estimate() const override;

	/** The particles (read-only), e.g. for drawing. */
	const mrpt::slam::CMonteCarloLocalization2D& particles() const { return m_pdf; }
	/** The map the particles are weighted against. */
	const CCodedLandmarksMap& map() const { return *m_map; }
	const ParticleFilterOptions& options() const { return m_opts; }
	/** Statistics of the last executeOn(). */
	const mrpt::bayes::CParticleFilter::TParticleFilterStats& lastStats() const { return m_stats; }
	/** Number of injections so far. */
	int injections() const { return m_injections; }

	/** Replaces about inject_fraction of the particles (the lowest weights)
	 * with samples around the single-landmark fixes of \a observations'
	 * coded sightings; returns false when it holds no fix. */
	bool injectAroundFixes(const mrpt::obs::CSensoryFrame& observations);

	/** The particles moved by a step's odometry: the prediction that each
	 * of the step's sightings is tested against (predictedInnovation()). */
	struct PredictedCloud
	{
		std::vector<Eigen::Vector3d> poses;	 //!< each particle moved by the odometry's mean
		std::vector<double> weights;  //!< normalised weights
		Eigen::Vector3d mean = Eigen::Vector3d::Zero();	 //!< weighted mean (circular yaw)
		/** The odometry's covariance in the world frame at the mean prior pose,
		 * G C_u G^T (linearised: no draws, so MRPT's generator stays the
		 * update's alone and seeded runs do not depend on this statistic). */
		Eigen::Matrix3d motion_cov = Eigen::Matrix3d::Zero();
	};
	/** The current particles moved by \a motion. */
	PredictedCloud predictCloud(const mrpt::obs::CActionRobotMovement2D& motion) const;

	/** The innovation of sighting \a sg (of a mapped landmark, in \a obs)
	 * against the predicted measurement distribution of \a cloud: the
	 * weighted mean and covariance of the L its poses predict, plus the
	 * motion covariance through the measurement Jacobian and the sighting's
	 * C_L (as measured, without the likelihood's sigma_scale and floors: the
	 * statistic judges the sightings' covariances). Gated beyond gate_chi2. */
	Innovation predictedInnovation(
		const PredictedCloud& cloud, const CObservationCodedLandmarks& obs,
		const CObservationCodedLandmarks::TSighting& sg) const;

   private:
	/** Throws std::runtime_error when a particle's pose or log-weight, or the
	 * estimate \a e (mean, covariance), is not finite; step() calls it. */
	void checkFinite(const PoseEstimate& e) const;
	/** Moves every particle by the regularisation's kernel (roughening). */
	void regularise();

	ParticleFilterOptions m_opts;
	std::shared_ptr<CCodedLandmarksMap> m_map;
	mrpt::slam::CMonteCarloLocalization2D m_pdf;
	mrpt::bayes::CParticleFilter m_pf;
	mrpt::bayes::CParticleFilter::TParticleFilterStats m_stats;
	bool m_converged = false;
	int m_unexplained = 0;
	int m_injections = 0;
	/** The volume [m^2 rad] of the initial uniform cloud while no sighting
	 * has updated it, else 0 (injectAroundFixes()). */
	double m_uniform_volume = 0;
};

}  // namespace codemark::filters
