// EKF-SLAM on CKalmanFilterCapable<3,3,3,3> (ekf_slam.h), after
// mrpt::slam::CRangeBearingKFSLAM2D.
#include <codemark/filters/ekf_slam.h>
#include <codemark/filters/mrpt_landmarks.h>
#include <codemark/landmark/truth.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <codemark/pose/closed_form.h>
#include <mrpt/bayes/CKalmanFilterCapable.h>
#include <mrpt/bayes/CKalmanFilterCapable_impl.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/math/distributions.h>
#include <mrpt/obs/CObservationBearingRange.h>
#include <mrpt/poses/CPosePDFGaussian.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "factories.h"

namespace codemark::filters
{
namespace
{
constexpr double kPi = M_PI;
constexpr double kDeg = M_PI / 180.0;

// Chi-square threshold, or +inf when gating is off.
double gateThreshold(double probability, unsigned dof)
{
	if (probability >= 1.0) return std::numeric_limits<double>::infinity();
	return mrpt::math::chi2inv(probability, dof);
}
}  // namespace

// ---------------------------------------------------------------------------
// Options
// ---------------------------------------------------------------------------
void EkfSlamOptions::validate() const
{
	auto bad = [](const char* key, const std::string& why)
	{ throw std::invalid_argument(std::string("ekf-slam: [ekf_slam] ") + key + " " + why); };
	if (!(gate_probability > 0.0 && gate_probability <= 1.0))
		bad("gate_probability", "must be in (0, 1]");
	if (!(std_sensor_range > 0.0)) bad("std_sensor_range", "must be > 0");
	if (!(std_sensor_yaw_deg > 0.0)) bad("std_sensor_yaw_deg", "must be > 0");
	if (!(measurement_cov_scale > 0.0)) bad("measurement_cov_scale", "must be > 0");
	if (!(point_yaw_sigma_deg > 0.0)) bad("point_yaw_sigma_deg", "must be > 0");
	if (!(extra_motion_var_xy_m2 >= 0.0)) bad("extra_motion_var_xy_m2", "must be >= 0");
	if (!(extra_motion_var_yaw_rad2 >= 0.0)) bad("extra_motion_var_yaw_rad2", "must be >= 0");
	if (!(std_no_odo_xy >= 0.0)) bad("std_no_odo_xy", "must be >= 0");
	if (!(std_no_odo_yaw_deg >= 0.0)) bad("std_no_odo_yaw_deg", "must be >= 0");
	if (!(prior_sigma_xy > 0.0)) bad("prior_sigma_xy", "must be > 0");
	if (!(prior_sigma_yaw_deg > 0.0)) bad("prior_sigma_yaw_deg", "must be > 0");
	if (!(pd_tolerance >= 0.0)) bad("pd_tolerance", "must be >= 0");
}

void EkfSlamOptions::loadFromConfigFile(
	const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	const std::string in = c.read_string(s, "input", "", false);
	if (!in.empty())
	{
		if (in == "auto") input = SlamInput::Auto;
		else if (in == "coded")
			input = SlamInput::Coded;
		else if (in == "bearing_range")
			input = SlamInput::BearingRange;
		else if (in == "both")
			input = SlamInput::Both;
		else
			throw std::invalid_argument(
				"ekf-slam: [" + s + "] input = '" + in +
				"' (expected auto, coded, bearing_range or both)");
	}
	MRPT_LOAD_CONFIG_VAR(gate_probability, double, c, s);
	MRPT_LOAD_CONFIG_VAR(std_sensor_range, double, c, s);
	MRPT_LOAD_CONFIG_VAR(std_sensor_yaw_deg, double, c, s);
	MRPT_LOAD_CONFIG_VAR(use_reading_covariance, bool, c, s);
	MRPT_LOAD_CONFIG_VAR(measurement_cov_scale, double, c, s);
	MRPT_LOAD_CONFIG_VAR(point_yaw_sigma_deg, double, c, s);
	MRPT_LOAD_CONFIG_VAR(extra_motion_var_xy_m2, double, c, s);
	MRPT_LOAD_CONFIG_VAR(extra_motion_var_yaw_rad2, double, c, s);
	MRPT_LOAD_CONFIG_VAR(std_no_odo_xy, double, c, s);
	MRPT_LOAD_CONFIG_VAR(std_no_odo_yaw_deg, double, c, s);
	prior_map_file = c.read_string(s, "prior_map_file", prior_map_file, false);
	MRPT_LOAD_CONFIG_VAR(prior_sigma_xy, double, c, s);
	MRPT_LOAD_CONFIG_VAR(prior_sigma_yaw_deg, double, c, s);
	MRPT_LOAD_CONFIG_VAR(pd_tolerance, double, c, s);
	validate();
}

void EkfSlamOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	static const char* kInput[] = {"auto", "coded", "bearing_range", "both"};
	c.write(s, "input", std::string(kInput[static_cast<int>(input)]), -1, -1);
	c.write(s, "gate_probability", gate_probability, -1, -1);
	c.write(s, "std_sensor_range", std_sensor_range, -1, -1);
	c.write(s, "std_sensor_yaw_deg", std_sensor_yaw_deg, -1, -1);
	c.write(s, "use_reading_covariance", use_reading_covariance, -1, -1);
	c.write(s, "measurement_cov_scale", measurement_cov_scale, -1, -1);
	c.write(s, "point_yaw_sigma_deg", point_yaw_sigma_deg, -1, -1);
	c.write(s, "extra_motion_var_xy_m2", extra_motion_var_xy_m2, -1, -1);
	c.write(s, "extra_motion_var_yaw_rad2", extra_motion_var_yaw_rad2, -1, -1);
	c.write(s, "std_no_odo_xy", std_no_odo_xy, -1, -1);
	c.write(s, "std_no_odo_yaw_deg", std_no_odo_yaw_deg, -1, -1);
	c.write(s, "prior_map_file", prior_map_file, -1, -1);
	c.write(s, "prior_sigma_xy", prior_sigma_xy, -1, -1);
	c.write(s, "prior_sigma_yaw_deg", prior_sigma_yaw_deg, -1, -1);
	c.write(s, "pd_tolerance", pd_tolerance, -1, -1);
}

