#pragma once
// Helpers shared by the pose tests: exact corner projections (no renderer).
#include <codemark/landmark/camera.h>
#include <codemark/landmark/geometry.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <stdexcept>

namespace codemark::test
{
/** A level camera (optical axis horizontal) at (x, y, z) of a frame whose
 * optical axis has heading \a heading there (MRPT optical frame). */
inline mrpt::poses::CPose3D levelCamera(double x, double y, double z, double heading)
{
	return mrpt::poses::CPose3D(x, y, z, heading, 0, 0) +
		   mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
}

/** A camera at distance \a d from the landmark centre, on the line of sight
 * at \a view_angle from the outward normal (CCW), at height \a z relative to
 * the centre, turned so that the centre appears \a phi1 left of the axis. */
inline mrpt::poses::CPose3D cameraAt(double d, double view_angle, double z = 0, double phi1 = 0)
{
	return levelCamera(
		d * std::cos(view_angle), d * std::sin(view_angle), z, view_angle + M_PI - phi1);
}

/** Exact raw-pixel projections of the reference points (TL TR BR BL). */
inline std::array<Eigen::Vector2d, 4> projectCorners(
	const mrpt::poses::CPose3D& landmark_T_camera, const CameraModel& camera,
	const LandmarkGeometry& geometry)
{
	const mrpt::poses::CPose3D camera_T_landmark = -landmark_T_camera;
	std::array<Eigen::Vector2d, 4> out;
	const auto ref = geometry.referencePoints();
	for (int i = 0; i < 4; ++i)
	{
		mrpt::math::TPoint3D q;
		camera_T_landmark.composePoint(mrpt::math::TPoint3D(ref[i].x(), ref[i].y(), ref[i].z()), q);
		const auto px = camera.project(Eigen::Vector3d(q.x, q.y, q.z));
		if (!px) throw std::runtime_error("projectCorners: corner behind the camera");
		out[i] = *px;
	}
	return out;
}

}  // namespace codemark::test
