// EKF localization with a known map on CKalmanFilterCapable<3,3,0,3>: the
// "ekf" (L with C_L) and "ekf-pose" (pose fix with C_R) variants share this
// class; ekf_pose.cpp only names the second one's factory.
#include <codemark/filters/ekf.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <codemark/pose/closed_form.h>
#include <mrpt/bayes/CKalmanFilterCapable.h>
#include <mrpt/bayes/CKalmanFilterCapable_impl.h>
#include <mrpt/core/bits_math.h>
#include <mrpt/math/distributions.h>
#include <mrpt/math/wrap2pi.h>
#include <mrpt/poses/CPosePDF.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "factories.h"

namespace codemark::filters
{
using mrpt::math::wrapToPi;
using mrpt::poses::CPose2D;

void EkfOptions::validate() const
{
	auto bad = [](const std::string& key, const std::string& why)
	{ throw std::invalid_argument("[ekf] " + key + ": " + why); };
	if (!(gate_probability > 0 && gate_probability < 1))
		bad("gate_probability", "must be in (0, 1)");
	if (kidnap_rejections < 0) bad("kidnap_rejections", "must be >= 0");
	if (!(measurement_cov_scale > 0)) bad("measurement_cov_scale", "must be > 0");
	if (!(extra_motion_var_xy_m2 >= 0)) bad("extra_motion_var_xy_m2", "must be >= 0");
	if (!(extra_motion_var_yaw_rad2 >= 0)) bad("extra_motion_var_yaw_rad2", "must be >= 0");
	if (!(iterations >= 1 && iterations <= 100)) bad("iterations", "must be in [1, 100]");
	if (!(pd_tolerance >= 0)) bad("pd_tolerance", "must be >= 0");
	if (!(min_eigenvalue > 0)) bad("min_eigenvalue", "must be > 0");
	if (!(converged_std_xy_m > 0)) bad("converged_std_xy_m", "must be > 0");
	if (!(converged_std_yaw_deg > 0)) bad("converged_std_yaw_deg", "must be > 0");
}

void EkfOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	MRPT_LOAD_CONFIG_VAR(gate_probability, double, c, s);
	MRPT_LOAD_CONFIG_VAR(kidnap_rejections, int, c, s);
	MRPT_LOAD_CONFIG_VAR(measurement_cov_scale, double, c, s);
	MRPT_LOAD_CONFIG_VAR(extra_motion_var_xy_m2, double, c, s);
	MRPT_LOAD_CONFIG_VAR(extra_motion_var_yaw_rad2, double, c, s);
	MRPT_LOAD_CONFIG_VAR(iterations, int, c, s);
	MRPT_LOAD_CONFIG_VAR(pd_tolerance, double, c, s);
	MRPT_LOAD_CONFIG_VAR(min_eigenvalue, double, c, s);
	MRPT_LOAD_CONFIG_VAR(converged_std_xy_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(converged_std_yaw_deg, double, c, s);
	validate();
}

void EkfOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	c.write(s, "gate_probability", gate_probability, -1, -1);
	c.write(s, "kidnap_rejections", kidnap_rejections, -1, -1);
	c.write(s, "measurement_cov_scale", measurement_cov_scale, -1, -1);
	c.write(s, "extra_motion_var_xy_m2", extra_motion_var_xy_m2, -1, -1);
	c.write(s, "extra_motion_var_yaw_rad2", extra_motion_var_yaw_rad2, -1, -1);
	c.write(s, "iterations", iterations, -1, -1);
	c.write(s, "pd_tolerance", pd_tolerance, -1, -1);
	c.write(s, "min_eigenvalue", min_eigenvalue, -1, -1);
	c.write(s, "converged_std_xy_m", converged_std_xy_m, -1, -1);
	c.write(s, "converged_std_yaw_deg", converged_std_yaw_deg, -1, -1);
}