// ---------------------------------------------------------------------------
// Models
// ---------------------------------------------------------------------------
Eigen::Vector3d slamObservation(
	const Eigen::Vector3d& robot, const mrpt::poses::CPose2D& sensor_on_robot,
	const Eigen::Vector3d& landmark, Eigen::Matrix3d* Hx, Eigen::Matrix3d* Hy)
{
	const double c = std::cos(robot[2]), s = std::sin(robot[2]);
	// The sensor's offset from the robot, rotated into the world.
	const double ox = c * sensor_on_robot.x() - s * sensor_on_robot.y();
	const double oy = s * sensor_on_robot.x() + c * sensor_on_robot.y();
	const double sx = robot[0] + ox, sy = robot[1] + oy, syaw = robot[2] + sensor_on_robot.phi();
	const double dx = landmark[0] - sx, dy = landmark[1] - sy;
	const double r2 = dx * dx + dy * dy, r = std::sqrt(r2);
	const Eigen::Vector3d h(
		r, wrapToPi(std::atan2(dy, dx) - syaw), wrapToPi(syaw - landmark[2] - kPi));
	if (Hx)
	{
		// d(sx, sy)/d(yaw) = (-oy, ox).
		*Hx << -dx / r, -dy / r, (dx * oy - dy * ox) / r,  //
			dy / r2, -dx / r2, -(dy * oy + dx * ox) / r2 - 1.0,  //
			0.0, 0.0, 1.0;
	}
	if (Hy)
	{
		*Hy << dx / r, dy / r, 0.0,  //
			-dy / r2, dx / r2, 0.0,  //
			0.0, 0.0, -1.0;
	}
	return h;
}

