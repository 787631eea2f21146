// makeLocalizer(): the method name to its filter's factory.
#include <mrpt/core/bits_math.h>

#include <Eigen/Core>

#include <algorithm>
#include <stdexcept>

#include "factories.h"

namespace codemark::filters
{
const std::vector<std::string>& localizationMethods()
{
	static const std::vector<std::string> m{"ekf", "ekf-pose", "ekf-slam", "pf"};
	return m;
}

void requireLocalizationMethod(const std::string& method)
{
	const auto& m = localizationMethods();
	if (std::find(m.begin(), m.end(), method) == m.end())
		throw std::invalid_argument(
			"unknown localization method '" + method +
			"' (expected ekf, ekf-pose, ekf-slam or pf)");
}

std::unique_ptr<Localizer> makeLocalizer(
	const std::string& method, const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial)
{
	requireLocalizationMethod(method);
	if (method == "ekf") return detail::makeEkf(cfg, map, initial);
	if (method == "ekf-pose") return detail::makeEkfPose(cfg, map, initial);
	if (method == "ekf-slam") return detail::makeEkfSlam(cfg, map, initial);
	if (method == "pf") return detail::makeParticleFilter(cfg, map, initial);
	throw std::logic_error("makeLocalizer: no factory for method '" + method + "'");
}

std::optional<PoseEstimate> initialPose(const mrpt::config::CConfigFileBase& cfg)
{
	if (!cfg.read_bool("localize", "initial_pose_known", false)) return std::nullopt;
	PoseEstimate e;
	e.initialized = true;
	e.mean = mrpt::poses::CPose2D(
		cfg.read_double("localize", "initial_x", 0), cfg.read_double("localize", "initial_y", 0),
		mrpt::DEG2RAD(cfg.read_double("localize", "initial_yaw_deg", 0)));
	const double sxy = cfg.read_double("localize", "initial_std_xy", 0.1);
	const double syaw = mrpt::DEG2RAD(cfg.read_double("localize", "initial_std_yaw_deg", 5.0));
	if (!(sxy > 0) || !(syaw > 0))
		throw std::invalid_argument(
			"[localize] initial_std_xy and initial_std_yaw_deg must be > 0");
	e.cov = Eigen::Vector3d(sxy * sxy, sxy * sxy, syaw * syaw).asDiagonal();
	return e;
}
}  // namespace codemark::filters
