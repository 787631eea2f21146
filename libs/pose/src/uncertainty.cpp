#include <codemark/landmark/truth.h>
#include <codemark/pose/uncertainty.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace codemark::pose
{
namespace
{

std::string fmt(double v, int prec)
{
	std::ostringstream s;
	s << std::fixed << std::setprecision(prec) << v;
	return s.str();
}
}  // namespace

PoseOptions constantNoise(double sigma_px)
{
	PoseOptions o;
	o.sigma_px = sigma_px;
	return o;
}

SightingUncertainty predictUncertainty(
	const CameraModel& camera, const LandmarkGeometry& g, double sigma_px, double d, double angle,
	double bearing, double height)
{
	return predictUncertainty(camera, g, constantNoise(sigma_px), d, angle, bearing, height);
}

SightingUncertainty predictUncertainty(
	const CameraModel& camera, const LandmarkGeometry& g, const PoseOptions& noise, double d,
	double angle, double bearing, double height)
{
	using mrpt::poses::CPose3D;
	SightingUncertainty out;
	const CPose3D landmark_T_camera =
		CPose3D(d * std::cos(angle), d * std::sin(angle), height, angle + M_PI - bearing, 0, 0) +
		CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
	const CPose3D camera_T_landmark = -landmark_T_camera;
	const auto toCamera = [&](const Eigen::Vector3d& p)
	{
		mrpt::math::TPoint3D q;
		camera_T_landmark.composePoint(mrpt::math::TPoint3D(p.x(), p.y(), p.z()), q);
		return Eigen::Vector3d(q.x, q.y, q.z);
	};
	const double H = g.outerHalf();
	bool in_image = true;
	for (const auto& st :
		 {Eigen::Vector2d(-H, H), Eigen::Vector2d(H, H), Eigen::Vector2d(H, -H),
		  Eigen::Vector2d(-H, -H)})
	{
		const auto px = camera.project(toCamera(LandmarkGeometry::faceToLandmark(st.x(), st.y())));
		if (!px) return out;
		in_image = in_image && px->x() >= -0.5 && px->y() >= -0.5 &&
				   px->x() <= camera.width() - 0.5 && px->y() <= camera.height() - 0.5;
	}
	if (!(landmark_T_camera.x() > 0)) return out;
	std::array<Eigen::Vector2d, 4> corners;
	const auto ref = g.referencePoints();
	for (int i = 0; i < 4; ++i)
	{
		const Eigen::Vector3d pc = toCamera(ref[i]);
		corners[i] = camera.distortNormalized({pc.x() / pc.z(), pc.y() / pc.z()});
	}
	out.measurement = measure(corners, camera, g, noise);
	out.in_image = in_image;
	const Measurement& m = out.measurement;
	out.size_px = 2 * std::min(m.P[1], m.P[3]);
	out.sigma_l2_m = std::sqrt(m.C_L(0, 0));
	out.sigma_phi1_rad = std::sqrt(m.C_L(1, 1));
	out.sigma_phi2_rad = std::sqrt(m.C_L(2, 2));
	const Eigen::Matrix2d Cxy = m.C_R.topLeftCorner<2, 2>();
	out.sigma_position_m = std::sqrt(
		std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(Cxy).eigenvalues()[1]));
	out.sigma_heading_rad = std::sqrt(m.C_R(2, 2));
	return out;
}

SizeAdvice sizeFor(
	const CameraModel& camera, double sigma_px, double position_m, double heading_rad,
	double distance_m, double angle, double k, double min_size_px)
{
	if (!(sigma_px > 0)) throw std::invalid_argument("sizeFor: sigma_px must be > 0");
	return sizeFor(
		camera, constantNoise(sigma_px), position_m, heading_rad, distance_m, angle, k,
		min_size_px);
}

SizeAdvice sizeFor(
	const CameraModel& camera, const PoseOptions& noise, double position_m, double heading_rad,
	double distance_m, double angle, double k, double min_size_px)
{
	if (!(position_m > 0) || !(heading_rad > 0) || !(distance_m > 0) || !(k > 0))
		throw std::invalid_argument("sizeFor: accuracies, distance and k_sigma must be > 0");
	const auto at = [&](double s)
	{ return predictUncertainty(camera, LandmarkGeometry::scaled(s), noise, distance_m, angle); };
	const auto accurate = [&](const SightingUncertainty& u)
	{ return k * u.sigma_position_m <= position_m && k * u.sigma_heading_rad <= heading_rad; };
	const auto ok = [&](const SightingUncertainty& u)
	{ return u.in_image && u.size_px >= min_size_px && accurate(u); };
	SizeAdvice out;
	// The largest scale that still fits in the image.
	double lo = 1e-3, hi = 1.0;
	if (!at(lo).in_image)
	{
		out.reason = "the landmark is not in the image at this distance and angle";
		return out;
	}
	while (at(hi).in_image && hi < 1e4) hi *= 2;
	for (int i = 0; i < 60; ++i)
	{
		const double mid = std::sqrt(lo * hi);
		(at(mid).in_image ? lo : hi) = mid;
	}
	const double s_max = lo;
	const SightingUncertainty best = at(s_max);
	if (!ok(best))
	{
		std::ostringstream s;
		s << "even the largest landmark that fits in the image (scale " << fmt(s_max, 2)
		  << ", outer frame " << fmt(0.2 * s_max, 3) << " m) gives " << fmt(k, 1)
		  << " sigma = " << fmt(k * best.sigma_position_m * 1000, 1) << " mm and "
		  << fmt(k * best.sigma_heading_rad * 180 / M_PI, 2) << " deg";
		out.reason = s.str();
		out.scale = s_max;
		out.at = best;
		return out;
	}
	// The smallest scale that meets every requirement.
	lo = 1e-3;
	hi = s_max;
	for (int i = 0; i < 60; ++i)
	{
		const double mid = std::sqrt(lo * hi);
		(ok(at(mid)) ? hi : lo) = mid;
	}
	out.found = true;
	out.scale = hi;
	out.at = at(hi);
	const SightingUncertainty below = at(hi * 0.999);
	if (below.size_px < min_size_px && accurate(below))
		out.reason = "set by the detector's minimum size (" + fmt(min_size_px, 0) + " px)";
	else if (k * below.sigma_position_m > position_m)
		out.reason = "set by the position accuracy";
	else
		out.reason = "set by the heading accuracy";
	return out;
}

}  // namespace codemark::pose
