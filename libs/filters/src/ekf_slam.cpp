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
	{ throw std::invalid_argument(std::string("[ekf_slam] ") + key + ": " + why); };
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
		if (in == "auto")
			input = SlamInput::Auto;
		else if (in == "coded")
			input = SlamInput::Coded;
		else if (in == "bearing_range")
			input = SlamInput::BearingRange;
		else if (in == "both")
			input = SlamInput::Both;
		else
			throw std::invalid_argument(
				"[" + s + "] input = '" + in + "' (expected auto, coded, bearing_range or both)");
	}
	const std::string lm = c.read_string(s, "landmarks", "", false);
	if (!lm.empty())
	{
		if (lm == "auto")
			landmarks = SlamLandmarks::Auto;
		else if (lm == "full")
			landmarks = SlamLandmarks::Full;
		else if (lm == "point")
			landmarks = SlamLandmarks::Point;
		else
			throw std::invalid_argument(
				"[" + s + "] landmarks = '" + lm + "' (expected auto, full or point)");
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
	static const char* kLandmarks[] = {"auto", "full", "point"};
	c.write(s, "landmarks", std::string(kLandmarks[static_cast<int>(landmarks)]), -1, -1);
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
	Eigen::Vector3d h(r, wrapToPi(std::atan2(dy, dx) - syaw), wrapToPi(syaw - landmark[2] - kPi));
	if (Hx)
	{
		// d(sx, sy)/d(yaw) = (-oy, ox).
		*Hx << -dx / r, -dy / r, (dx * oy - dy * ox) / r,  //
			dy / r2, -dx / r2, -(dy * oy + dx * ox) / r2 - 1.0,	 //
			0.0, 0.0, 1.0;
	}
	if (Hy)
	{
		*Hy << dx / r, dy / r, 0.0,	 //
			-dy / r2, dx / r2, 0.0,	 //
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
	Eigen::Vector3d l(
		robot[0] + ox + z[0] * cb, robot[1] + oy + z[0] * sb, wrapToPi(syaw - z[2] - kPi));
	if (Jx)
	{
		*Jx << 1.0, 0.0, -oy - z[0] * sb,  //
			0.0, 1.0, ox + z[0] * cb,  //
			0.0, 0.0, 1.0;
	}
	if (Jz)
	{
		*Jz << cb, -z[0] * sb, 0.0,	 //
			sb, z[0] * cb, 0.0,	 //
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
	Eigen::Matrix3d C =
		Eigen::Matrix3d::Identity();  //!< covariance of z (dummy 1 on the third for points)
	/** Whitening W = chol(C)^-1 (lower triangular, so its top-left 2x2
	 * block whitens the range-bearing part alone). */
	Eigen::Matrix3d W = Eigen::Matrix3d::Identity();
	mrpt::poses::CPose2D sensor;  //!< sensor's planar pose on the robot
	bool point = false;	 //!< range-bearing: the third component is unused
	double height_m = std::numeric_limits<double>::quiet_NaN();	 //!< landmark z estimate
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

/** The filter, D = 3: landmarks (x, y, yaw), measurements [l2 phi1 phi2]
 * (CKalmanFilterCapable<3,3,3,3>); D = 2: point landmarks (x, y),
 * measurements [range yaw] (CKalmanFilterCapable<3,2,2,3>, as
 * CRangeBearingKFSLAM2D), for range-bearing-only data. */
template <std::size_t D>
class SlamKF : public mrpt::bayes::CKalmanFilterCapable<3, D, D, 3>
{
	using Base = mrpt::bayes::CKalmanFilterCapable<3, D, D, 3>;
	using typename Base::KFArray_ACT;
	using typename Base::KFArray_FEAT;
	using typename Base::KFArray_OBS;
	using typename Base::KFArray_VEH;
	using typename Base::KFMatrix;
	using typename Base::KFMatrix_FxF;
	using typename Base::KFMatrix_FxO;
	using typename Base::KFMatrix_FxV;
	using typename Base::KFMatrix_OxF;
	using typename Base::KFMatrix_OxO;
	using typename Base::KFMatrix_OxV;
	using typename Base::KFMatrix_VxV;
	using typename Base::vector_KFArray_OBS;
	using VecD = Eigen::Matrix<double, D, 1>;
	using MatD = Eigen::Matrix<double, D, D>;
	using MatDx3 = Eigen::Matrix<double, D, 3>;

   public:
	using Base::m_pkk;
	using Base::m_xkk;

	EkfSlamOptions opts;
	std::map<int, std::size_t> id_to_idx;
	std::vector<LandmarkInfo> info;

	// Per Kalman iteration.
	std::vector<Sighting> pass;	 //!< this iteration's sightings, one per landmark at most
	std::vector<int> sighting_of;  //!< landmark index -> index in pass, or -1
	mutable std::vector<MatD> t_of;	 //!< per pass index: transform(), once computed
	mutable std::vector<bool> t_ready;	//!< per pass index: t_of is computed
	bool skip_prediction = false;
	mrpt::poses::CPose2D odo_mean;	//!< odometry increment in the robot frame
	Eigen::Matrix3d odo_cov = Eigen::Matrix3d::Zero();
	std::vector<std::size_t> new_queue;	 //!< pass indices of sightings to add, in order
	mutable std::size_t new_cursor = 0;
	int used = 0, rejected = 0;
	std::vector<Innovation> innovations;  //!< of this step's sightings of mapped landmarks
	std::size_t iterations = 0;

	SlamKF()
	{
		m_xkk.assign(3, 0.0);
		m_pkk.setSize(3, 3);
		m_pkk.setZero();
		this->KF_options.method = mrpt::bayes::kfEKFAlaDavison;
	}

	void iterate()
	{
		sighting_of.assign(this->getNumberOfLandmarksInTheMap(), -1);
		for (std::size_t i = 0; i < pass.size(); ++i)
			if (const auto it = id_to_idx.find(pass[i].id); it != id_to_idx.end())
				sighting_of[it->second] = static_cast<int>(i);
		new_queue.clear();
		new_cursor = 0;
		t_of.assign(pass.size(), MatD::Identity());
		t_ready.assign(pass.size(), false);
		this->runOneKalmanIteration();
		++iterations;
	}

	Eigen::Vector3d robot() const { return Eigen::Vector3d(m_xkk[0], m_xkk[1], m_xkk[2]); }
	/** Landmark \a idx as (x, y, yaw); yaw 0 for D = 2. */
	Eigen::Vector3d landmark(std::size_t idx) const
	{
		const std::size_t o = 3 + D * idx;
		return Eigen::Vector3d(m_xkk[o], m_xkk[o + 1], D == 3 ? m_xkk[o + D - 1] : 0.0);
	}
	/** Its covariance as 3x3 (D = 2: the yaw entry is point_yaw_sigma^2). */
	Eigen::Matrix3d landmarkCov(std::size_t idx) const
	{
		const Eigen::Index o = 3 + D * static_cast<Eigen::Index>(idx);
		Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
		c.topLeftCorner<D, D>() = m_pkk.asEigen().template block<D, D>(o, o);
		if (D == 2) c(2, 2) = std::pow(opts.point_yaw_sigma_deg * kDeg, 2);
		return c;
	}

	// h and its Jacobians for one sighting; for a range-bearing sighting in
	// the D = 3 filter the unused third row is zeroed (so its zero innovation
	// carries no information).
	VecD predict(const Sighting& s, std::size_t idx, MatDx3* Hx, MatD* Hy) const
	{
		Eigen::Matrix3d hx, hy;
		Eigen::Vector3d h = slamObservation(robot(), s.sensor, landmark(idx), &hx, &hy);
		if (D == 3 && s.point)
		{
			h[2] = 0;
			hx.row(2).setZero();
			hy.row(2).setZero();
		}
		if (Hx) *Hx = hx.topRows<D>();
		if (Hy) *Hy = hy.topLeftCorner<D, D>();
		return h.head<D>();
	}

	MatD whitening(const Sighting& s) const { return s.W.topLeftCorner<D, D>(); }

	/** The predicted observation of a sighting with its angle components
	 * unwrapped to within pi of the measured ones, so that z - h is the
	 * wrapped innovation whatever linear transform is applied to both. */
	VecD predictNear(const Sighting& s, std::size_t idx, MatDx3* Hx, MatD* Hy) const
	{
		VecD h = predict(s, idx, Hx, Hy);
		for (std::size_t k = 1; k < D; ++k) h[k] = s.z[k] - wrapToPi(s.z[k] - h[k]);
		return h;
	}

	/** The transform T applied to the sighting of landmark \a idx (pass
	 * index \a p), computed once per Kalman iteration, after the prediction
	 * stage, from the predicted covariance: T = V^T W with W = chol(C)^-1
	 * and V the eigenvectors of W H P H^T W^T + I. Then T C T^T = I (MRPT's
	 * single R) and T S T^T is diagonal: the scalar components of the
	 * transformed innovation are uncorrelated. That is what makes MRPT's
	 * scalar-at-once update (kfEKFAlaDavison) exact: it processes the
	 * components one after the other with the innovations computed once,
	 * before the first of them, which is only right when updating with one
	 * component does not change the prediction of the next (H_j P H_i^T =
	 * 0). With W alone, the correlated components of L (and the landmark
	 * yaw seen only through phi2) were fused as if independent: the
	 * landmark yaws diverged. Any invertible T leaves the full update
	 * (kfEKFNaive) unchanged. */
	const MatD& transform(std::size_t p, std::size_t idx) const
	{
		if (t_ready[p]) return t_of[p];
		MatDx3 hx;
		MatD hy;
		predict(pass[p], idx, &hx, &hy);
		const MatD W = whitening(pass[p]);
		Eigen::Matrix<double, D, 3 + D> H;
		H << W * hx, W * hy;
		const auto P = m_pkk.asEigen();
		const Eigen::Index o = 3 + D * static_cast<Eigen::Index>(idx);
		Eigen::Matrix<double, 3 + D, 3 + D> Pb;
		Pb.template topLeftCorner<3, 3>() = P.template block<3, 3>(0, 0);
		Pb.template topRightCorner<3, D>() = P.template block<3, D>(0, o);
		Pb.template bottomLeftCorner<D, 3>() = P.template block<D, 3>(o, 0);
		Pb.template bottomRightCorner<D, D>() = P.template block<D, D>(o, o);
		const MatD S = H * Pb * H.transpose() + MatD::Identity();
		const Eigen::SelfAdjointEigenSolver<MatD> eig(0.5 * (S + S.transpose()));
		t_of[p] = eig.eigenvectors().transpose() * W;
		t_ready[p] = true;
		return t_of[p];
	}

	// After every prediction and update (OnNormalizeStateVector), O(n):
	// wraps the yaws, checks that the state and P's diagonal are finite and
	// the diagonal >= -pd_tolerance (one in [-tol, 0] is raised to 0).
	void normalize()
	{
		m_xkk[2] = wrapToPi(m_xkk[2]);
		if (D == 3)
			for (std::size_t i = 5; i < static_cast<std::size_t>(m_xkk.size()); i += 3)
				m_xkk[i] = wrapToPi(m_xkk[i]);
		auto P = m_pkk.asEigen();
		for (Eigen::Index i = 0; i < P.rows(); ++i)
		{
			if (!std::isfinite(m_xkk[i]))
				throw std::runtime_error(
					"ekf-slam: the state became non-finite (entry " + std::to_string(i) + ")");
			if (!std::isfinite(P(i, i)) || P(i, i) < -opts.pd_tolerance)
				throw std::runtime_error(
					"ekf-slam: the covariance is no longer symmetric positive definite (diagonal " +
					std::to_string(i) + " = " + std::to_string(P(i, i)) + ")");
			if (P(i, i) < 0) P(i, i) = 0;
		}
	}

	// Once per step, O(n^2) (a full eigen-decomposition would cost O(n^3)):
	// symmetrises P (MRPT's full update (I-KH)P is not symmetric) and checks
	// every entry finite, every 2x2 principal minor non-negative within the
	// tolerance (P_ij^2 <= P_ii P_jj (1 + 1e-6) + tol), and the robot's block
	// and each landmark's block positive semi-definite (eigenvalues >= -tol
	// max(1, largest)). Anything else stops the run with an error.
	void checkCovariance()
	{
		auto P = m_pkk.asEigen();
		const double tol = opts.pd_tolerance;
		auto fail = [&](const std::string& what)
		{
			throw std::runtime_error(
				"ekf-slam: the covariance is no longer symmetric positive definite (" + what + ")");
		};
		P = 0.5 * (P + P.transpose()).eval();
		if (!P.allFinite()) fail("non-finite entries");
		const Eigen::VectorXd d = P.diagonal();
		const Eigen::MatrixXd excess = P.cwiseAbs2() - (d * d.transpose()) * (1.0 + 1e-6) -
									   Eigen::MatrixXd::Constant(P.rows(), P.cols(), tol);
		Eigen::Index r = 0, c = 0;
		if (excess.maxCoeff(&r, &c) > 0)
			fail(
				"entry (" + std::to_string(r) + ", " + std::to_string(c) +
				") = " + std::to_string(P(r, c)) + " exceeds its 2x2 principal minor");
		auto checkBlock = [&](const auto& B, Eigen::Index o)
		{
			using M = std::decay_t<decltype(B)>;
			const auto ev =
				Eigen::SelfAdjointEigenSolver<M>(B, Eigen::EigenvaluesOnly).eigenvalues();
			if (ev.minCoeff() < -tol * std::max(1.0, ev.maxCoeff()))
				fail(
					(o == 0 ? std::string("robot") : "landmark " + std::to_string((o - 3) / D)) +
					" block has eigenvalue " + std::to_string(ev.minCoeff()));
		};
		checkBlock(Eigen::Matrix3d(P.template block<3, 3>(0, 0)), 0);
		for (Eigen::Index o = 3; o + static_cast<Eigen::Index>(D) <= P.rows(); o += D)
			checkBlock(MatD(P.template block<D, D>(o, o)), o);
	}

	void addHeight(std::size_t idx, const Sighting& s)
	{
		if (idx >= info.size() || info[idx].z_prior || !std::isfinite(s.height_m)) return;
		info[idx].z_sum += s.height_m;
		++info[idx].z_count;
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

	void OnObservationModel(const std::vector<size_t>& idxs, vector_KFArray_OBS& out) const override
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
			const std::size_t p = static_cast<std::size_t>(sighting_of[idx]);
			out[k].asEigen() = transform(p, idx) * predictNear(pass[p], idx, nullptr, nullptr);
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
		const std::size_t p = static_cast<std::size_t>(sighting_of[idx]);
		MatDx3 hx;
		MatD hy;
		predict(pass[p], idx, &hx, &hy);
		const MatD& T = transform(p, idx);
		Hx.asEigen() = T * hx;
		Hy.asEigen() = T * hy;
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
			const VecD z = s.z.head<D>();
			const auto it = id_to_idx.find(s.id);
			if (it == id_to_idx.end())
			{
				KFArray_OBS zz;
				zz.asEigen() = z;
				out_z.push_back(zz);
				out_da.push_back(-1);
				new_queue.push_back(i);
				++used;
				continue;
			}
			const std::size_t idx = it->second;
			const VecD nu = z - predictNear(s, idx, nullptr, nullptr);	// wrapped
			const MatD& T = transform(i, idx);
			const VecD w = T * nu;
			std::size_t k = 0;
			while (k < in_idx_S.size() && in_idx_S[k] != idx) ++k;
			if (k == in_idx_S.size())
				throw std::logic_error("ekf-slam: sighted landmark not predicted");
			const MatD S = in_S.asEigen().template block<D, D>(D * k, D * k);
			const int dof = (D == 2 || s.point) ? 2 : 3;
			Innovation in = makeInnovation(w, S, gateThreshold(opts.gate_probability, dof));
			in.dof = dof;  // D = 3 with a point sighting: the third row is unused
			// Its components are the whitened measurement's, not L's.
			in.component_nis = Innovation::nanComponents();
			in.id = s.id;
			innovations.push_back(in);
			if (in.gated)
			{
				++rejected;
				continue;
			}
			// MRPT's innovation is out_z - T h = T nu (h from predictNear()):
			// the wrapped innovation, transformed.
			KFArray_OBS zz;
			zz.asEigen() = T * z;
			out_z.push_back(zz);
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
		if ((in_z.asEigen() - s.z.head<D>()).cwiseAbs().maxCoeff() != 0.0)
			throw std::logic_error("ekf-slam: new landmark out of order");
		Eigen::Matrix3d Jx, Jz;
		Eigen::Vector3d l = slamInverseObservation(robot(), s.sensor, s.z, &Jx, &Jz);
		Eigen::Matrix3d P = Jz * s.C * Jz.transpose();
		if (D == 3 && s.point)
		{
			// The never-observed yaw: 0, fixed variance, uncorrelated.
			l[2] = 0;
			Jx.row(2).setZero();
			Jz.row(2).setZero();
			P = Jz * s.C * Jz.transpose();
			P(2, 2) = std::pow(opts.point_yaw_sigma_deg * kDeg, 2);
		}
		if (D == 2)
		{
			// Range and bearing only (the sighting's full C when it is coded
			// only matters through its range-bearing block).
			const Eigen::Matrix2d J = Jz.topLeftCorner<2, 2>();
			P.topLeftCorner<2, 2>() = J * s.C.topLeftCorner<2, 2>() * J.transpose();
		}
		yn.asEigen() = l.head<D>();
		dyn_dxv.asEigen() = Jx.topRows<D>();
		dyn_dhn.asEigen() = Jz.topLeftCorner<D, D>();
		dyn_dhn_R_dyn_dhnT.asEigen() = P.topLeftCorner<D, D>();
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
};

// Whitening matrix W = L^-1 with C = L L^T; false on a non-PD C.
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
	EkfSlamOptions opts;
	std::unique_ptr<SlamKF<3>> k3;	//!< full landmarks
	std::unique_ptr<SlamKF<2>> k2;	//!< point landmarks (range-bearing-only data)
	std::optional<PoseEstimate> initial;
	LandmarkMap prior;
	/** The Kalman template's options (TKF_options holds a reference, so it
	 * cannot be copied whole). */
	struct KfOptions
	{
		mrpt::bayes::TKFMethod method = mrpt::bayes::kfEKFAlaDavison;
		int IKF_iterations = 5;
		bool enable_profiler = false;
		bool use_analytic_transition_jacobian = true;
		bool use_analytic_observation_jacobian = true;
		bool debug_verify_analytic_jacobians = false;
		double debug_verify_analytic_jacobians_threshold = 1e-2;
	} kfo;
	bool initialized = true;

	template <class F>
	auto visit(F&& f) const
	{
		if (k3) return f(*k3);
		return f(*k2);
	}
	bool created() const { return k3 || k2; }

	// Builds the filter of landmark dimension D with the initial pose and the
	// prior map.
	template <std::size_t D>
	void build(std::unique_ptr<SlamKF<D>>& kf)
	{
		kf = std::make_unique<SlamKF<D>>();
		kf->opts = opts;
		auto& k = kf->KF_options;
		k.method = kfo.method;
		k.IKF_iterations = kfo.IKF_iterations;
		k.enable_profiler = kfo.enable_profiler;
		k.use_analytic_transition_jacobian = kfo.use_analytic_transition_jacobian;
		k.use_analytic_observation_jacobian = kfo.use_analytic_observation_jacobian;
		k.debug_verify_analytic_jacobians = kfo.debug_verify_analytic_jacobians;
		k.debug_verify_analytic_jacobians_threshold = kfo.debug_verify_analytic_jacobians_threshold;
		if (initial && initial->initialized)
		{
			kf->m_xkk[0] = initial->mean.x();
			kf->m_xkk[1] = initial->mean.y();
			kf->m_xkk[2] = initial->mean.phi();
			kf->m_pkk.asEigen() = 0.5 * (initial->cov + initial->cov.transpose());
		}
		if (prior.landmarks.empty()) return;
		const std::size_t n = 3 + D * prior.landmarks.size();
		Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n, n);
		P.topLeftCorner<3, 3>() = kf->m_pkk.asEigen();
		kf->m_xkk.resize(n);
		for (std::size_t i = 0; i < prior.landmarks.size(); ++i)
		{
			const MapLandmark& l = prior.landmarks[i];
			const std::size_t o = 3 + D * i;
			kf->m_xkk[o] = l.x_m;
			kf->m_xkk[o + 1] = l.y_m;
			P(o, o) = P(o + 1, o + 1) = opts.prior_sigma_xy * opts.prior_sigma_xy;
			if (D == 3)
			{
				kf->m_xkk[o + D - 1] = wrapToPi(l.yaw_rad);
				P(o + D - 1, o + D - 1) = std::pow(opts.prior_sigma_yaw_deg * kDeg, 2);
			}
			kf->id_to_idx[l.id] = i;
			kf->info.push_back(LandmarkInfo{l.id, l.z_m, 1, true});
		}
		kf->m_pkk.setSize(n, n);
		kf->m_pkk.asEigen() = P;
		// Full landmarks: without an initial pose the first coded sighting of
		// a prior landmark places the robot. Points cannot: the robot starts
		// where the initial pose (default: the origin) says.
		initialized = D == 2 || (initial && initial->initialized);
	}

	// Sightings of a frame, in the order of its observations.
	std::vector<Sighting> collect(const mrpt::obs::CSensoryFrame& sf, int& rejected) const
	{
		const EkfSlamOptions& o = opts;
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
					if (whiten(s))
						out.push_back(s);
					else
						++rejected;
				}
			}
			else if (const auto b =
						 std::dynamic_pointer_cast<mrpt::obs::CObservationBearingRange>(obs);
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
					if (whiten(s))
						out.push_back(s);
					else
						++rejected;
				}
			}
		}
		return out;
	}

	// Places the robot from a coded sighting of a prior landmark (pose fix
	// with C_R, plus the landmark's own uncertainty and correlation).
	void anchor(SlamKF<3>& kf, const Sighting& s, std::size_t idx)
	{
		const Eigen::Vector3d lm = kf.landmark(idx);
		const mrpt::poses::CPose2D world_T_landmark(lm[0], lm[1], lm[2]);
		Eigen::Matrix3d C_world;
		const mrpt::poses::CPose2D r =
			pose::robotPoseInWorld(s.pose_in_landmark, s.C_R, world_T_landmark, s.sensor, &C_world);
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

	template <std::size_t D>
	StepStats step(
		SlamKF<D>& kf, const mrpt::obs::CActionRobotMovement2D* odometry, std::vector<Sighting> all,
		StepStats st)
	{
		kf.used = 0;
		kf.rejected = 0;
		kf.innovations.clear();
		if (odometry && odometry->poseChange)
		{
			const mrpt::poses::CPosePDFGaussian g(*odometry->poseChange);
			kf.odo_mean = g.mean;
			kf.odo_cov = g.cov.asEigen();
		}
		else
		{
			const double vxy = opts.std_no_odo_xy * opts.std_no_odo_xy;
			kf.odo_mean = mrpt::poses::CPose2D();
			kf.odo_cov =
				Eigen::Vector3d(vxy, vxy, std::pow(opts.std_no_odo_yaw_deg * kDeg, 2)).asDiagonal();
		}
		if (!initialized)
		{
			if constexpr (D == 3)
			{
				// A prior map and no initial pose: wait for a coded sighting
				// of a prior landmark; odometry before it is meaningless.
				for (std::size_t i = 0; i < all.size(); ++i)
				{
					const auto it = kf.id_to_idx.find(all[i].id);
					if (all[i].point || it == kf.id_to_idx.end()) continue;
					anchor(kf, all[i], it->second);
					kf.normalize();
					initialized = true;
					st.reinitialized = true;
					++st.used;
					all.erase(all.begin() + static_cast<std::ptrdiff_t>(i));
					break;
				}
			}
			if (!initialized)
			{
				st.unknown_id += static_cast<int>(all.size());
				return st;
			}
			kf.odo_mean = mrpt::poses::CPose2D();  // the fix is at this frame
			kf.odo_cov.setZero();
		}
		// One Kalman iteration per pass; later passes skip the prediction.
		// The full update (kfEKFNaive): pass k holds the k-th sighting of each
		// ID in this frame (one observation per landmark per iteration, the
		// transform is per landmark). The scalar-at-once update: one sighting
		// of a mapped landmark per pass, since SlamKF::transform() decorrelates
		// the components of one sighting given the covariance before its
		// update; new landmarks share the first pass.
		std::vector<std::vector<Sighting>> passes(1);
		if (kf.KF_options.method == mrpt::bayes::kfEKFAlaDavison)
		{
			std::map<int, int> seen;
			for (auto& s : all)
			{
				const bool fresh = !kf.id_to_idx.count(s.id) && seen[s.id]++ == 0;
				if (fresh)
					passes.front().push_back(std::move(s));
				else
					passes.push_back({std::move(s)});
			}
			if (passes.size() > 1 && passes.front().empty()) passes.erase(passes.begin());
		}
		else
		{
			std::map<int, int> seen;
			for (auto& s : all)
			{
				const int k = seen[s.id]++;
				if (static_cast<int>(passes.size()) <= k) passes.resize(k + 1);
				passes[k].push_back(std::move(s));
			}
		}
		for (std::size_t p = 0; p < passes.size(); ++p)
		{
			kf.pass = std::move(passes[p]);
			kf.skip_prediction = p > 0;
			kf.iterate();
		}
		kf.pass.clear();
		kf.checkCovariance();
		st.used += kf.used;
		st.rejected += kf.rejected;
		st.innovations.insert(st.innovations.end(), kf.innovations.begin(), kf.innovations.end());
		return st;
	}
};