Eigen::Vector3d slamInverseObservation(
	const Eigen::Vector3d& robot, const mrpt::poses::CPose2D& sensor_on_robot,
	const Eigen::Vector3d& z, Eigen::Matrix3d* Jx, Eigen::Matrix3d* Jz)
{
	const double c = std::cos(robot[2]), s = std::sin(robot[2]);
	const double ox = c * sensor_on_robot.x() - s * sensor_on_robot.y();
	const double oy = s * sensor_on_robot.x() + c * sensor_on_robot.y();
	const double syaw = robot[2] + sensor_on_robot.phi();
	const double beta = syaw + z[1];
	const double cb = std::cos(beta), sb = std::sin(beta);
	const Eigen::Vector3d l(
		robot[0] + ox + z[0] * cb, robot[1] + oy + z[0] * sb, wrapToPi(syaw - z[2] - kPi));
	if (Jx)
	{
		*Jx << 1.0, 0.0, -oy - z[0] * sb,  //
			0.0, 1.0, ox + z[0] * cb,  //
			0.0, 0.0, 1.0;
	}
	if (Jz)
	{
		*Jz << cb, -z[0] * sb, 0.0,  //
			sb, z[0] * cb, 0.0,  //
			0.0, 0.0, -1.0;
	}
	return l;
}

// ---------------------------------------------------------------------------
// The Kalman filter
// ---------------------------------------------------------------------------
namespace
{
/** One measurement of one landmark, in the robot frame's terms. */
struct Sighting
{
	int id = -1;
	Eigen::Vector3d z = Eigen::Vector3d::Zero();  //!< [l2 phi1 phi2] or [range yaw 0]
	Eigen::Matrix3d C = Eigen::Matrix3d::Identity();  //!< covariance of z (dummy 1 on the third for points)
	Eigen::Matrix3d W = Eigen::Matrix3d::Identity();  //!< whitening: W C W^T = I
	mrpt::poses::CPose2D sensor;  //!< sensor's planar pose on the robot
	bool point = false;  //!< range-bearing: the third component is unused
	double height_m = std::numeric_limits<double>::quiet_NaN();  //!< landmark z estimate
	// Coded only, for the pose fix that anchors a prior map.
	Eigen::Vector3d pose_in_landmark = Eigen::Vector3d::Zero();
	Eigen::Matrix3d C_R = Eigen::Matrix3d::Zero();
};

struct LandmarkInfo
{
	int id = -1;
	double z_sum = 0;  //!< sum of height estimates [m]
	int z_count = 0;
	bool z_prior = false;  //!< z_sum holds the prior's z
};

class SlamKF : public mrpt::bayes::CKalmanFilterCapable<3, 3, 3, 3>
{
   public:
	EkfSlamOptions opts;
	std::map<int, std::size_t> id_to_idx;
	std::vector<LandmarkInfo> info;

	// Per Kalman iteration.
	std::vector<Sighting> pass;  //!< this iteration's sightings, one per landmark at most
	std::vector<int> sighting_of;  //!< landmark index -> index in pass, or -1
	bool skip_prediction = false;
	mrpt::poses::CPose2D odo_mean;  //!< odometry increment in the robot frame
	Eigen::Matrix3d odo_cov = Eigen::Matrix3d::Zero();
	std::vector<std::size_t> new_queue;  //!< pass indices of sightings to add, in order
	mutable std::size_t new_cursor = 0;
	int used = 0, rejected = 0;
	std::size_t iterations = 0;

	SlamKF()
	{
		m_xkk.assign(3, 0.0);
		m_pkk.setSize(3, 3);
		m_pkk.setZero();
		KF_options.method = mrpt::bayes::kfEKFAlaDavison;
	}

	using mrpt::bayes::CKalmanFilterCapable<3, 3, 3, 3>::m_xkk;
	using mrpt::bayes::CKalmanFilterCapable<3, 3, 3, 3>::m_pkk;

	void iterate()
	{
		sighting_of.assign(getNumberOfLandmarksInTheMap(), -1);
		for (std::size_t i = 0; i < pass.size(); ++i)
			if (const auto it = id_to_idx.find(pass[i].id); it != id_to_idx.end())
				sighting_of[it->second] = static_cast<int>(i);
		new_queue.clear();
		new_cursor = 0;
		runOneKalmanIteration();
		++iterations;
	}

	Eigen::Vector3d robot() const { return Eigen::Vector3d(m_xkk[0], m_xkk[1], m_xkk[2]); }
	Eigen::Vector3d landmark(std::size_t idx) const
	{
		const std::size_t o = 3 + 3 * idx;
		return Eigen::Vector3d(m_xkk[o], m_xkk[o + 1], m_xkk[o + 2]);
	}

