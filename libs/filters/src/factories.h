#pragma once
// Internal: one factory per filter, defined beside each filter and called by
// makeLocalizer() (factory.cpp).
#include <codemark/filters/localizer.h>

namespace codemark::filters::detail
{
using Factory = std::unique_ptr<Localizer> (*)(
	const mrpt::config::CConfigFileBase& cfg, const LandmarkMap& map,
	const std::optional<PoseEstimate>& initial);

/** "ekf": CKalmanFilterCapable<3,3,0,3> updating with L and C_L (ekf_localization.cpp). */
std::unique_ptr<Localizer> makeEkf(
	const mrpt::config::CConfigFileBase&, const LandmarkMap&, const std::optional<PoseEstimate>&);
/** "ekf-pose": the paper's variant, the pose fix with C_R as a direct pose measurement
 * (ekf_pose.cpp). */
std::unique_ptr<Localizer> makeEkfPose(
	const mrpt::config::CConfigFileBase&, const LandmarkMap&, const std::optional<PoseEstimate>&);
/** "ekf-slam": CKalmanFilterCapable<3,3,3,3> (ekf_slam.cpp). */
std::unique_ptr<Localizer> makeEkfSlam(
	const mrpt::config::CConfigFileBase&, const LandmarkMap&, const std::optional<PoseEstimate>&);
/** "pf": CMonteCarloLocalization2D + CParticleFilter over the coded-landmark map
 * (particle_filter.cpp). */
std::unique_ptr<Localizer> makeParticleFilter(
	const mrpt::config::CConfigFileBase&, const LandmarkMap&, const std::optional<PoseEstimate>&);
}  // namespace codemark::filters::detail