Eigen::Vector3d predictLandmarkMeasurement(
	const Eigen::Vector3d& r, const CPose2D& cam, const CPose2D& lm, Eigen::Matrix3d* H)
{
	// Camera in the world: c = r (+) cam.
	const double cr = std::cos(r[2]), sr = std::sin(r[2]);
	const double cx = r[0] + cam.x() * cr - cam.y() * sr;
	const double cy = r[1] + cam.x() * sr + cam.y() * cr;
	// Camera in the landmark frame: p = lm (-) c.
	const double cl = std::cos(lm.phi()), sl = std::sin(lm.phi());
	const double dx = cx - lm.x(), dy = cy - lm.y();
	const double px = cl * dx + sl * dy, py = -sl * dx + cl * dy;
	const double pth = r[2] + cam.phi() - lm.phi();
	// Spec section 4 inverted: x = l2 cos(phi1 + phi2), y = l2 sin(phi1 + phi2),
	// theta = pi + phi2.
	const double l2 = std::hypot(px, py);
	const double phi2 = wrapToPi(pth - M_PI);
	const double phi1 = wrapToPi(std::atan2(py, px) - phi2);
	if (H)
	{
		// d(cx, cy)/d(x, y, yaw), then rotated into L; d(pth)/d(yaw) = 1.
		Eigen::Matrix<double, 2, 3> dc;
		dc << 1, 0, -cam.x() * sr - cam.y() * cr, 0, 1, cam.x() * cr - cam.y() * sr;
		Eigen::Matrix2d Rl;
		Rl << cl, sl, -sl, cl;
		const Eigen::Matrix<double, 2, 3> dp = Rl * dc;
		const double l2sq = l2 * l2;
		H->row(0) = (px * dp.row(0) + py * dp.row(1)) / l2;
		const Eigen::RowVector3d dbeta = (px * dp.row(1) - py * dp.row(0)) / l2sq;
		const Eigen::RowVector3d dphi2(0, 0, 1);
		H->row(2) = dphi2;
		H->row(1) = dbeta - dphi2;
	}
	return {l2, phi1, phi2};
}

Eigen::Vector3d composeMotion(
	const Eigen::Vector3d& x, const Eigen::Vector3d& u, Eigen::Matrix3d* F, Eigen::Matrix3d* G)
{
	const double c = std::cos(x[2]), s = std::sin(x[2]);
	if (F) *F << 1, 0, -u[0] * s - u[1] * c, 0, 1, u[0] * c - u[1] * s, 0, 0, 1;
	if (G) *G << c, -s, 0, s, c, 0, 0, 0, 1;
	return {x[0] + u[0] * c - u[1] * s, x[1] + u[0] * s + u[1] * c, wrapToPi(x[2] + u[2])};
}

void symmetriseAndCheckCovariance(
	Eigen::Matrix3d& P, double tolerance, double min_eigenvalue, const std::string& what)
{
	if (!P.allFinite())
	{
		std::ostringstream os;
		os << what << ": covariance has non-finite entries:\n" << P;
		throw std::runtime_error(os.str());
	}
	P = (0.5 * (P + P.transpose())).eval();	 // eval: P.transpose() aliases P
	Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(P);
	const Eigen::Vector3d& ev = es.eigenvalues();  // ascending
	if (ev[0] < -tolerance * std::max(1.0, ev[2]))
	{
		std::ostringstream os;
		os << what << ": covariance is not positive definite (eigenvalues " << ev.transpose()
		   << ", tolerance " << tolerance << "):\n"
		   << P;
		throw std::runtime_error(os.str());
	}
	if (ev[0] < min_eigenvalue)
	{
		const Eigen::Vector3d fixed = ev.cwiseMax(min_eigenvalue);
		P = es.eigenvectors() * fixed.asDiagonal() * es.eigenvectors().transpose();
		P = (0.5 * (P + P.transpose())).eval();
	}
}

