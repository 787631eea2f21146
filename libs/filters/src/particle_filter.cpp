// Particle filter localizer (work in progress: first a linkable factory).
#include "factories.h"

#include <stdexcept>

namespace codemark::filters::detail
{
std::unique_ptr<Localizer> makeParticleFilter(
	const mrpt::config::CConfigFileBase&, const LandmarkMap&, const std::optional<PoseEstimate>&)
{
	throw std::invalid_argument("method 'pf': the particle filter is not built yet");
}
}  // namespace codemark::filters::detail