EkfSlam::EkfSlam(
	const EkfSlamOptions& options, const LandmarkMap& prior,
	const std::optional<PoseEstimate>& initial, const mrpt::config::CConfigFileBase* kf_cfg,
	const std::string& kf_section)
	: impl_(std::make_unique<Impl>())
{
	options.validate();
	Impl& m = *impl_;
	m.opts = options;
	m.initial = initial;
	m.prior = prior;
	if (kf_cfg)
	{
		SlamKF<3> probe;  // MRPT's own loader, defaults as ours
		auto& k = probe.KF_options;
		k.loadFromConfigFile(*kf_cfg, kf_section);
		m.kfo = {
			k.method,
			k.IKF_iterations,
			k.enable_profiler,
			k.use_analytic_transition_jacobian,
			k.use_analytic_observation_jacobian,
			k.debug_verify_analytic_jacobians,
			k.debug_verify_analytic_jacobians_threshold};
	}
	// With a prior map and no initial pose the robot waits for a pose fix
	// (full landmarks; build() decides for good).
	m.initialized = prior.landmarks.empty() || (initial && initial->initialized);
	if (options.landmarks == SlamLandmarks::Full)
		m.build(m.k3);
	else if (options.landmarks == SlamLandmarks::Point)
		m.build(m.k2);
	// Auto: decided by the first frame with sightings.
}