namespace
{
// One sighting ready to fuse: the measurement and what h(x) needs.
struct Sighting
{
	const CObservationCodedLandmarks::TSighting* s = nullptr;
	const MapLandmark* landmark = nullptr;
	CPose2D robot_T_camera;	 // planar camera mounting
	CPose2D world_T_landmark;  // planar landmark pose
};

class EkfLocalizer final : public Localizer, private mrpt::bayes::CKalmanFilterCapable<3, 3, 0, 3>
{
   public:
	EkfLocalizer(
		EkfMeasurement kind, const EkfOptions& o, const LandmarkMap& map,
		const std::optional<PoseEstimate>& initial)
		: kind_(kind), opt_(o), map_(map), gate_(mrpt::math::chi2inv(o.gate_probability, 3))
	{
		opt_.validate();
		if (map_.landmarks.empty())
			throw std::invalid_argument(
				std::string("method '") + (kind == EkfMeasurement::Landmark ? "ekf" : "ekf-pose") +
				"': the landmark map is empty");
		setMinLoggingLevel(mrpt::system::LVL_ERROR);
		KF_options.method = mrpt::bayes::kfEKFNaive;
		KF_options.use_analytic_observation_jacobian = true;  // required with FEAT = 0
		KF_options.use_analytic_transition_jacobian = true;
		KF_options.enable_profiler = false;
		m_xkk.resize(3);
		m_xkk.setZero();
		m_pkk.setSize(3, 3);
		m_pkk.setZero();
		if (initial && initial->initialized)
		{
			Eigen::Matrix3d P = initial->cov;
			symmetriseAndCheckCovariance(P, opt_.pd_tolerance, opt_.min_eigenvalue, "initial pose");
			setState({initial->mean.x(), initial->mean.y(), initial->mean.phi()}, P);
			initialized_ = converged_ = true;
		}
	}

	std::string method() const override
	{
		return kind_ == EkfMeasurement::Landmark ? "ekf" : "ekf-pose";
	}

	PoseEstimate estimate() const override
	{
		PoseEstimate e;
		e.initialized = converged_;
		e.mean = CPose2D(m_xkk[0], m_xkk[1], m_xkk[2]);
		e.cov = m_pkk.asEigen().block<3, 3>(0, 0);
		return e;
	}

	StepStats step(
		const mrpt::obs::CActionRobotMovement2D* odometry,
		const mrpt::obs::CSensoryFrame& observations) override
	{
		StepStats st = filterStep(odometry, observations);
		// The first fix (sticky, as the particle filter's): the estimate is
		// reported once it is tight, not at the first sighting, whose single
		// pose fix can be tens of centimetres wide at range.
		if (initialized_ && !converged_)
			converged_ = converged(
				m_pkk.asEigen().block<3, 3>(0, 0), opt_.converged_std_xy_m,
				mrpt::DEG2RAD(opt_.converged_std_yaw_deg));
		return st;
	}

   private:
	StepStats filterStep(
		const mrpt::obs::CActionRobotMovement2D* odometry,
		const mrpt::obs::CSensoryFrame& observations)
	{
		StepStats st;
		predict_ = false;
		if (odometry && odometry->poseChange)
		{
			mrpt::math::CMatrixDouble33 C;
			CPose2D mean;
			odometry->poseChange->getCovarianceAndMean(C, mean);
			u_ = {mean.x(), mean.y(), mean.phi()};
			C_u_ = C.asEigen();
			if (!u_.allFinite() || !C_u_.allFinite())
				throw std::runtime_error(
					"ekf: odometry increment with non-finite mean or covariance");
			predict_ = initialized_;
		}

		// The frame's sightings of mapped landmarks, in order.
		std::vector<Sighting> sightings;
		for (const auto& obs : observations)
		{
			const auto* lm_obs = dynamic_cast<const CObservationCodedLandmarks*>(obs.get());
			if (!lm_obs) continue;	// BearingRange twins would count the same sightings twice
			const CPose2D cam = pose::cameraPlanarPose(lm_obs->cameraPose);
			for (const auto& s : lm_obs->sightings)
			{
				const MapLandmark* m = map_.find(s.id);
				if (!m)
				{
					++st.unknown_id;
					continue;
				}
				sightings.push_back({&s, m, cam, pose::landmarkPlanarPose(m->world_T_landmark())});
			}
		}

		if (!initialized_)
		{
			if (sightings.empty()) return st;
			// Initialise from the frame's most precise fix (smallest
			// position covariance), then fuse the others.
			auto best = sightings.begin();
			double best_trace = std::numeric_limits<double>::infinity();
			for (auto it = sightings.begin(); it != sightings.end(); ++it)
			{
				Eigen::Matrix3d C;
				poseFix(*it, C);
				const double tr = C.block<2, 2>(0, 0).trace();
				if (tr < best_trace) best_trace = tr, best = it;
			}
			initialiseFrom(*best);
			st.reinitialized = true;
			++st.used;
			sightings.erase(best);
		}

		if (sightings.empty())
		{
			if (predict_) iterate(nullptr);
			return st;
		}
		for (const auto& s : sightings)
		{
			const bool accepted = iterate(&s);
			predict_ = false;  // one prediction per step (FEAT = 0: one landmark per iteration)
			if (tested_)
			{
				innovation_.id = s.s->id;
				st.innovations.push_back(innovation_);
			}
			if (accepted)
			{
				++st.used;
				consecutive_rejections_ = 0;
				continue;
			}
			++st.rejected;
			++consecutive_rejections_;
			if (opt_.kidnap_rejections > 0 && consecutive_rejections_ >= opt_.kidnap_rejections)
			{
				// Kidnapped: restart from this landmark's fix.
				initialiseFrom(s);
				consecutive_rejections_ = 0;
				st.reinitialized = true;
			}
		}
		return st;
	}