	// h and its Jacobians for one sighting, the unused third row zeroed for
	// range-bearing readings (so its zero innovation carries no information).
	Eigen::Vector3d predict(
		const Sighting& s, std::size_t idx, Eigen::Matrix3d* Hx, Eigen::Matrix3d* Hy) const
	{
		Eigen::Vector3d h = slamObservation(robot(), s.sensor, landmark(idx), Hx, Hy);
		if (s.point)
		{
			h[2] = 0;
			if (Hx) Hx->row(2).setZero();
			if (Hy) Hy->row(2).setZero();
		}
		return h;
	}

   protected:
	void OnGetAction(KFArray_ACT& u) const override
	{
		u[0] = odo_mean.x();
		u[1] = odo_mean.y();
		u[2] = odo_mean.phi();
	}

	void OnTransitionModel(const KFArray_ACT& u, KFArray_VEH& xv, bool& out_skip) const override
	{
		out_skip = skip_prediction;
		const mrpt::poses::CPose2D p =
			mrpt::poses::CPose2D(xv[0], xv[1], xv[2]) + mrpt::poses::CPose2D(u[0], u[1], u[2]);
		xv[0] = p.x();
		xv[1] = p.y();
		xv[2] = p.phi();
	}

	void OnTransitionJacobian(KFMatrix_VxV& F) const override
	{
		const double c = std::cos(m_xkk[2]), s = std::sin(m_xkk[2]);
		F.setIdentity();
		F(0, 2) = -odo_mean.x() * s - odo_mean.y() * c;
		F(1, 2) = odo_mean.x() * c - odo_mean.y() * s;
	}

	void OnTransitionNoise(KFMatrix_VxV& Q) const override
	{
		const double c = std::cos(m_xkk[2]), s = std::sin(m_xkk[2]);
		Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
		R.topLeftCorner<2, 2>() << c, -s, s, c;
		Eigen::Matrix3d q = R * odo_cov * R.transpose();
		q(0, 0) += opts.extra_motion_var_xy_m2;
		q(1, 1) += opts.extra_motion_var_xy_m2;
		q(2, 2) += opts.extra_motion_var_yaw_rad2;
		Q.asEigen() = q;
	}

	// Observations are whitened: unit noise.
	void OnGetObservationNoise(KFMatrix_OxO& R) const override { R.setIdentity(); }

	// Predict only the landmarks sighted in this iteration.
	void OnPreComputingPredictions(
		const vector_KFArray_OBS&, std::vector<size_t>& out) const override
	{
		out.clear();
		for (std::size_t i = 0; i < sighting_of.size(); ++i)
			if (sighting_of[i] >= 0) out.push_back(i);
	}

	void OnObservationModel(
		const std::vector<size_t>& idxs, vector_KFArray_OBS& out) const override
	{
		out.resize(idxs.size());
		for (std::size_t k = 0; k < idxs.size(); ++k)
		{
			const std::size_t idx = idxs[k];
			if (idx >= sighting_of.size() || sighting_of[idx] < 0)
			{
				out[k].setZero();  // not sighted: never used, not computed
				continue;
			}
			const Sighting& s = pass[sighting_of[idx]];
			out[k].asEigen() = s.W * predict(s, idx, nullptr, nullptr);
		}
	}

	void OnObservationJacobians(size_t idx, KFMatrix_OxV& Hx, KFMatrix_OxF& Hy) const override
	{
		if (idx >= sighting_of.size() || sighting_of[idx] < 0)
		{
			Hx.setZero();
			Hy.setZero();
			return;
		}
		const Sighting& s = pass[sighting_of[idx]];
		Eigen::Matrix3d hx, hy;
		predict(s, idx, &hx, &hy);
		Hx.asEigen() = s.W * hx;
		Hy.asEigen() = s.W * hy;
	}

