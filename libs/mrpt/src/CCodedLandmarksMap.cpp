#include <codemark/mrpt/CCodedLandmarksMap.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <codemark/pose/closed_form.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/math/wrap2pi.h>
#include <mrpt/obs/CObservationBearingRange.h>
#include <mrpt/opengl/CBox.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/opengl/CText.h>
#include <mrpt/opengl/stock_objects.h>
#include <mrpt/serialization/CArchive.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

//  Map definition: [MetricMap] codedLandmarksMap_count=1 builds one.
MAP_DEFINITION_REGISTER(
	"codemark::CCodedLandmarksMap,codedLandmarksMap", codemark::CCodedLandmarksMap)

IMPLEMENTS_SERIALIZABLE(CCodedLandmarksMap, mrpt::maps::CMetricMap, codemark)

namespace codemark
{
namespace
{
constexpr double kTwoPi = 2.0 * M_PI;
constexpr int kMaxIndexedId = 65536;

/** Wraps an angle in (-3 pi, 3 pi), e.g. a difference of two wrapped
 * angles, to (-pi, pi] without fmod (hot path: once per particle). */
inline double wrapNear(double a)
{
	if (a > M_PI) return a - kTwoPi;
	if (a <= -M_PI) return a + kTwoPi;
	return a;
}

/** A difference of angles wrapped to (-pi, pi]: the cheap branch for
 * wrapped inputs, MRPT's general one otherwise. */
inline double wrapDiff(double a)
{
	a = wrapNear(a);
	return (a > M_PI || a <= -M_PI) ? mrpt::math::wrapToPi(a) : a;
}

/** The camera's pose in frame L (\a xl, \a yl [m], heading (\a ux, \a uy))
 * of a camera at (cam_x, cam_y, heading (cam_cos, cam_sin)) in the world and
 * a landmark at (lm_x, lm_y, yaw (lm_cos, lm_sin)): a rotation by -yaw. */
struct InLandmark
{
	double xl, yl, ux, uy;
	InLandmark(
		double cam_x, double cam_y, double cam_cos, double cam_sin, double lm_x, double lm_y,
		double lm_cos, double lm_sin)
	{
		const double dx = cam_x - lm_x, dy = cam_y - lm_y;
		xl = lm_cos * dx + lm_sin * dy;
		yl = -lm_sin * dx + lm_cos * dy;
		ux = lm_cos * cam_cos + lm_sin * cam_sin;
		uy = -lm_sin * cam_cos + lm_cos * cam_sin;
	}
	/** L = [l2 phi1 phi2]: theta = pi + phi2 and atan2(y, x) = phi1 + phi2
	 * (spec section 4). */
	Eigen::Vector3d L() const
	{
		const double phi2 = std::atan2(-uy, -ux);
		return {std::hypot(xl, yl), wrapNear(std::atan2(yl, xl) - phi2), phi2};
	}
};

/** log((1 - p) exp(log_gauss) + p exp(log_uniform)), computed stably; when
 * one term exceeds the other by e^35 the smaller one is below double
 * precision of the sum and is skipped (no exp/log on the hot path). */
double logMixture(double log_gauss, double log_uniform, double p)
{
	if (p <= 0) return log_gauss;
	const double a = std::log1p(-p) + log_gauss;
	const double b = std::log(p) + log_uniform;
	if (a - b > 35) return a;
	if (b - a > 35) return b;
	const double m = std::max(a, b);
	return m + std::log(std::exp(a - m) + std::exp(b - m));
}

/** log N(r; 0, C) for a k-dimensional residual (k = 2 or 3), Eigen's
 * fixed-size closed-form inverse; +inf-free: returns false when C is not
 * positive definite. */
template <int K>
bool logGauss(
	const Eigen::Matrix<double, K, 1>& r, const Eigen::Matrix<double, K, K>& C, double& out)
{
	const double det = C.determinant();
	if (!(det > 0) || !std::isfinite(det)) return false;
	const double d2 = r.dot(C.inverse() * r);
	out = -0.5 * d2 - 0.5 * (K * std::log(kTwoPi) + std::log(det));
	return std::isfinite(out);
}

/** Whether a sighting is scored in P (CCodedLandmarksMap::scoreP()): the
 * closed form's sightings, whose P follows from L by the level camera's
 * model; the general path's L comes from the corners by a 6-DoF pose. */
bool scoredInPrimary(const CObservationCodedLandmarks::TSighting& sg)
{
	return sg.method == pose::PoseMethod::ClosedForm && sg.P[1] > 0 && sg.P[3] > 0 && sg.L[0] > 0 &&
		   sg.C_P.allFinite();
}

/** The inner half-height [m] that a sighting was measured with: the closed
 * form's range is proportional to it (landmarkFromPrimary()), so it is the
 * sighting's l2 over the closed form's range of a landmark of unit size from
 * the same P. Taken from the sighting rather than from the map, so that a
 * landmark file of another geometry is scored with its own; a refined l2
 * (refine_on_primary) differs from the closed form's by a small fraction of
 * its standard deviation. */
double impliedInnerHalf(const Eigen::Vector4d& P, double l2, double lambda_px)
{
	return l2 / pose::landmarkFromPrimary(P, lambda_px, 1.0)[0];
}
}  // namespace

// ---------------------------------------------------------------- options
void CCodedLandmarksMap::TLikelihoodOptions::loadFromConfigFile(
	const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	MRPT_LOAD_CONFIG_VAR(outlier_probability, double, c, s);
	MRPT_LOAD_CONFIG_VAR(sigma_scale, double, c, s);
	MRPT_LOAD_CONFIG_VAR(min_std_range_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(min_std_angle_deg, double, c, s);
	MRPT_LOAD_CONFIG_VAR(max_range_m, double, c, s);
	ASSERTMSG_(
		outlier_probability >= 0 && outlier_probability < 1,
		"[" + s + "] outlier_probability must be in [0, 1)");
	ASSERTMSG_(sigma_scale > 0, "[" + s + "] sigma_scale must be > 0");
	ASSERTMSG_(
		min_std_range_m >= 0 && min_std_angle_deg >= 0,
		"[" + s + "] min_std_range_m and min_std_angle_deg must be >= 0");
	ASSERTMSG_(max_range_m > 0, "[" + s + "] max_range_m must be > 0");
}

void CCodedLandmarksMap::TLikelihoodOptions::saveToConfigFile(
	mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	c.write(
		s, "outlier_probability", outlier_probability, -1, -1, "uniform's weight in the mixture");
	c.write(s, "sigma_scale", sigma_scale, -1, -1, "multiplies each std of C_L");
	c.write(s, "min_std_range_m", min_std_range_m, -1, -1, "added in quadrature [m]");
	c.write(s, "min_std_angle_deg", min_std_angle_deg, -1, -1, "added in quadrature [deg]");
	c.write(s, "max_range_m", max_range_m, -1, -1, "outliers' range span [m]");
}

// ---------------------------------------------------------- map definition
CCodedLandmarksMap::TMapDefinition::TMapDefinition() = default;

void CCodedLandmarksMap::TMapDefinition::loadFromConfigFile_map_specific(
	const mrpt::config::CConfigFileBase& source, const std::string& prefix)
{
	map_file = source.read_string(prefix + "_creationOpts", "map_file", map_file);
	likelihoodOpts.loadFromConfigFile(source, prefix + "_likelihoodOpts");
}

void CCodedLandmarksMap::TMapDefinition::dumpToTextStream_map_specific(std::ostream& out) const
{
	out << "map_file = " << map_file << "\n";
	likelihoodOpts.dumpToTextStream(out);
}

mrpt::maps::CMetricMap* CCodedLandmarksMap::internal_CreateFromMapDefinition(
	const mrpt::maps::TMetricMapInitializer& def_)
{
	const auto& def = dynamic_cast<const CCodedLandmarksMap::TMapDefinition&>(def_);
	auto map = std::make_unique<CCodedLandmarksMap>();
	map->likelihoodOptions = def.likelihoodOpts;
	if (!def.map_file.empty()) map->setLandmarks(LandmarkMap::load(def.map_file));
	return map.release();
}

// ------------------------------------------------------------- landmarks
CCodedLandmarksMap::CCodedLandmarksMap(const LandmarkMap& map) { setLandmarks(map); }

void CCodedLandmarksMap::setLandmarks(const LandmarkMap& map)
{
	m_map = map;
	rebuildIndex();
}

void CCodedLandmarksMap::rebuildIndex()
{
	m_cache.clear();
	m_index.clear();
	int max_id = -1;
	for (const auto& lm : m_map.landmarks)
	{
		m_cache.push_back({lm.x_m, lm.y_m, lm.z_m, std::cos(lm.yaw_rad), std::sin(lm.yaw_rad)});
		if (lm.id >= 0 && lm.id < kMaxIndexedId) max_id = std::max(max_id, lm.id);
	}
	m_index.assign(static_cast<size_t>(max_id) + 1, -1);
	for (size_t i = 0; i < m_map.landmarks.size(); ++i)
	{
		const int id = m_map.landmarks[i].id;
		if (id >= 0 && id < kMaxIndexedId)
			m_index[static_cast<size_t>(id)] = static_cast<int32_t>(i);
	}
}

int CCodedLandmarksMap::indexOf(int id) const
{
	if (id >= 0 && id < kMaxIndexedId)
		return static_cast<size_t>(id) < m_index.size() ? m_index[static_cast<size_t>(id)] : -1;
	for (size_t i = 0; i < m_map.landmarks.size(); ++i)
		if (m_map.landmarks[i].id == id) return static_cast<int>(i);
	return -1;
}

const MapLandmark* CCodedLandmarksMap::find(int id) const
{
	const int i = indexOf(id);
	return i < 0 ? nullptr : &m_map.landmarks[static_cast<size_t>(i)];
}

bool CCodedLandmarksMap::boundingBox(mrpt::math::TPoint3D& lo, mrpt::math::TPoint3D& hi) const
{
	if (m_map.landmarks.empty()) return false;
	const auto& f = m_map.landmarks.front();
	lo = hi = mrpt::math::TPoint3D(f.x_m, f.y_m, f.z_m);
	for (const auto& lm : m_map.landmarks)
	{
		lo.x = std::min(lo.x, lm.x_m), lo.y = std::min(lo.y, lm.y_m), lo.z = std::min(lo.z, lm.z_m);
		hi.x = std::max(hi.x, lm.x_m), hi.y = std::max(hi.y, lm.y_m), hi.z = std::max(hi.z, lm.z_m);
	}
	return true;
}

void CCodedLandmarksMap::internal_clear()
{
	m_map.landmarks.clear();
	rebuildIndex();
}

bool CCodedLandmarksMap::internal_insertObservation(
	const mrpt::obs::CObservation&, const std::optional<const mrpt::poses::CPose3D>&)
{
	return false;  // a known, static map: observations do not change it
}

// ------------------------------------------------------------ likelihood
Eigen::Vector3d CCodedLandmarksMap::predictL(
	double cam_x, double cam_y, double cam_cos, double cam_sin, double lm_x, double lm_y,
	double lm_cos, double lm_sin)
{
	return InLandmark(cam_x, cam_y, cam_cos, cam_sin, lm_x, lm_y, lm_cos, lm_sin).L();
}

double CCodedLandmarksMap::sightingLogLikelihood(
	const Eigen::Vector3d& L, const Eigen::Matrix3d& C_L, double cam_x, double cam_y,
	double cam_cos, double cam_sin, const MapLandmark& lm) const
{
	const InLandmark in(
		cam_x, cam_y, cam_cos, cam_sin, lm.x_m, lm.y_m, std::cos(lm.yaw_rad), std::sin(lm.yaw_rad));
	return scoreL(L, C_L, in.xl, in.yl, in.ux, in.uy);
}

bool CCodedLandmarksMap::cameraInWorld(
	double rx, double ry, double rc, double rs, const mrpt::poses::CPose3D& cp, double& cam_x,
	double& cam_y, double& cam_c, double& cam_s)
{
	// The optical axis is the third column of the optical frame's rotation.
	const auto& CR = cp.getRotationMatrix();
	double ax = CR(0, 2), ay = CR(1, 2);
	const double an = std::hypot(ax, ay);
	if (!(an > 1e-9)) return false;
	ax /= an, ay /= an;
	cam_x = rx + rc * cp.x() - rs * cp.y();
	cam_y = ry + rs * cp.x() + rc * cp.y();
	cam_c = rc * ax - rs * ay;
	cam_s = rs * ax + rc * ay;
	return true;
}

Eigen::Matrix3d CCodedLandmarksMap::inflatedCovariance(const Eigen::Matrix3d& C_L) const
{
	const auto& o = likelihoodOptions;
	const double sa = o.min_std_angle_deg * M_PI / 180.0;
	Eigen::Matrix3d C = (o.sigma_scale * o.sigma_scale) * C_L;
	C(0, 0) += o.min_std_range_m * o.min_std_range_m;
	C(1, 1) += sa * sa;
	C(2, 2) += sa * sa;
	return C;
}

double CCodedLandmarksMap::sightingMahalanobis2(
	const Eigen::Vector3d& L, const Eigen::Matrix3d& C_L, const Eigen::Vector3d& Lp) const
{
	Eigen::Vector3d r = L - Lp;
	r[1] = wrapDiff(r[1]);
	r[2] = wrapDiff(r[2]);
	const Eigen::Matrix3d C = inflatedCovariance(C_L);
	if (!(C.determinant() > 0)) return std::numeric_limits<double>::infinity();
	return r.dot(C.inverse() * r);
}

double CCodedLandmarksMap::scoreL(
	const Eigen::Vector3d& L, const Eigen::Matrix3d& C_L, double xl, double yl, double ux,
	double uy) const
{
	const auto& o = likelihoodOptions;
	const double p = o.outlier_probability;
	const double log_uniform = -std::log(o.max_range_m * kTwoPi * kTwoPi);
	const Eigen::Matrix3d C = inflatedCovariance(C_L);
	const double det = C.determinant();
	if (!(det > 0) || !std::isfinite(det))
		return log_uniform;	 // unusable covariance: no information
	const double log_norm = -0.5 * (3 * std::log(kTwoPi) + std::log(det));
	// Early out before the angles: d^2 >= r_range^2 / C(0,0) for any
	// positive definite C, so a range residual alone can make the Gaussian
	// term negligible against the uniform (e^-35).
	const double r0 = L[0] - std::hypot(xl, yl);
	const double log_out = p > 0 ? std::log(p) + log_uniform : 0;
	if (p > 0 && std::log1p(-p) + log_norm - 0.5 * r0 * r0 / C(0, 0) - log_out < -35)
		return log_out;
	const double phi2 = std::atan2(-uy, -ux);
	const double phi1 = wrapNear(std::atan2(yl, xl) - phi2);
	const Eigen::Vector3d r(r0, wrapDiff(L[1] - phi1), wrapDiff(L[2] - phi2));
	const double lg = log_norm - 0.5 * r.dot(C.inverse() * r);
	return logMixture(lg, log_uniform, p);
}

double CCodedLandmarksMap::scoreP(
	const Eigen::Vector4d& P, const Eigen::Matrix4d& C_P, double h, double lambda,
	double log_uniform, double xl, double yl, double ux, double uy) const
{
	const auto& o = likelihoodOptions;
	const double p = o.outlier_probability;
	// Where the landmark cannot be seen, only the outliers' share remains
	// (p = 0: a negligible 1e-12 of it, keeping the weights finite).
	const double log_out = std::log(std::max(p, 1e-12)) + log_uniform;
	if (!(xl > 0)) return log_out;	// the camera is behind the printed side
	// L's angles without trigonometry: phi2 = atan2(-uy, -ux) and
	// phi1 = atan2(yl, xl) - phi2 (spec section 4).
	const double l2 = std::hypot(xl, yl), ca = xl / l2, sa = yl / l2, c2 = -ux, s2 = -uy;
	Eigen::Vector4d Pp;
	Eigen::Matrix<double, 4, 3> J;
	if (!pose::primaryFromLandmark(
			l2, ca * c2 + sa * s2, sa * c2 - ca * s2, c2, s2, lambda, h, Pp, &J))
		return log_out;
	const double s_angle = o.min_std_angle_deg * M_PI / 180.0;
	const Eigen::Vector3d floors(
		o.min_std_range_m * o.min_std_range_m, s_angle * s_angle, s_angle * s_angle);
	const Eigen::Matrix4d C =
		(o.sigma_scale * o.sigma_scale) * C_P + J * floors.asDiagonal() * J.transpose();
	// Cholesky rather than a closed-form inverse: near an edge-on view J is
	// huge and C ill-conditioned.
	const Eigen::LLT<Eigen::Matrix4d> llt(C);
	if (llt.info() != Eigen::Success) return log_uniform;  // unusable covariance: no information
	const double d2 = llt.matrixL().solve(P - Pp).squaredNorm();
	const double log_det_half = llt.matrixLLT().diagonal().array().log().sum();
	const double lg = -0.5 * d2 - 2 * std::log(kTwoPi) - log_det_half;
	return logMixture(lg, log_uniform, p);
}

double CCodedLandmarksMap::internal_computeObservationLikelihood(
	const mrpt::obs::CObservation& obs, const mrpt::poses::CPose3D& takenFrom) const
{
	const auto& o = likelihoodOptions;
	// The robot's planar pose: the rotation matrix's first column is the
	// heading (no trigonometry per particle).
	const auto& R = takenFrom.getRotationMatrix();
	const double rc = R(0, 0), rs = R(1, 0), rx = takenFrom.x(), ry = takenFrom.y();

	// Exact class checks (pointer compares) rather than dynamic_cast: this
	// runs once per particle and observation.
	const auto* cls = obs.GetRuntimeClass();
	if (cls == CLASS_ID(CObservationCodedLandmarks))
	{
		double cam_x = 0, cam_y = 0, cam_c = 1, cam_s = 0;
		const auto* coded = static_cast<const CObservationCodedLandmarks*>(&obs);
		if (!cameraInWorld(rx, ry, rc, rs, coded->cameraPose, cam_x, cam_y, cam_c, cam_s))
			return 0;  // camera looking straight up/down: no planar model
		// P's outliers spread over the image: x1, x2 across its width, y1,
		// y2 up to half its height.
		const mrpt::img::TCamera& camera = coded->camera;
		const double lambda = camera.fx();
		const bool in_p = lambda > 0 && camera.ncols > 0 && camera.nrows > 0;
		const double log_uniform_p =
			in_p ? -2 * std::log(0.5 * double(camera.ncols) * double(camera.nrows)) : 0;
		double ll = 0;
		for (const auto& sg : coded->sightings)
		{
			const int i = indexOf(sg.id);
			if (i < 0) continue;  // unknown ID: no information about the pose
			const Cached& lm = m_cache[static_cast<size_t>(i)];
			const InLandmark in(cam_x, cam_y, cam_c, cam_s, lm.x, lm.y, lm.cos_yaw, lm.sin_yaw);
			if (in_p && scoredInPrimary(sg))
				ll += scoreP(
					sg.P, sg.C_P, impliedInnerHalf(sg.P, sg.L[0], lambda), lambda, log_uniform_p,
					in.xl, in.yl, in.ux, in.uy);
			else
				ll += scoreL(sg.L, sg.C_L, in.xl, in.yl, in.ux, in.uy);
		}
		return ll;
	}

	if (cls == CLASS_ID(mrpt::obs::CObservationBearingRange))
	{
		const auto* br = static_cast<const mrpt::obs::CObservationBearingRange*>(&obs);
		const mrpt::poses::CPose3D sensor = takenFrom + br->sensorLocationOnRobot;
		const double k2 = o.sigma_scale * o.sigma_scale;
		const double sa = o.min_std_angle_deg * M_PI / 180.0;
		const double sr = o.min_std_range_m;
		const double span = br->maxSensorDistance > br->minSensorDistance
								? double(br->maxSensorDistance - br->minSensorDistance)
								: o.max_range_m;
		double ll = 0;
		for (const auto& m : br->sensedData)
		{
			const int i = indexOf(m.landmarkID);
			if (i < 0) continue;
			const Cached& lm = m_cache[static_cast<size_t>(i)];
			double range = 0, yaw = 0, pitch = 0;
			sensor.sphericalCoordinates(mrpt::math::TPoint3D(lm.x, lm.y, lm.z), range, yaw, pitch);
			Eigen::Matrix3d C;
			if (br->validCovariances)
				C = m.covariance.asEigen();
			else
				C = Eigen::Vector3d(
						double(br->sensor_std_range) * br->sensor_std_range,
						double(br->sensor_std_yaw) * br->sensor_std_yaw,
						double(br->sensor_std_pitch) * br->sensor_std_pitch)
						.asDiagonal();
			C *= k2;
			C(0, 0) += sr * sr;
			C(1, 1) += sa * sa;
			const Eigen::Vector3d r(
				m.range - range, wrapDiff(m.yaw - yaw), wrapDiff(m.pitch - pitch));
			double lg = 0;
			bool ok = false;
			double log_uniform = -std::log(span * kTwoPi);
			if (C(2, 2) > 0)
			{
				// A 3-D sensor: range, yaw and pitch.
				C(2, 2) += sa * sa;
				log_uniform -= std::log(M_PI);
				ok = logGauss<3>(r, C, lg);
			}
			else  // a planar sensor (no pitch uncertainty): range and yaw
				ok = logGauss<2>(
					Eigen::Vector2d(r.head<2>()), Eigen::Matrix2d(C.topLeftCorner<2, 2>()), lg);
			ll += ok ? logMixture(lg, log_uniform, o.outlier_probability) : log_uniform;
		}
		return ll;
	}
	return 0;  // other observations say nothing about this map
}

bool CCodedLandmarksMap::internal_canComputeObservationLikelihood(
	const mrpt::obs::CObservation& obs) const
{
	const auto* cls = obs.GetRuntimeClass();
	return cls == CLASS_ID(CObservationCodedLandmarks) ||
		   cls == CLASS_ID(mrpt::obs::CObservationBearingRange);
}

// --------------------------------------------------------- serialization
uint8_t CCodedLandmarksMap::serializeGetVersion() const { return 0; }

void CCodedLandmarksMap::serializeTo(mrpt::serialization::CArchive& out) const
{
	out << genericMapParams;
	const auto& o = likelihoodOptions;
	out << o.outlier_probability << o.sigma_scale << o.min_std_range_m << o.min_std_angle_deg
		<< o.max_range_m;
	out << static_cast<uint32_t>(m_map.landmarks.size());
	for (const auto& lm : m_map.landmarks)
		out << static_cast<int32_t>(lm.id) << lm.x_m << lm.y_m << lm.z_m << lm.yaw_rad << lm.scale;
}

void CCodedLandmarksMap::serializeFrom(mrpt::serialization::CArchive& in, uint8_t version)
{
	switch (version)
	{
		case 0:
		{
			in >> genericMapParams;
			auto& o = likelihoodOptions;
			in >> o.outlier_probability >> o.sigma_scale >> o.min_std_range_m >>
				o.min_std_angle_deg >> o.max_range_m;
			uint32_t n = 0;
			in >> n;
			if (n > kMaxLandmarks)
				THROW_EXCEPTION_FMT("CCodedLandmarksMap: corrupt stream (%u landmarks)", n);
			LandmarkMap map;
			map.landmarks.resize(n);
			for (auto& lm : map.landmarks)
			{
				int32_t id = 0;
				in >> id >> lm.x_m >> lm.y_m >> lm.z_m >> lm.yaw_rad >> lm.scale;
				lm.id = id;
			}
			setLandmarks(map);
		}
		break;
		default:
			MRPT_THROW_UNKNOWN_SERIALIZATION_VERSION(version);
	}
}

// ------------------------------------------------------- representation
void CCodedLandmarksMap::saveMetricMapRepresentationToFile(const std::string& prefix) const
{
	m_map.save(prefix + "_landmarks.txt");
}

void CCodedLandmarksMap::getVisualizationInto(mrpt::opengl::CSetOfObjects& o) const
{
	if (!genericMapParams.enableSaveAs3DObject) return;
	for (const auto& lm : m_map.landmarks)
	{
		const auto pose = lm.world_T_landmark();
		// The sheet: thin along X_L (the normal), A4 across (approximate:
		// centred on the green square).
		const double w = 0.21 * lm.scale, h = 0.297 * lm.scale;
		auto sheet = mrpt::opengl::CBox::Create(
			mrpt::math::TPoint3D(-0.005, -w / 2, -h / 2), mrpt::math::TPoint3D(0.0, w / 2, h / 2));
		sheet->setColor(0.1f, 0.6f, 0.2f, 0.8f);
		sheet->setPose(pose);
		o.insert(sheet);
		auto axes = mrpt::opengl::stock_objects::CornerXYZSimple(float(0.15 * lm.scale), 2.0f);
		axes->setPose(pose);
		o.insert(axes);
		auto label = mrpt::opengl::CText::Create(std::to_string(lm.id));
		label->setLocation(lm.x_m, lm.y_m, lm.z_m + h / 2 + 0.05);
		o.insert(label);
	}
}

std::string CCodedLandmarksMap::asString() const
{
	std::ostringstream s;
	s << "CCodedLandmarksMap: " << m_map.landmarks.size() << " coded landmarks";
	return s.str();
}

}  // namespace codemark
