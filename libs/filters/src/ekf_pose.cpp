// "ekf-pose": the paper's own fusion, each sighting's pose fix (the robot's
// world pose from pose_in_landmark, the landmark's map pose and the camera
// mounting, C_R propagated) as a direct measurement h(x) = x. The filter is
// the one of ekf_localization.cpp with EkfMeasurement::PoseFix.
#include <codemark/filters/ekf.h>

#include "factories.h"

namespace codemark::filters::detail
{
std::unique_ptr<Localizer> makeEkfPose(
	const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial)
{
	EkfOptions o;
	o.loadFromConfigFile(cfg, "ekf");
	return makeEkfLocalizer(EkfMeasurement::PoseFix, o, map, initial);
}
}  // namespace codemark::filters::detail