	void OnGetObservationsAndDataAssociation(
		vector_KFArray_OBS& out_z, std::vector<int>& out_da, const vector_KFArray_OBS&,
		const KFMatrix& in_S, const std::vector<size_t>& in_idx_S, const KFMatrix_OxO&) override
	{
		out_z.clear();
		out_da.clear();
		for (std::size_t i = 0; i < pass.size(); ++i)
		{
			const Sighting& s = pass[i];
			const auto it = id_to_idx.find(s.id);
			if (it == id_to_idx.end())
			{
				KFArray_OBS z;
				z.asEigen() = s.z;
				out_z.push_back(z);
				out_da.push_back(-1);
				new_queue.push_back(i);
				++used;
				continue;
			}
			const std::size_t idx = it->second;
			const Eigen::Vector3d h = predict(s, idx, nullptr, nullptr);
			Eigen::Vector3d nu = s.z - h;
			nu[1] = wrapToPi(nu[1]);
			nu[2] = s.point ? 0.0 : wrapToPi(nu[2]);
			const Eigen::Vector3d w = s.W * nu;
			std::size_t k = 0;
			while (k < in_idx_S.size() && in_idx_S[k] != idx) ++k;
			if (k == in_idx_S.size()) throw std::logic_error("ekf-slam: sighted landmark not predicted");
			const Eigen::Matrix3d S = in_S.asEigen().block<3, 3>(3 * k, 3 * k);
			const double d2 = w.dot(S.ldlt().solve(w));
			if (!(d2 <= gateThreshold(opts.gate_probability, s.point ? 2 : 3)))
			{
				++rejected;
				continue;
			}
			// MRPT's innovation is out_z - W h = W nu: the wrapped innovation.
			KFArray_OBS z;
			z.asEigen() = s.W * (h + nu);
			out_z.push_back(z);
			out_da.push_back(static_cast<int>(idx));
			++used;
			addHeight(idx, s);
		}
	}

	void OnInverseObservationModel(
		const KFArray_OBS& in_z, KFArray_FEAT& yn, KFMatrix_FxV& dyn_dxv, KFMatrix_FxO& dyn_dhn,
		KFMatrix_FxF& dyn_dhn_R_dyn_dhnT, bool& use_dyn_dhn_jacobian) const override
	{
		if (new_cursor >= new_queue.size())
			throw std::logic_error("ekf-slam: more new landmarks than queued sightings");
		const Sighting& s = pass[new_queue[new_cursor]];
		if ((in_z.asEigen() - s.z).cwiseAbs().maxCoeff() != 0.0)
			throw std::logic_error("ekf-slam: new landmark out of order");
		Eigen::Matrix3d Jx, Jz;
		Eigen::Vector3d l = slamInverseObservation(robot(), s.sensor, s.z, &Jx, &Jz);
		Eigen::Matrix3d P = Jz * s.C * Jz.transpose();
		if (s.point)
		{
			// The never-observed yaw: 0, fixed variance, uncorrelated.
			l[2] = 0;
			Jx.row(2).setZero();
			Jz.row(2).setZero();
			P = Jz * s.C * Jz.transpose();
			P(2, 2) = std::pow(opts.point_yaw_sigma_deg * kDeg, 2);
		}
		yn.asEigen() = l;
		dyn_dxv.asEigen() = Jx;
		dyn_dhn.asEigen() = Jz;
		dyn_dhn_R_dyn_dhnT.asEigen() = P;
		use_dyn_dhn_jacobian = false;  // the per-sighting covariance, not R = I
	}

	void OnNewLandmarkAddedToMap(const size_t, const size_t new_idx) override
	{
		const Sighting& s = pass[new_queue[new_cursor++]];
		id_to_idx[s.id] = new_idx;
		if (info.size() <= new_idx) info.resize(new_idx + 1);
		info[new_idx] = LandmarkInfo{s.id, 0.0, 0, false};
		addHeight(new_idx, s);
	}

	void OnNormalizeStateVector() override { normalize(); }

   public:
	// Wraps the yaws, symmetrises P and checks its diagonal.
	void normalize()
	{
		for (std::size_t i = 2; i < static_cast<std::size_t>(m_xkk.size()); i += 3)
			m_xkk[i] = wrapToPi(m_xkk[i]);
		auto P = m_pkk.asEigen();
		const Eigen::Index n = P.rows();
		for (Eigen::Index r = 0; r < n; ++r)
		{
			for (Eigen::Index c = r + 1; c < n; ++c)
			{
				const double m = 0.5 * (P(r, c) + P(c, r));
				P(r, c) = m;
				P(c, r) = m;
			}
			if (!std::isfinite(P(r, r)) || P(r, r) < -opts.pd_tolerance)
				throw std::runtime_error(
					"ekf-slam: covariance lost positive definiteness (diagonal " +
					std::to_string(r) + " = " + std::to_string(P(r, r)) + ")");
			if (P(r, r) < 0) P(r, r) = 0;
		}
	}

