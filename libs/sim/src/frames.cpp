#include <nlohmann/json.hpp>
#include <codemark/landmark/text.h>
#include <codemark/sim/frames.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "background.h"

namespace codemark::sim
{
namespace
{
const mrpt::poses::CPose3D& bodyToOptical()
{
	static const mrpt::poses::CPose3D p(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
	return p;
}
}  // namespace

mrpt::poses::CPose3D opticalFromBody(const mrpt::poses::CPose3D& world_T_body)
{
	return world_T_body + bodyToOptical();
}

mrpt::poses::CPose3D bodyFromOptical(const mrpt::poses::CPose3D& world_T_camera)
{
	return world_T_camera + (-bodyToOptical());
}

std::vector<mrpt::poses::CPose3D> viewpointsAroundLandmarks(
	const LandmarkMap& map, int count, uint64_t seed, const ViewpointOptions& vp)
{
	if (map.landmarks.empty()) throw std::invalid_argument("viewpoints: the map has no landmarks");
	if (!(vp.min_distance_m > 0 && vp.max_distance_m >= vp.min_distance_m &&
		  vp.max_view_angle_rad >= 0 && vp.max_view_angle_rad < M_PI / 2 &&
		  vp.max_bearing_rad >= 0))
		throw std::invalid_argument(
			"viewpoints: need 0 < min_distance <= max_distance, 0 <= view angle < 90 deg, bearing "
			">= 0");
	cv::RNG rng(detail::streamSeed(seed, 100));
	std::vector<mrpt::poses::CPose3D> poses;
	poses.reserve(count);
	for (int i = 0; i < count; ++i)
	{
		const MapLandmark& lm = map.landmarks[i % map.landmarks.size()];
		const double d = rng.uniform(vp.min_distance_m, vp.max_distance_m);
		const double a = rng.uniform(-vp.max_view_angle_rad, vp.max_view_angle_rad);
		const double b = rng.uniform(-vp.max_bearing_rad, vp.max_bearing_rad);
		poses.push_back(levelCameraLookingAt(lm, d, a, vp.camera_height_m - lm.z_m, b));
	}
	return poses;
}

std::vector<mrpt::poses::CPose3D> loadCameraPoses(const std::string& path)
{
	std::ifstream in(path);
	if (!in) throw std::runtime_error(path + ": cannot open camera poses file");
	std::vector<mrpt::poses::CPose3D> poses;
	std::string line;
	for (int n = 1; std::getline(in, line); ++n)
	{
		const std::vector<double> v = parseNumberRow(line, path, n);
		if (v.empty()) continue;
		if (v.size() != 6)
			throw std::runtime_error(
				path + ":" + std::to_string(n) +
				": expected 6 fields 'x y z yaw pitch roll' (m, deg), got " +
				std::to_string(v.size()));
		const double k = M_PI / 180;
		poses.push_back(
			opticalFromBody(mrpt::poses::CPose3D(v[0], v[1], v[2], v[3] * k, v[4] * k, v[5] * k)));
	}
	if (poses.empty()) throw std::runtime_error(path + ": no camera poses in file");
	return poses;
}

bool isInView(const LandmarkTruth& t, const CameraModel& cam)
{
	if (!t.in_front || !t.facing || !(t.area_px > 0)) return false;
	double minu = 1e300, maxu = -1e300, minv = 1e300, maxv = -1e300;
	for (const auto& c : t.corners_px)
	{
		if (!std::isfinite(c.x()) || !std::isfinite(c.y())) return false;
		minu = std::min(minu, c.x());
		maxu = std::max(maxu, c.x());
		minv = std::min(minv, c.y());
		maxv = std::max(maxv, c.y());
	}
	return maxu >= -0.5 && minu <= cam.width() - 0.5 && maxv >= -0.5 && minv <= cam.height() - 0.5;
}

namespace
{
std::string jsonString(const std::string& s)
{
	return nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

template <typename Vec>
void jsonArray(std::ostream& o, const Vec& v, int n)
{
	o << '[';
	for (int i = 0; i < n; ++i) o << (i ? ", " : "") << v[i];
	o << ']';
}
}  // namespace

std::string frameTruthJson(
	const std::string& image, const mrpt::poses::CPose3D& world_T_camera,
	const std::vector<LandmarkTruth>& truth, const CameraModel& cam)
{
	std::ostringstream o;
	o << std::setprecision(10);
	const mrpt::poses::CPose3D body = bodyFromOptical(world_T_camera);
	o << "{\"image\": " << jsonString(image) << ", \"width\": " << cam.width()
	  << ", \"height\": " << cam.height() << ", \"camera_pose\": [" << body.x() << ", " << body.y()
	  << ", " << body.z() << ", " << body.yaw() << ", " << body.pitch() << ", " << body.roll()
	  << "], \"landmarks\": [";
	bool first = true;
	for (const auto& t : truth)
	{
		if (!isInView(t, cam)) continue;
		o << (first ? "" : ", ") << "{\"id\": " << t.id << ", \"corners\": [";
		for (int i = 0; i < 4; ++i)
			o << (i ? ", " : "") << '[' << t.corners_px[i].x() << ", " << t.corners_px[i].y()
			  << ']';
		o << "], \"P\": ";
		jsonArray(o, t.P, 4);
		o << ", \"L\": ";
		jsonArray(o, t.sighting.L, 3);
		o << ", \"pose_in_landmark\": ";
		jsonArray(o, t.sighting.pose_in_landmark, 3);
		o << ", \"fully_visible\": " << (t.fully_visible ? "true" : "false")
		  << ", \"area_px\": " << t.area_px << ", \"occluded_fraction\": " << t.occluded_fraction
		  << '}';
		first = false;
	}
	o << "]}";
	return o.str();
}

}  // namespace codemark::sim
