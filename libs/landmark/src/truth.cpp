#include <codemark/landmark/truth.h>

#include <cmath>

namespace codemark
{
double wrapToPi(double a)
{
	a = std::fmod(a + M_PI, 2 * M_PI);
	if (a <= 0) a += 2 * M_PI;
	return a - M_PI;
}

SightingTruth sightingTruth(const mrpt::poses::CPose3D& landmark_T_camera)
{
	const auto& t = landmark_T_camera.translation();
	const auto R = landmark_T_camera.getRotationMatrix();
	// Optical axis (camera z) in frame L, projected on the horizontal plane.
	const double dx = R(0, 2), dy = R(1, 2);
	const double theta = std::atan2(dy, dx);
	const double phi2 = wrapToPi(theta - M_PI);
	SightingTruth out;
	out.pose_in_landmark = {t.x, t.y, wrapToPi(theta)};
	// The landmark centre is L's origin: seen from the camera along -t.
	out.L = {std::hypot(t.x, t.y), wrapToPi(std::atan2(t.y, t.x) - phi2), phi2};
	return out;
}

}  // namespace codemark