EkfSlam::~EkfSlam() = default;

StepStats EkfSlam::step(
	const mrpt::obs::CActionRobotMovement2D* odometry, const mrpt::obs::CSensoryFrame& sf)
{
	Impl& m = *impl_;
	StepStats st;
	std::vector<Sighting> all = m.collect(sf, st.rejected);
	if (!m.created())
	{
		if (all.empty())
		{
			// Nothing to decide the landmark kind by: dead-reckon the pose
			// (unless it waits for a fix from a prior map).
			if (m.initialized && odometry && odometry->poseChange)
			{
				const mrpt::poses::CPosePDFGaussian g(*odometry->poseChange);
				PoseEstimate e = m.initial.value_or(PoseEstimate{});
				const double c = std::cos(e.mean.phi()), s = std::sin(e.mean.phi());
				Eigen::Matrix3d F = Eigen::Matrix3d::Identity(), R = Eigen::Matrix3d::Identity();
				F(0, 2) = -g.mean.x() * s - g.mean.y() * c;
				F(1, 2) = g.mean.x() * c - g.mean.y() * s;
				R.topLeftCorner<2, 2>() << c, -s, s, c;
				e.cov = F * e.cov * F.transpose() + R * g.cov.asEigen() * R.transpose();
				e.mean = e.mean + g.mean;
				e.initialized = true;
				m.initial = e;
			}
			return st;
		}
		bool any_coded = false;
		for (const auto& s : all) any_coded |= !s.point;
		if (any_coded)
			m.build(m.k3);
		else
			m.build(m.k2);
	}
	if (m.k2)
		for (auto& s : all) s.point = true;	 // coded sightings feed range and bearing only
	if (m.k3) return m.step(*m.k3, odometry, std::move(all), st);
	return m.step(*m.k2, odometry, std::move(all), st);
}

