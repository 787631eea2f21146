// makeLocalizer(): the method name to its filter's factory.
#include <stdexcept>

#include "factories.h"

namespace codemark::filters
{
std::unique_ptr<Localizer> makeLocalizer(
	const std::string& method, const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial)
{
	if (method == "ekf") return detail::makeEkf(cfg, map, initial);
	if (method == "ekf-pose") return detail::makeEkfPose(cfg, map, initial);
	if (method == "ekf-slam") return detail::makeEkfSlam(cfg, map, initial);
	if (method == "pf") return detail::makeParticleFilter(cfg, map, initial);
	throw std::invalid_argument(
		"unknown localization method '" + method + "' (expected ekf, ekf-pose, ekf-slam or pf)");
}
}  // namespace codemark::filters