	void setState(const Eigen::Vector3d& x, const Eigen::Matrix3d& P)
	{
		for (int i = 0; i < 3; ++i) m_xkk[i] = x[i];
		m_xkk[2] = wrapToPi(m_xkk[2]);
		m_pkk.asEigen() = P;
	}

	// The robot's world pose from one sighting alone, with its covariance.
	Eigen::Vector3d poseFix(const Sighting& s, Eigen::Matrix3d& C) const
	{
		const CPose2D p = pose::robotPoseInWorld(
			s.s->pose_in_landmark, s.s->C_R, s.world_T_landmark, s.robot_T_camera, &C);
		C *= opt_.measurement_cov_scale;
		return {p.x(), p.y(), p.phi()};
	}

	void initialiseFrom(const Sighting& s)
	{
		Eigen::Matrix3d C;
		const Eigen::Vector3d x = poseFix(s, C);
		symmetriseAndCheckCovariance(C, opt_.pd_tolerance, opt_.min_eigenvalue, "ekf: pose fix");
		setState(x, C);
		initialized_ = true;
	}

	// One Kalman iteration: the pending prediction (if any) and the update
	// with \a s (none: prediction only). Returns whether \a s passed the gate.
	bool iterate(const Sighting* s)
	{
		current_ = s;
		accepted_ = false;
		tested_ = false;
		if (s)
		{
			if (kind_ == EkfMeasurement::Landmark)
			{
				z_ = s->s->L;
				R_ = s->s->C_L * opt_.measurement_cov_scale;
			}
			else
				z_ = poseFix(*s, R_);
		}
		runOneKalmanIteration();
		if (accepted_ && kind_ == EkfMeasurement::Landmark && opt_.iterations > 1) refine();
		return accepted_;
	}