PoseEstimate EkfSlam::estimate() const
{
	const Impl& m = *impl_;
	if (!m.created())
	{
		PoseEstimate e = m.initial.value_or(PoseEstimate{});
		e.initialized = m.initialized;
		return e;
	}
	return m.visit(
		[&](const auto& kf)
		{
			PoseEstimate e;
			e.initialized = m.initialized;
			e.mean = mrpt::poses::CPose2D(kf.m_xkk[0], kf.m_xkk[1], kf.m_xkk[2]);
			e.cov = kf.m_pkk.asEigen().template topLeftCorner<3, 3>();
			return e;
		});
}

std::vector<MappedLandmark> EkfSlam::landmarks() const
{
	const Impl& m = *impl_;
	if (!m.created()) return {};
	return m.visit(
		[&](const auto& kf)
		{
			std::vector<MappedLandmark> out;
			const std::size_t n = kf.getNumberOfLandmarksInTheMap();
			out.reserve(n);
			for (std::size_t i = 0; i < n; ++i)
			{
				MappedLandmark lm;
				const Eigen::Vector3d l = kf.landmark(i);
				lm.landmark.id = kf.info[i].id;
				lm.landmark.x_m = l[0];
				lm.landmark.y_m = l[1];
				lm.landmark.yaw_rad = l[2];
				lm.landmark.z_m =
					kf.info[i].z_count > 0 ? kf.info[i].z_sum / kf.info[i].z_count : 0.0;
				lm.cov = kf.landmarkCov(i);
				out.push_back(lm);
			}
			return out;
		});
}

std::size_t EkfSlam::landmarkCount() const
{
	if (!impl_->created()) return 0;
	return impl_->visit([](const auto& kf) { return kf.getNumberOfLandmarksInTheMap(); });
}

std::size_t EkfSlam::landmarkDimension() const
{
	if (!impl_->created()) return 0;
	return impl_->k3 ? 3 : 2;
}

Eigen::MatrixXd EkfSlam::fullCovariance() const
{
	if (!impl_->created()) return impl_->initial.value_or(PoseEstimate{}).cov;
	return impl_->visit([](const auto& kf) { return Eigen::MatrixXd(kf.m_pkk.asEigen()); });
}

double EkfSlam::meanKalmanIterationMs() const
{
	if (!impl_->created()) return 0;
	return impl_->visit(
		[](const auto& kf)
		{
			return 1e3 * const_cast<std::decay_t<decltype(kf)>&>(kf).getProfiler().getMeanTime(
							 "KF:complete_step");
		});
}

std::size_t EkfSlam::kalmanIterations() const
{
	if (!impl_->created()) return 0;
	return impl_->visit([](const auto& kf) { return kf.iterations; });
}

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
