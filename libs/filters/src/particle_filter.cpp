// The particle filter localizer: MRPT's CMonteCarloLocalization2D and
// CParticleFilter over the coded-landmark map (particle_filter.h).
#include <codemark/landmark/random.h>
#include <codemark/filters/ekf.h>
#include <codemark/filters/particle_filter.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <codemark/pose/closed_form.h>
#include <mrpt/math/wrap2pi.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationBearingRange.h>
#include <mrpt/random/RandomGenerators.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "factories.h"

namespace codemark::filters
{
namespace
{
constexpr double kDeg = M_PI / 180.0;
const char* const kSection = "ParticleFilter";
const char* const kLikelihoodSection = "MetricMap_codedLandmarksMap_00_likelihoodOpts";

/** One draw of N(0, I) in 3-D with MRPT's generator (reproducible with
 * random_seed). */
Eigen::Vector3d drawStandardNormal()
{
	auto& rng = mrpt::random::getRandomGenerator();
	const double a = rng.drawGaussian1D_normalized(), b = rng.drawGaussian1D_normalized();
	return {a, b, rng.drawGaussian1D_normalized()};
}

/** One draw of N(mean, C); C must be positive semi-definite. */
Eigen::Vector3d drawGaussian(const Eigen::Vector3d& mean, const Eigen::Matrix3d& C)
{
	Eigen::LLT<Eigen::Matrix3d> llt(C);
	return mean + llt.matrixL() * drawStandardNormal();
}

/** A robot pose hypothesis from one sighting. */
struct Fix
{
	Eigen::Vector3d mean;  //!< x, y [m], yaw [rad]
	Eigen::Matrix3d cov;
};
}  // namespace

// ------------------------------------------------------------------ options
void ParticleFilterOptions::loadFromConfigFile(
	const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	MRPT_LOAD_CONFIG_VAR(particles_count, int, c, s);
	MRPT_LOAD_CONFIG_VAR(init_margin_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(initial_std_xy_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(initial_std_yaw_deg, double, c, s);
	MRPT_LOAD_CONFIG_VAR(inject_fraction, double, c, s);
	MRPT_LOAD_CONFIG_VAR(inject_ess_threshold, double, c, s);
	MRPT_LOAD_CONFIG_VAR(gate_chi2, double, c, s);
	MRPT_LOAD_CONFIG_VAR(inject_after_unexplained, int, c, s);
	MRPT_LOAD_CONFIG_VAR(inject_min_std_xy_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(inject_min_std_yaw_deg, double, c, s);
	MRPT_LOAD_CONFIG_VAR(converged_std_xy_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(converged_std_yaw_deg, double, c, s);
	MRPT_LOAD_CONFIG_VAR(roughening, double, c, s);
	MRPT_LOAD_CONFIG_VAR(random_seed, int, c, s);
	MRPT_LOAD_CONFIG_VAR(no_odometry_std_xy_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(no_odometry_std_yaw_deg, double, c, s);
	auto require = [&](bool ok, const char* key, const char* what)
	{
		if (!ok) throw std::invalid_argument(std::string("[") + s + "] " + key + ": " + what);
	};
	require(particles_count > 0, "particles_count", "must be > 0");
	require(init_margin_m >= 0, "init_margin_m", "must be >= 0");
	require(roughening >= 0, "roughening", "must be >= 0");
	require(initial_std_xy_m >= 0 && initial_std_yaw_deg >= 0, "initial_std_*", "must be >= 0");
	require(inject_fraction > 0 && inject_fraction <= 1, "inject_fraction", "must be in (0, 1]");
	require(
		inject_ess_threshold >= 0 && inject_ess_threshold < 1, "inject_ess_threshold",
		"must be in [0, 1)");
	require(gate_chi2 > 0, "gate_chi2", "must be > 0");
	require(inject_after_unexplained >= 0, "inject_after_unexplained", "must be >= 0");
	require(
		inject_min_std_xy_m >= 0 && inject_min_std_yaw_deg >= 0, "inject_min_std_*",
		"must be >= 0");
	require(converged_std_xy_m > 0 && converged_std_yaw_deg > 0, "converged_std_*", "must be > 0");
	require(
		no_odometry_std_xy_m > 0 && no_odometry_std_yaw_deg > 0, "no_odometry_std_*",
		"must be > 0");
}

void ParticleFilterOptions::saveToConfigFile(
	mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	c.write(s, "particles_count", particles_count, -1, -1);
	c.write(s, "init_margin_m", init_margin_m, -1, -1);
	c.write(s, "initial_std_xy_m", initial_std_xy_m, -1, -1);
	c.write(s, "initial_std_yaw_deg", initial_std_yaw_deg, -1, -1);
	c.write(s, "inject_fraction", inject_fraction, -1, -1);
	c.write(s, "inject_ess_threshold", inject_ess_threshold, -1, -1);
	c.write(s, "gate_chi2", gate_chi2, -1, -1);
	c.write(s, "inject_after_unexplained", inject_after_unexplained, -1, -1);
	c.write(s, "inject_min_std_xy_m", inject_min_std_xy_m, -1, -1);
	c.write(s, "inject_min_std_yaw_deg", inject_min_std_yaw_deg, -1, -1);
	c.write(s, "converged_std_xy_m", converged_std_xy_m, -1, -1);
	c.write(s, "converged_std_yaw_deg", converged_std_yaw_deg, -1, -1);
	c.write(s, "roughening", roughening, -1, -1);
	c.write(s, "random_seed", random_seed, -1, -1);
	c.write(s, "no_odometry_std_xy_m", no_odometry_std_xy_m, -1, -1);
	c.write(s, "no_odometry_std_yaw_deg", no_odometry_std_yaw_deg, -1, -1);
}

// ---------------------------------------------------------------- localizer
ParticleFilterLocalizer::ParticleFilterLocalizer(
	const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial)
{
	if (map.landmarks.empty())
		throw std::invalid_argument("method 'pf': the landmark map is empty");
	try
	{
		m_opts.loadFromConfigFile(cfg, kSection);
		m_pf.m_options.loadFromConfigFile(cfg, "PF_options");
		m_pdf.options.KLD_params.loadFromConfigFile(cfg, "KLD_options");
		m_map = std::make_shared<CCodedLandmarksMap>(map);
		m_map->likelihoodOptions.loadFromConfigFile(cfg, kLikelihoodSection);
	}
	catch (const std::invalid_argument&)
	{
		throw;
	}
	catch (const std::exception& e)
	{
		throw std::invalid_argument(std::string("method 'pf': bad configuration: ") + e.what());
	}
	if (m_pf.m_options.adaptiveSampleSize &&
		m_pf.m_options.resamplingMethod != mrpt::bayes::CParticleFilter::prMultinomial)
		throw std::invalid_argument(
			"[PF_options] adaptiveSampleSize: 1 (KLD) needs resamplingMethod=0 "
			"(prMultinomial)");
	if (m_pf.m_options.PF_algorithm == mrpt::bayes::CParticleFilter::pfOptimalProposal)
		throw std::invalid_argument(
			"[PF_options] PF_algorithm: 2 (pfOptimalProposal) is not offered by "
			"CMonteCarloLocalization2D; use 0, 1 or 3");
	if (m_opts.random_seed >= 0) reseedMrptRandom(static_cast<uint32_t>(m_opts.random_seed));
	m_pdf.options.metricMap = m_map;

	const auto N = static_cast<size_t>(m_opts.particles_count);
	if (initial)
	{
		// Gaussian around the given pose: its covariance when it has one,
		// else the configured spread.
		Eigen::Matrix3d C = initial->cov;
		if (!(C.determinant() > 0))
			C = Eigen::Vector3d(
					m_opts.initial_std_xy_m * m_opts.initial_std_xy_m,
					m_opts.initial_std_xy_m * m_opts.initial_std_xy_m,
					std::pow(m_opts.initial_std_yaw_deg * kDeg, 2))
					.asDiagonal();
		C += Eigen::Matrix3d::Identity() * 1e-12;
		const Eigen::Vector3d mean(initial->mean.x(), initial->mean.y(), initial->mean.phi());
		m_pdf.resetDeterministic(mrpt::math::TPose2D(mean[0], mean[1], mean[2]), N);
		for (auto& p : m_pdf.m_particles)
		{
			const Eigen::Vector3d v = drawGaussian(mean, C);
			p.d = mrpt::math::TPose2D(v[0], v[1], mrpt::math::wrapToPi(v[2]));
			p.log_w = 0;
		}
		m_converged = initial->initialized;
	}
	else
	{
		mrpt::math::TPoint3D lo, hi;
		m_map->boundingBox(lo, hi);
		const double m = m_opts.init_margin_m;
		m_pdf.resetUniform(
			lo.x - m, hi.x + m, lo.y - m, hi.y + m, -M_PI, M_PI, static_cast<int>(N));
		m_uniform_volume = (hi.x - lo.x + 2 * m) * (hi.y - lo.y + 2 * m) * 2 * M_PI;
	}
}

StepStats ParticleFilterLocalizer::step(
	const mrpt::obs::CActionRobotMovement2D* odometry, const mrpt::obs::CSensoryFrame& observations)
{
	StepStats stats;

	// The action: the step's odometry, or a still robot with a little noise.
	mrpt::obs::CActionCollection actions;
	if (odometry)
		actions.insert(*odometry);
	else
	{
		mrpt::obs::CActionRobotMovement2D still;
		mrpt::obs::CActionRobotMovement2D::TMotionModelOptions mm;
		mm.modelSelection = mrpt::obs::CActionRobotMovement2D::mmGaussian;
		mm.gaussianModel.a1 = mm.gaussianModel.a2 = mm.gaussianModel.a3 = mm.gaussianModel.a4 = 0;
		mm.gaussianModel.minStdXY = m_opts.no_odometry_std_xy_m;
		mm.gaussianModel.minStdPHI = m_opts.no_odometry_std_yaw_deg * kDeg;
		still.computeFromOdometry(mrpt::poses::CPose2D(), mm);
		actions.insert(still);
	}

	// Only the observations the map scores (the images stay out of the loop).
	// Once converged, each coded sighting is tested against the predicted
	// measurement distribution (predictedInnovation()) and one beyond the
	// gate is left out of the update, as the EKFs reject it; before
	// convergence the likelihood's outlier mixture carries wrong sightings.
	mrpt::obs::CSensoryFrame sf, all;
	std::vector<const CObservationCodedLandmarks*> coded;
	const auto motion = actions.getBestMovementEstimation();
	std::optional<PredictedCloud> cloud;  // computed at the frame's first mapped sighting
	for (const auto& o : observations)
	{
		if (!o) continue;
		if (auto c = std::dynamic_pointer_cast<CObservationCodedLandmarks>(o))
		{
			coded.push_back(c.get());
			all.insert(o);
			auto kept = std::make_shared<CObservationCodedLandmarks>(*c);
			kept->sightings.clear();
			for (const auto& sg : c->sightings)
			{
				if (!m_map->find(sg.id))
				{
					++stats.unknown_id;
					continue;
				}
				if (m_converged && motion && motion->poseChange)
				{
					if (!cloud) cloud = predictCloud(*motion);
					Innovation in = predictedInnovation(*cloud, *c, sg);
					in.id = sg.id;
					stats.innovations.push_back(in);
					if (in.gated)
					{
						++stats.rejected;
						continue;
					}
				}
				++stats.used;
				kept->sightings.push_back(sg);
			}
			if (!kept->sightings.empty()) sf.insert(kept);
		}
		else if (auto b = std::dynamic_pointer_cast<mrpt::obs::CObservationBearingRange>(o))
		{
			for (const auto& m : b->sensedData)
				(m_map->find(m.landmarkID) ? stats.used : stats.unknown_id)++;
			sf.insert(o);
			all.insert(o);
		}
	}

	m_pf.executeOn(m_pdf, &actions, !sf.empty() ? &sf : nullptr, &m_stats);

	// Does the best particle explain the frame's coded sightings?
	auto gatedOut = [&](const mrpt::math::TPose2D& pose)
	{
		int known = 0, out = 0;
		const double c = std::cos(pose.phi), s = std::sin(pose.phi);
		for (const auto* o : coded)
		{
			double cx = 0, cy = 0, cc = 1, cs = 0;
			if (!CCodedLandmarksMap::cameraInWorld(
					pose.x, pose.y, c, s, o->cameraPose, cx, cy, cc, cs))
				continue;
			for (const auto& sg : o->sightings)
			{
				const MapLandmark* lm = m_map->find(sg.id);
				if (!lm) continue;
				++known;
				const Eigen::Vector3d Lp = CCodedLandmarksMap::predictL(
					cx, cy, cc, cs, lm->x_m, lm->y_m, std::cos(lm->yaw_rad), std::sin(lm->yaw_rad));
				if (m_map->sightingMahalanobis2(sg.L, sg.C_L, Lp) > m_opts.gate_chi2) ++out;
			}
		}
		return std::make_pair(known, out);
	};
	if (!coded.empty() && !m_pdf.m_particles.empty())
	{
		const auto best = std::max_element(
			m_pdf.m_particles.begin(), m_pdf.m_particles.end(),
			[](const auto& a, const auto& b) { return a.log_w < b.log_w; });
		const auto [known, out] = gatedOut(best->d);
		if (known > 0) m_unexplained = (out == known) ? m_unexplained + 1 : 0;

		const bool collapsed = m_opts.inject_ess_threshold > 0 &&
							   m_stats.ESS_beforeResample < m_opts.inject_ess_threshold;
		// Before the first convergence one unexplained frame suffices: with
		// the uniform mixture, a spread-out cloud far from every fix scores
		// the same floor everywhere and its ESS says nothing.
		const int patience = m_converged ? m_opts.inject_after_unexplained : 1;
		const bool lost = m_opts.inject_after_unexplained > 0 && m_unexplained >= patience;
		if ((collapsed || lost) && injectAroundFixes(all))
		{
			stats.reinitialized = true;
			m_unexplained = 0;
		}
	}

	if (!sf.empty() && m_opts.roughening > 0) regularise();
	if (!sf.empty()) m_uniform_volume = 0;	// a sighting has shaped the cloud
	// Convergence (sticky).
	const PoseEstimate e = estimate();
	checkFinite(e);
	if (!m_converged)
	{
		m_converged =
			converged(e.cov, m_opts.converged_std_xy_m, m_opts.converged_std_yaw_deg * kDeg);
	}
	return stats;
}

ParticleFilterLocalizer::PredictedCloud ParticleFilterLocalizer::predictCloud(
	const mrpt::obs::CActionRobotMovement2D& motion) const
{
	mrpt::math::CMatrixDouble33 Cu;
	mrpt::poses::CPose2D u;
	motion.poseChange->getCovarianceAndMean(Cu, u);
	const Eigen::Vector3d ue(u.x(), u.y(), u.phi());
	const auto& parts = m_pdf.m_particles;
	double max_lw = -std::numeric_limits<double>::infinity();
	for (const auto& p : parts) max_lw = std::max(max_lw, p.log_w);
	PredictedCloud c;
	c.poses.reserve(parts.size());
	c.weights.reserve(parts.size());
	double wsum = 0, sc = 0, ss = 0;
	Eigen::Vector2d xy = Eigen::Vector2d::Zero();
	for (const auto& p : parts)
	{
		const double w = std::exp(p.log_w - max_lw);
		const Eigen::Vector3d x = composeMotion(Eigen::Vector3d(p.d.x, p.d.y, p.d.phi), ue);
		c.poses.push_back(x);
		c.weights.push_back(w);
		xy += w * x.head<2>();
		sc += w * std::cos(x[2]);
		ss += w * std::sin(x[2]);
		wsum += w;
	}
	if (!(wsum > 0))
	{
		// No usable weights: an empty cloud, against which every sighting is gated.
		c.poses.clear();
		c.weights.clear();
		return c;
	}
	for (double& w : c.weights) w /= wsum;
	c.mean = Eigen::Vector3d(xy[0] / wsum, xy[1] / wsum, std::atan2(ss, sc));
	// G = d(x (+) u)/du depends on the prior yaw only: the mean's, before the
	// odometry's turn.
	Eigen::Matrix3d G;
	composeMotion(Eigen::Vector3d(0, 0, mrpt::math::wrapToPi(c.mean[2] - ue[2])), ue, nullptr, &G);
	c.motion_cov = G * Cu.asEigen() * G.transpose();
	return c;
}

Innovation ParticleFilterLocalizer::predictedInnovation(
	const PredictedCloud& cloud, const CObservationCodedLandmarks& obs,
	const CObservationCodedLandmarks::TSighting& sg) const
{
	if (cloud.poses.empty())
	{
		Innovation bad;
		bad.nis = std::numeric_limits<double>::infinity();
		bad.gated = true;
		return bad;
	}
	const MapLandmark& lm = *m_map->find(sg.id);
	const mrpt::poses::CPose2D cam = pose::cameraPlanarPose(obs.cameraPose);
	const mrpt::poses::CPose2D world_T_lm = pose::landmarkPlanarPose(lm.world_T_landmark());
	Eigen::Vector3d mean_d = Eigen::Vector3d::Zero();
	Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
	for (std::size_t i = 0; i < cloud.poses.size(); ++i)
	{
		Eigen::Vector3d d = predictLandmarkMeasurement(cloud.poses[i], cam, world_T_lm) - sg.L;
		d[1] = mrpt::math::wrapToPi(d[1]);
		d[2] = mrpt::math::wrapToPi(d[2]);
		mean_d += cloud.weights[i] * d;
		second += cloud.weights[i] * d * d.transpose();
	}
	const Eigen::Matrix3d spread = second - mean_d * mean_d.transpose();
	Eigen::Matrix3d H;
	predictLandmarkMeasurement(cloud.mean, cam, world_T_lm, &H);
	const Eigen::Matrix3d S = spread + H * cloud.motion_cov * H.transpose() + sg.C_L;
	const Eigen::MatrixXd R = sg.C_L;
	return makeInnovation(-mean_d, S, m_opts.gate_chi2, &R);
}

bool ParticleFilterLocalizer::injectAroundFixes(const mrpt::obs::CSensoryFrame& observations)
{
	std::vector<Fix> fixes;
	const Eigen::Matrix3d floor =
		Eigen::Vector3d(
			std::pow(m_opts.inject_min_std_xy_m, 2), std::pow(m_opts.inject_min_std_xy_m, 2),
			std::pow(m_opts.inject_min_std_yaw_deg * kDeg, 2))
			.asDiagonal();
	for (const auto& o : observations)
	{
		const auto* c = dynamic_cast<const CObservationCodedLandmarks*>(o.get());
		if (!c) continue;
		const mrpt::poses::CPose2D robot_T_camera = pose::cameraPlanarPose(c->cameraPose);
		for (const auto& sg : c->sightings)
		{
			const MapLandmark* lm = m_map->find(sg.id);
			if (!lm) continue;
			Eigen::Matrix3d C;
			const mrpt::poses::CPose2D world_T_robot = pose::robotPoseInWorld(
				sg.pose_in_landmark, sg.C_R, pose::landmarkPlanarPose(lm->world_T_landmark()),
				robot_T_camera, &C);
			C = 0.5 * (C + C.transpose()) + floor;
			if (!C.allFinite() || !(C.determinant() > 0)) continue;
			fixes.push_back(
				{Eigen::Vector3d(world_T_robot.x(), world_T_robot.y(), world_T_robot.phi()), C});
		}
	}
	auto& parts = m_pdf.m_particles;
	if (fixes.empty() || parts.empty()) return false;

	// Replace the lowest-weight particles, cycling over the fixes. Each new
	// sample is weighted by this frame's likelihood at it, with the prior
	// weight of the current best particle: the injected samples compete
	// with the survivors on the same evidence.
	auto frameLogLik = [&](const mrpt::math::TPose2D& p)
	{
		const mrpt::poses::CPose3D x{mrpt::poses::CPose2D(p)};
		double ll = 0;
		for (const auto& o : observations) ll += m_map->computeObservationLikelihood(*o, x);
		return ll;
	};
	const auto best = std::max_element(
		parts.begin(), parts.end(), [](const auto& a, const auto& b) { return a.log_w < b.log_w; });
	const double prior_best = best->log_w - frameLogLik(best->d);
	const size_t n = std::min(
		parts.size(),
		std::max<size_t>(
			1, static_cast<size_t>(std::lround(m_opts.inject_fraction * double(parts.size())))));
	std::vector<size_t> order(parts.size());
	std::iota(order.begin(), order.end(), size_t(0));
	std::nth_element(
		order.begin(), order.begin() + static_cast<std::ptrdiff_t>(n - 1), order.end(),
		[&](size_t a, size_t b) { return parts[a].log_w < parts[b].log_w; });
	for (size_t k = 0; k < n; ++k)
	{
		const Fix& f = fixes[k % fixes.size()];
		const Eigen::Vector3d v = drawGaussian(f.mean, f.cov);
		auto& p = parts[order[k]];
		p.d = mrpt::math::TPose2D(v[0], v[1], mrpt::math::wrapToPi(v[2]));
		p.log_w = prior_best + frameLogLik(p.d);
	}
	if (m_uniform_volume > 0)
	{
		// Into the initial uniform cloud (the first fix), the injected samples
		// and the survivors are draws from two proposals of one posterior:
		// each particle is weighted by its likelihood over the mixture density
		// it was drawn from, (1 - a) / V + a q(x), a the injected share, V the
		// uniform's volume and q the fixes' Gaussian mixture (deterministic-
		// mixture importance sampling). The likelihood alone would nearly
		// square the fix's density (the injected samples come from about the
		// same Gaussian) and report half its variance.
		const double a = double(n) / double(parts.size());
		std::vector<Eigen::LLT<Eigen::Matrix3d>> chol;
		std::vector<double> log_norm;
		for (const Fix& f : fixes)
		{
			chol.emplace_back(f.cov);
			log_norm.push_back(
				-1.5 * std::log(2 * M_PI) - chol.back().matrixLLT().diagonal().array().log().sum() -
				std::log(double(fixes.size())));
		}
		for (auto& p : parts)
		{
			double Vq = 0;
			for (size_t i = 0; i < fixes.size(); ++i)
			{
				Eigen::Vector3d r = Eigen::Vector3d(p.d.x, p.d.y, p.d.phi) - fixes[i].mean;
				r[2] = mrpt::math::wrapToPi(r[2]);
				Vq += m_uniform_volume *
					  std::exp(log_norm[i] - 0.5 * chol[i].matrixL().solve(r).squaredNorm());
			}
			p.log_w = frameLogLik(p.d) - std::log((1 - a) + a * Vq);
		}
	}
	m_pdf.normalizeWeights();
	++m_injections;
	return true;
}

// MRPT's CParticleFilter offers no regularisation: written here.
void ParticleFilterLocalizer::regularise()
{
	auto& parts = m_pdf.m_particles;
	if (parts.size() < 2) return;
	const auto [cov, mean] = m_pdf.getCovarianceAndMean();
	const Eigen::Matrix3d C = 0.5 * (cov.asEigen() + cov.asEigen().transpose());
	constexpr double d = 3;
	const double h =
		m_opts.roughening * std::pow(4.0 / (double(parts.size()) * (d + 2)), 1.0 / (d + 4));
	const Eigen::LLT<Eigen::Matrix3d> llt(h * h * C);
	if (llt.info() != Eigen::Success || !C.allFinite())
		return;	 // a collapsed cloud: nothing to spread
	const Eigen::Matrix3d L = llt.matrixL();
	for (auto& p : parts)
	{
		const Eigen::Vector3d v = Eigen::Vector3d(p.d.x, p.d.y, p.d.phi) + L * drawStandardNormal();
		p.d = mrpt::math::TPose2D(v[0], v[1], mrpt::math::wrapToPi(v[2]));
	}
}

// MRPT's particle filter checks nothing: an overflowing motion (e.g. a huge
// but finite odometry increment) or a likelihood that turns NaN would leave
// a silently wrong estimate. The caller adds the rawlog entry to the message.
void ParticleFilterLocalizer::checkFinite(const PoseEstimate& e) const
{
	const auto& parts = m_pdf.m_particles;
	for (std::size_t i = 0; i < parts.size(); ++i)
	{
		const auto& p = parts[i];
		if (!std::isfinite(p.d.x) || !std::isfinite(p.d.y) || !std::isfinite(p.d.phi) ||
			std::isnan(p.log_w))
			throw std::runtime_error(
				"pf: particle #" + std::to_string(i) + " of " + std::to_string(parts.size()) +
				" became non-finite (pose " + p.d.asString() + ", log-weight " +
				std::to_string(p.log_w) + ")");
	}
	if (!std::isfinite(e.mean.x()) || !std::isfinite(e.mean.y()) || !std::isfinite(e.mean.phi()))
		throw std::runtime_error("pf: the estimate became non-finite: " + e.mean.asString());
	if (!e.cov.allFinite())
		throw std::runtime_error(
			"pf: the estimate's covariance became non-finite (particle spread overflows)");
}

PoseEstimate ParticleFilterLocalizer::estimate() const
{
	PoseEstimate e;
	const auto [cov, mean] = m_pdf.getCovarianceAndMean();
	e.mean = mean;
	e.cov = cov.asEigen();
	e.cov = 0.5 * (e.cov + e.cov.transpose()).eval();
	e.initialized = m_converged;
	return e;
}

// ------------------------------------------------------------------ factory
namespace detail
{
std::unique_ptr<Localizer> makeParticleFilter(
	const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial)
{
	return std::make_unique<ParticleFilterLocalizer>(cfg, map, initial);
}
}  // namespace detail

}  // namespace codemark::filters