	void addHeight(std::size_t idx, const Sighting& s)
	{
		if (idx >= info.size() || info[idx].z_prior || !std::isfinite(s.height_m)) return;
		info[idx].z_sum += s.height_m;
		++info[idx].z_count;
	}
};

// Whitening matrix W = L^-1 with C = L L^T; throws on a non-PD C.
bool whiten(Sighting& s)
{
	if (!s.C.allFinite() || !s.z.allFinite()) return false;
	Eigen::LLT<Eigen::Matrix3d> llt(s.C);
	if (llt.info() != Eigen::Success) return false;
	s.W = llt.matrixL().solve(Eigen::Matrix3d::Identity());
	return true;
}
}  // namespace

// ---------------------------------------------------------------------------
// EkfSlam
// ---------------------------------------------------------------------------
class EkfSlam::Impl
{
   public:
	SlamKF kf;
	bool initialized = true;

	// Sightings of a frame, in the order of its observations.
	std::vector<Sighting> collect(const mrpt::obs::CSensoryFrame& sf, int& rejected) const
	{
		const EkfSlamOptions& o = kf.opts;
		bool has_coded = false;
		for (const auto& obs : sf)
			if (std::dynamic_pointer_cast<CObservationCodedLandmarks>(obs)) has_coded = true;
		const bool take_coded = o.input != SlamInput::BearingRange;
		const bool take_br = o.input == SlamInput::BearingRange || o.input == SlamInput::Both ||
			(o.input == SlamInput::Auto && !has_coded);
		std::vector<Sighting> out;
		for (const auto& obs : sf)
		{
			if (const auto c = std::dynamic_pointer_cast<CObservationCodedLandmarks>(obs);
				c && take_coded)
			{
				const mrpt::poses::CPose2D sensor = pose::cameraPlanarPose(c->cameraPose);
				for (const auto& t : c->sightings)
				{
					Sighting s;
					s.id = t.id;
					s.z = t.L;
					s.C = t.C_L * o.measurement_cov_scale;
					s.sensor = sensor;
					s.pose_in_landmark = t.pose_in_landmark;
					s.C_R = t.C_R * o.measurement_cov_scale;
					// Landmark centre height from the corners' mean row (level
					// camera, distortion ignored): z = z_cam - l2 (v - cy) / fy.
					const double fy = c->camera.fy();
					if (fy > 0 && t.L[0] > 0)
					{
						double v = 0;
						for (const auto& p : t.corners) v += 0.25 * p.y();
						s.height_m = c->cameraPose.z() - t.L[0] * (v - c->camera.cy()) / fy;
					}
					if (whiten(s)) out.push_back(s);
					else
						++rejected;
				}
			}
			else if (const auto b = std::dynamic_pointer_cast<mrpt::obs::CObservationBearingRange>(obs);
					 b && take_br)
			{
				const mrpt::poses::CPose2D sensor(b->sensorLocationOnRobot);
				for (const auto& m : b->sensedData)
				{
					if (m.landmarkID == mrpt::obs::INVALID_LANDMARK_ID)
					{
						++rejected;
						continue;
					}
					Sighting s;
					s.id = m.landmarkID;
					s.point = true;
					s.z = Eigen::Vector3d(m.range * std::cos(m.pitch), m.yaw, 0.0);
					s.C.setZero();
					if (o.use_reading_covariance && b->validCovariances)
						s.C.topLeftCorner<2, 2>() = m.covariance.asEigen().topLeftCorner<2, 2>();
					else
					{
						s.C(0, 0) = o.std_sensor_range * o.std_sensor_range;
						s.C(1, 1) = std::pow(o.std_sensor_yaw_deg * kDeg, 2);
					}
					s.C(2, 2) = 1.0;  // the unused component: unit noise, zero innovation
					s.sensor = sensor;
					s.height_m = b->sensorLocationOnRobot.z() - m.range * std::sin(m.pitch);
					if (whiten(s)) out.push_back(s);
					else
						++rejected;
				}
			}
		}
		return out;
	}

