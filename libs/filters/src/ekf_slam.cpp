// Placeholder so that makeLocalizer() links while EKF-SLAM is written.
#include "factories.h"

#include <stdexcept>

namespace codemark::filters::detail
{
std::unique_ptr<Localizer> makeEkfSlam(
	const mrpt::config::CConfigFileBase&, const LandmarkMap&, const std::optional<PoseEstimate>&)
{
	throw std::invalid_argument("ekf-slam: not implemented yet");
}
}  // namespace codemark::filters::detail