	// The iterated EKF update (Bell and Cathey 1993): Gauss-Newton steps that
	// re-linearise h at the updated estimate, from MRPT's (first) update on.
	// phi1 is good to ~1e-4 rad while an update moves the robot by
	// centimetres at 2-4 m from the landmark: the second-order terms of h
	// over that step (~(dx / l2)^2 rad) exceed phi1's sigma, so one
	// linearisation leaves the estimate off the bearing constraint by more
	// than its covariance says (NEES far above 3 with small per-axis errors).
	void refine()
	{
		const Eigen::Matrix3d P0 = P0_;
		Eigen::Vector3d xi(m_xkk[0], m_xkk[1], m_xkk[2]);
		Eigen::Matrix3d H, K;
		// The MAP cost the iterations minimise; a step that does not lower it
		// ends them (Gauss-Newton without a line search can overshoot when
		// the prior is wide).
		const Eigen::LDLT<Eigen::Matrix3d> P0_inv(P0), R_inv(R_);
		auto cost = [&](const Eigen::Vector3d& x)
		{
			Eigen::Vector3d dx = x - x0_,
							nu = z_ - predictLandmarkMeasurement(
										  x, current_->robot_T_camera, current_->world_T_landmark);
			dx[2] = wrapToPi(dx[2]);
			nu[1] = wrapToPi(nu[1]);
			nu[2] = wrapToPi(nu[2]);
			return dx.dot(P0_inv.solve(dx)) + nu.dot(R_inv.solve(nu));
		};
		double ci = cost(xi);
		for (int it = 1; it < opt_.iterations; ++it)
		{
			const Eigen::Vector3d h = predictLandmarkMeasurement(
				xi, current_->robot_T_camera, current_->world_T_landmark, &H);
			Eigen::Vector3d nu = z_ - h, dx = x0_ - xi;
			nu[1] = wrapToPi(nu[1]);
			nu[2] = wrapToPi(nu[2]);
			dx[2] = wrapToPi(dx[2]);
			const Eigen::Matrix3d S = H * P0 * H.transpose() + R_;
			K = P0 * H.transpose() * S.inverse();
			Eigen::Vector3d xn = x0_ + K * (nu - H * dx);
			xn[2] = wrapToPi(xn[2]);
			const double cn = cost(xn);
			if (!(cn < ci)) break;
			Eigen::Vector3d step = xn - xi;
			step[2] = wrapToPi(step[2]);
			xi = xn;
			ci = cn;
			if (step.head<2>().norm() < 1e-7 && std::abs(step[2]) < 1e-8) break;
		}
		predictLandmarkMeasurement(xi, current_->robot_T_camera, current_->world_T_landmark, &H);
		const Eigen::Matrix3d S = H * P0 * H.transpose() + R_;
		K = P0 * H.transpose() * S.inverse();
		// Joseph form: symmetric and positive semi-definite by construction.
		const Eigen::Matrix3d I_KH = Eigen::Matrix3d::Identity() - K * H;
		Eigen::Matrix3d P = I_KH * P0 * I_KH.transpose() + K * R_ * K.transpose();
		symmetriseAndCheckCovariance(
			P, opt_.pd_tolerance, opt_.min_eigenvalue, "ekf (iterated update)");
		setState(xi, P);
	}

	// --- CKalmanFilterCapable -------------------------------------------
	void OnGetAction(KFArray_ACT& out_u) const override
	{
		for (int i = 0; i < 3; ++i) out_u[i] = u_[i];
	}

	void OnTransitionModel(const KFArray_ACT& u, KFArray_VEH& x, bool& skip) const override
	{
		skip = !predict_;
		if (skip) return;
		const Eigen::Vector3d xn = composeMotion({x[0], x[1], x[2]}, {u[0], u[1], u[2]});
		for (int i = 0; i < 3; ++i) x[i] = xn[i];
	}

	void OnTransitionJacobian(KFMatrix_VxV& F) const override
	{
		Eigen::Matrix3d Fe;
		composeMotion({m_xkk[0], m_xkk[1], m_xkk[2]}, u_, &Fe, nullptr);
		F.asEigen() = Fe;
	}

	void OnTransitionNoise(KFMatrix_VxV& Q) const override
	{
		// The increment's covariance is in the robot frame at the prior pose:
		// Q = J_u C_u J_u^T with J_u = d(x (+) u)/du.
		Eigen::Matrix3d G;
		composeMotion({m_xkk[0], m_xkk[1], m_xkk[2]}, u_, nullptr, &G);
		Eigen::Matrix3d Qe = G * C_u_ * G.transpose();
		Qe(0, 0) += opt_.extra_motion_var_xy_m2;
		Qe(1, 1) += opt_.extra_motion_var_xy_m2;
		Qe(2, 2) += opt_.extra_motion_var_yaw_rad2;
		Q.asEigen() = Qe;
	}

	void OnGetObservationNoise(KFMatrix_OxO& out_R) const override
	{
		if (current_)
			out_R.asEigen() = R_;
		else
			out_R.setIdentity();
	}

	void OnObservationModel(const std::vector<size_t>&, vector_KFArray_OBS& out) const override
	{
		// FEAT = 0: always one prediction, whatever the (empty) index list.
		out.resize(1);
		Eigen::Vector3d h = Eigen::Vector3d::Zero();
		const Eigen::Vector3d x(m_xkk[0], m_xkk[1], m_xkk[2]);
		if (current_)
			h = kind_ == EkfMeasurement::Landmark
					? predictLandmarkMeasurement(
						  x, current_->robot_T_camera, current_->world_T_landmark)
					: x;
		for (int i = 0; i < 3; ++i) out[0][i] = h[i];
	}