	// Places the robot from a coded sighting of a prior landmark (pose fix
	// with C_R, plus the landmark's own uncertainty and correlation).
	void anchor(const Sighting& s, std::size_t idx)
	{
		const Eigen::Vector3d lm = kf.landmark(idx);
		const mrpt::poses::CPose2D world_T_landmark(lm[0], lm[1], lm[2]);
		Eigen::Matrix3d C_world;
		const mrpt::poses::CPose2D r = pose::robotPoseInWorld(
			s.pose_in_landmark, s.C_R, world_T_landmark, s.sensor, &C_world);
		Eigen::Matrix3d J = Eigen::Matrix3d::Identity();  // d(robot)/d(landmark)
		J(0, 2) = -(r.y() - lm[1]);
		J(1, 2) = r.x() - lm[0];
		auto& x = kf.m_xkk;
		auto P = kf.m_pkk.asEigen();
		x[0] = r.x();
		x[1] = r.y();
		x[2] = r.phi();
		const Eigen::Index o = 3 + 3 * static_cast<Eigen::Index>(idx), n = P.rows();
		const Eigen::MatrixXd cross = J * P.block(o, 3, 3, n - 3);
		P.block(0, 3, 3, n - 3) = cross;
		P.block(3, 0, n - 3, 3) = cross.transpose();
		P.topLeftCorner<3, 3>() = C_world + J * P.block<3, 3>(o, o) * J.transpose();
	}
};

EkfSlam::EkfSlam(
	const EkfSlamOptions& options, const LandmarkMap& prior,
	const std::optional<PoseEstimate>& initial, const mrpt::config::CConfigFileBase* kf_cfg,
	const std::string& kf_section)
	: impl_(std::make_unique<Impl>())
{
	options.validate();
	SlamKF& kf = impl_->kf;
	kf.opts = options;
	if (kf_cfg) kf.KF_options.loadFromConfigFile(*kf_cfg, kf_section);
	if (initial && initial->initialized)
	{
		kf.m_xkk[0] = initial->mean.x();
		kf.m_xkk[1] = initial->mean.y();
		kf.m_xkk[2] = initial->mean.phi();
		kf.m_pkk.asEigen() = 0.5 * (initial->cov + initial->cov.transpose());
	}
	if (!prior.landmarks.empty())
	{
		const std::size_t n = 3 + 3 * prior.landmarks.size();
		Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n, n);
		P.topLeftCorner<3, 3>() = kf.m_pkk.asEigen();
		kf.m_xkk.resize(n);
		for (std::size_t i = 0; i < prior.landmarks.size(); ++i)
		{
			const MapLandmark& l = prior.landmarks[i];
			const std::size_t o = 3 + 3 * i;
			kf.m_xkk[o] = l.x_m;
			kf.m_xkk[o + 1] = l.y_m;
			kf.m_xkk[o + 2] = wrapToPi(l.yaw_rad);
			P(o, o) = P(o + 1, o + 1) = options.prior_sigma_xy * options.prior_sigma_xy;
			P(o + 2, o + 2) = std::pow(options.prior_sigma_yaw_deg * kDeg, 2);
			kf.id_to_idx[l.id] = i;
			kf.info.push_back(LandmarkInfo{l.id, l.z_m, 1, true});
		}
		kf.m_pkk.setSize(n, n);
		kf.m_pkk.asEigen() = P;
		impl_->initialized = initial && initial->initialized;
	}
}

EkfSlam::~EkfSlam() = default;

