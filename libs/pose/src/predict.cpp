#include <codemark/landmark/primary.h>
#include <codemark/landmark/truth.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pose/predict.h>
#include <mrpt/config/CConfigFileBase.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace codemark::pose
{
void VisibilityOptions::loadFromConfigFile(
	const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	MRPT_LOAD_CONFIG_VAR(max_range_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(max_view_angle_deg, double, c, s);
	MRPT_LOAD_CONFIG_VAR(min_size_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(image_margin_px, double, c, s);
	ASSERT_(max_range_m > 0 && max_view_angle_deg > 0 && max_view_angle_deg <= 90);
	ASSERT_(min_size_px >= 0 && image_margin_px >= 0);
}

void VisibilityOptions::saveToConfigFile(
	mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	c.write(s, "max_range_m", max_range_m, -1, -1, "maximum horizontal distance [m]");
	c.write(
		s, "max_view_angle_deg", max_view_angle_deg, -1, -1,
		"maximum angle of view from the normal [deg]");
	c.write(
		s, "min_size_px", min_size_px, -1, -1,
		"minimum vertical size of the reference square [px]");
	c.write(
		s, "image_margin_px", image_margin_px, -1, -1,
		"outer frame this far inside the image [px]");
}

mrpt::poses::CPose3D worldTCamera(
	const mrpt::poses::CPose2D& world_T_robot, const mrpt::poses::CPose3D& robot_T_camera)
{
	return mrpt::poses::CPose3D(
			   world_T_robot.x(), world_T_robot.y(), 0, world_T_robot.phi(), 0, 0) +
		   robot_T_camera;
}

Eigen::Matrix3d fuseCovariance(const Eigen::Matrix3d& prior, const Eigen::Matrix3d& C_fix)
{
	const Eigen::Matrix3d K = prior * (prior + C_fix).inverse();
	const Eigen::Matrix3d post = (Eigen::Matrix3d::Identity() - K) * prior;
	return 0.5 * (post + post.transpose());
}

Prediction predictSighting(
	const mrpt::poses::CPose2D& world_T_robot, const Eigen::Matrix3d& robot_cov,
	const mrpt::poses::CPose3D& robot_T_camera, const CameraModel& camera,
	const MapLandmark& landmark, const PoseOptions& options, const VisibilityOptions& vis)
{
	Prediction pr;
	pr.id = landmark.id;
	const LandmarkGeometry g = landmark.geometry();
	const mrpt::poses::CPose3D world_T_landmark = landmark.world_T_landmark();
	const mrpt::poses::CPose3D landmark_T_camera =
		worldTCamera(world_T_robot, robot_T_camera) - world_T_landmark;
	const mrpt::poses::CPose3D camera_T_landmark = -landmark_T_camera;

	const auto toCamera = [&](const Eigen::Vector3d& pL)
	{
		mrpt::math::TPoint3D q;
		camera_T_landmark.composePoint(mrpt::math::TPoint3D(pL.x(), pL.y(), pL.z()), q);
		return Eigen::Vector3d(q.x, q.y, q.z);
	};

	// Facing and view angle from the camera's position in L.
	const auto& t = landmark_T_camera.translation();
	pr.facing = t.x > 0;
	pr.view_angle_rad = std::atan2(t.y, t.x);
	pr.angle_ok = std::abs(pr.view_angle_rad) <= vis.max_view_angle_deg * M_PI / 180.0;
	pr.in_range = std::hypot(t.x, t.y) <= vis.max_range_m;

	// In front / field of view from the outer frame corners.
	const double H = g.outerHalf();
	pr.in_front = true;
	pr.in_fov = true;
	for (const auto& st :
		 {Eigen::Vector2d(-H, H), Eigen::Vector2d(H, H), Eigen::Vector2d(H, -H),
		  Eigen::Vector2d(-H, -H)})
	{
		const auto px = camera.project(toCamera(LandmarkGeometry::faceToLandmark(st.x(), st.y())));
		if (!px)
		{
			pr.in_front = false;
			pr.in_fov = false;
			continue;
		}
		const double m = vis.image_margin_px;
		if (px->x() < -0.5 + m || px->y() < -0.5 + m || px->x() > camera.width() - 0.5 - m ||
			px->y() > camera.height() - 0.5 - m)
			pr.in_fov = false;
	}
	if (!pr.in_front || !pr.facing) return pr;

	const auto ref = g.referencePoints();
	for (int i = 0; i < 4; ++i)
	{
		const Eigen::Vector3d pc = toCamera(ref[i]);
		// Exact pinhole + distortion, also outside the image (for the numbers).
		pr.corners_px[i] = camera.distortNormalized({pc.x() / pc.z(), pc.y() / pc.z()});
	}
	// The measurement the closed form would give from these exact corners,
	// with the options' C_P (and refinement, C_R order): measure() itself.
	PoseOptions closed_form = options;
	closed_form.method = PoseMethod::ClosedForm;
	pr.measurement = measure(pr.corners_px, camera, g, closed_form);
	const Measurement& m = pr.measurement;
	pr.size_px = 2 * std::min(m.P[1], m.P[3]);
	pr.big_enough = pr.size_px >= vis.min_size_px;

	robotPoseInWorld(
		m.pose_in_landmark, m.C_R, landmarkPlanarPose(world_T_landmark),
		cameraPlanarPose(robot_T_camera), &pr.C_fix_world);
	pr.posterior = fuseCovariance(robot_cov, pr.C_fix_world);
	pr.score = pr.posterior(0, 0) + pr.posterior(1, 1);
	return pr;
}

std::vector<Prediction> rankLandmarks(
	const mrpt::poses::CPose2D& world_T_robot, const Eigen::Matrix3d& robot_cov,
	const mrpt::poses::CPose3D& robot_T_camera, const CameraModel& camera, const LandmarkMap& map,
	const PoseOptions& options, const VisibilityOptions& vis)
{
	std::vector<Prediction> out;
	for (const auto& lm : map.landmarks)
	{
		Prediction p =
			predictSighting(world_T_robot, robot_cov, robot_T_camera, camera, lm, options, vis);
		if (p.visible()) out.push_back(std::move(p));
	}
	std::stable_sort(
		out.begin(), out.end(),
		[](const Prediction& a, const Prediction& b) { return a.score < b.score; });
	return out;
}

}  // namespace codemark::pose
