#include <codemark/landmark/primary.h>

namespace codemark
{
Eigen::Vector4d primaryMeasurementFromIdeal(
	const std::array<Eigen::Vector2d, 4>& c, const CameraModel& cam)
{
	// Pixels of the single focal length lambda = fx, relative to the
	// principal point.
	const double sy = cam.fx() / cam.fy();
	std::array<Eigen::Vector2d, 4> q;
	for (int i = 0; i < 4; ++i) q[i] = {c[i].x() - cam.cx(), (c[i].y() - cam.cy()) * sy};
	// Left edge: TL (0) - BL (3); right edge: TR (1) - BR (2).
	const double x1 = 0.5 * (q[0].x() + q[3].x());
	const double y1 = 0.5 * (q[0] - q[3]).norm();
	const double x2 = 0.5 * (q[1].x() + q[2].x());
	const double y2 = 0.5 * (q[1] - q[2]).norm();
	return {x1, y1, x2, y2};
}

Eigen::Vector4d primaryMeasurement(
	const std::array<Eigen::Vector2d, 4>& raw, const CameraModel& cam, double* lambda)
{
	std::array<Eigen::Vector2d, 4> ideal;
	for (int i = 0; i < 4; ++i) ideal[i] = cam.undistortPixel(raw[i]);
	if (lambda) *lambda = cam.fx();
	return primaryMeasurementFromIdeal(ideal, cam);
}

}  // namespace codemark