	void OnObservationJacobians(size_t, KFMatrix_OxV& Hx, KFMatrix_OxF&) const override
	{
		Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
		if (current_ && kind_ == EkfMeasurement::Landmark)
			predictLandmarkMeasurement(
				{m_xkk[0], m_xkk[1], m_xkk[2]}, current_->robot_T_camera,
				current_->world_T_landmark, &H);
		Hx.asEigen() = H;
	}

	void OnSubstractObservationVectors(KFArray_OBS& A, const KFArray_OBS& B) const override
	{
		A -= B;
		// Landmark: phi1 and phi2 are angles; pose fix: only the yaw.
		if (kind_ == EkfMeasurement::Landmark) A[1] = wrapToPi(A[1]);
		A[2] = wrapToPi(A[2]);
	}

	void OnGetObservationsAndDataAssociation(
		vector_KFArray_OBS& out_z, std::vector<int>& out_da, const vector_KFArray_OBS& pred,
		const KFMatrix& S, const std::vector<size_t>&, const KFMatrix_OxO&) override
	{
		out_z.clear();
		out_da.clear();
		if (!current_) return;
		// Chi-square gate, 3 DoF, on the angle-wrapped innovation.
		KFArray_OBS nu;
		for (int i = 0; i < 3; ++i) nu[i] = z_[i];
		OnSubstractObservationVectors(nu, pred.at(0));
		const Eigen::Matrix3d Se = S.asEigen().block<3, 3>(0, 0);
		const Eigen::MatrixXd R = R_;
		innovation_ = makeInnovation(Eigen::Vector3d(nu[0], nu[1], nu[2]), Se, gate_, &R);
		tested_ = true;
		if (innovation_.gated) return;
		KFArray_OBS z;
		for (int i = 0; i < 3; ++i) z[i] = z_[i];
		out_z.push_back(z);
		accepted_ = true;
		// The prior of this update, for refine().
		x0_ = Eigen::Vector3d(m_xkk[0], m_xkk[1], m_xkk[2]);
		P0_ = m_pkk.asEigen().block<3, 3>(0, 0);
	}

	void OnNormalizeStateVector() override
	{
		m_xkk[2] = wrapToPi(m_xkk[2]);
		Eigen::Matrix3d P = m_pkk.asEigen();
		symmetriseAndCheckCovariance(P, opt_.pd_tolerance, opt_.min_eigenvalue, "ekf");
		m_pkk.asEigen() = P;
	}

	EkfMeasurement kind_;
	EkfOptions opt_;
	LandmarkMap map_;
	double gate_;  // chi2inv(gate_probability, 3)
	bool initialized_ = false;
	bool converged_ = false;  // the first fix (estimate().initialized)
	int consecutive_rejections_ = 0;

	// The iteration in progress.
	bool predict_ = false;
	Eigen::Vector3d u_ = Eigen::Vector3d::Zero();
	Eigen::Matrix3d C_u_ = Eigen::Matrix3d::Zero();
	const Sighting* current_ = nullptr;
	Eigen::Vector3d z_ = Eigen::Vector3d::Zero();
	Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
	bool accepted_ = false;
	bool tested_ = false;  // the gate saw the current sighting
	Innovation innovation_;	 // its NIS
	Eigen::Vector3d x0_ = Eigen::Vector3d::Zero();	// prior of the accepted update
	Eigen::Matrix3d P0_ = Eigen::Matrix3d::Zero();
};
}  // namespace

std::unique_ptr<Localizer> makeEkfLocalizer(
	EkfMeasurement measurement, const EkfOptions& options, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial)
{
	return std::make_unique<EkfLocalizer>(measurement, options, map, initial);
}

namespace detail
{
std::unique_ptr<Localizer> makeEkf(
	const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial)
{
	EkfOptions o;
	o.loadFromConfigFile(cfg, "ekf");
	return makeEkfLocalizer(EkfMeasurement::Landmark, o, map, initial);
}
}  // namespace detail

}  // namespace codemark::filters