StepStats EkfSlam::step(
	const mrpt::obs::CActionRobotMovement2D* odometry, const mrpt::obs::CSensoryFrame& sf)
{
	SlamKF& kf = impl_->kf;
	StepStats st;
	kf.used = 0;
	kf.rejected = 0;
	std::vector<Sighting> all = impl_->collect(sf, st.rejected);

	if (odometry && odometry->poseChange)
	{
		const mrpt::poses::CPosePDFGaussian g(*odometry->poseChange);
		kf.odo_mean = g.mean;
		kf.odo_cov = g.cov.asEigen();
	}
	else
	{
		kf.odo_mean = mrpt::poses::CPose2D();
		kf.odo_cov = Eigen::Vector3d(
						 kf.opts.std_no_odo_xy * kf.opts.std_no_odo_xy,
						 kf.opts.std_no_odo_xy * kf.opts.std_no_odo_xy,
						 std::pow(kf.opts.std_no_odo_yaw_deg * kDeg, 2))
						 .asDiagonal();
	}

	if (!impl_->initialized)
	{
		// A prior map and no initial pose: wait for a coded sighting of a
		// prior landmark; odometry before it is meaningless.
		for (std::size_t i = 0; i < all.size(); ++i)
		{
			const auto it = kf.id_to_idx.find(all[i].id);
			if (all[i].point || it == kf.id_to_idx.end()) continue;
			impl_->anchor(all[i], it->second);
			kf.normalize();
			impl_->initialized = true;
			st.reinitialized = true;
			++st.used;
			all.erase(all.begin() + static_cast<std::ptrdiff_t>(i));
			break;
		}
		if (!impl_->initialized)
		{
			st.unknown_id += static_cast<int>(all.size());
			return st;
		}
		kf.odo_mean = mrpt::poses::CPose2D();  // the fix is at this frame
		kf.odo_cov.setZero();
	}

	// Pass k holds the k-th sighting of each ID in this frame: one
	// observation per landmark per Kalman iteration (the whitening is per
	// landmark); later passes skip the prediction.
	std::map<int, int> seen;
	std::vector<std::vector<Sighting>> passes(1);
	for (auto& s : all)
	{
		const int k = seen[s.id]++;
		if (static_cast<int>(passes.size()) <= k) passes.resize(k + 1);
		passes[k].push_back(std::move(s));
	}
	for (std::size_t p = 0; p < passes.size(); ++p)
	{
		kf.pass = std::move(passes[p]);
		kf.skip_prediction = p > 0;
		kf.iterate();
	}
	kf.pass.clear();
	st.used += kf.used;
	st.rejected += kf.rejected;
	return st;
}

PoseEstimate EkfSlam::estimate() const
{
	const SlamKF& kf = impl_->kf;
	PoseEstimate e;
	e.initialized = impl_->initialized;
	e.mean = mrpt::poses::CPose2D(kf.m_xkk[0], kf.m_xkk[1], kf.m_xkk[2]);
	e.cov = kf.m_pkk.asEigen().topLeftCorner<3, 3>();
	return e;
}

std::vector<MappedLandmark> EkfSlam::landmarks() const
{
	const SlamKF& kf = impl_->kf;
	std::vector<MappedLandmark> out;
	const std::size_t n = kf.getNumberOfLandmarksInTheMap();
	out.reserve(n);
	for (std::size_t i = 0; i < n; ++i)
	{
		MappedLandmark m;
		const Eigen::Vector3d l = kf.landmark(i);
		m.landmark.id = kf.info[i].id;
		m.landmark.x_m = l[0];
		m.landmark.y_m = l[1];
		m.landmark.yaw_rad = l[2];
		m.landmark.z_m = kf.info[i].z_count > 0 ? kf.info[i].z_sum / kf.info[i].z_count : 0.0;
		m.cov = kf.m_pkk.asEigen().block<3, 3>(3 + 3 * i, 3 + 3 * i);
		out.push_back(m);
	}
	return out;
}

std::size_t EkfSlam::landmarkCount() const { return impl_->kf.getNumberOfLandmarksInTheMap(); }

Eigen::MatrixXd EkfSlam::fullCovariance() const { return impl_->kf.m_pkk.asEigen(); }

double EkfSlam::meanKalmanIterationMs() const
{
	auto& kf = const_cast<SlamKF&>(impl_->kf);
	return 1e3 * kf.getProfiler().getMeanTime("KF:complete_step");
}

std::size_t EkfSlam::kalmanIterations() const { return impl_->kf.iterations; }

// ---------------------------------------------------------------------------
// Factory
// ---------------------------------------------------------------------------
namespace detail
{
std::unique_ptr<Localizer> makeEkfSlam(
	const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial)
{
	EkfSlamOptions o;
	o.loadFromConfigFile(cfg, "ekf_slam");
	LandmarkMap prior = map;
	if (prior.landmarks.empty() && !o.prior_map_file.empty())
		prior = isMrptLandmarksFile(o.prior_map_file) ? loadMrptLandmarksFile(o.prior_map_file)
													  : LandmarkMap::load(o.prior_map_file);
	return std::make_unique<EkfSlam>(o, prior, initial, &cfg, "ekf_slam_kf");
}
}  // namespace detail

}  // namespace codemark::filters
