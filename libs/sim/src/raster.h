#pragma once
/** \file raster.h
 * Internal: exact area coverage of convex polygons on the pixel grid, and
 * clipping of 3-D polygons against the camera's near plane. Written by hand
 * because OpenCV's polygon fill (cv::fillConvexPoly, even with LINE_AA) is a
 * fixed-point scan converter accurate to about 1/16 px, far from the 0.02 px
 * the renderer promises.
 *
 * Pixel convention: pixel (u, v) is the unit square centred at (u, v).
 */
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>

#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>
#include <vector>

namespace codemark::sim::detail
{
/** A convex polygon in pixel coordinates, either orientation. */
using Polygon2 = std::vector<Eigen::Vector2d>;
/** A planar convex polygon in the camera optical frame [m]. */
using Polygon3 = std::vector<Eigen::Vector3d>;

/** Signed area (shoelace), positive when counter-clockwise in (x, y). */
double signedArea(const Polygon2& poly);

/** Area of the intersection of convex \a poly with the unit pixel square
 * centred at (u, v) [px^2]. */
double pixelCoverage(const Polygon2& poly, double u, double v);

/** Adds weight * (exact coverage of convex \a poly) to every pixel of
 * \a acc (CV_64FC1), whose pixel (0, 0) is image pixel \a origin. Pixels
 * wholly inside or outside take a fast path; only those that an edge crosses
 * are clipped (Sutherland-Hodgman against the pixel square). */
void accumulateCoverage(
	const Polygon2& poly, cv::Mat& acc, const cv::Point& origin, double weight = 1.0);

/** The part of \a poly with z >= \a z_min (Sutherland-Hodgman against one
 * plane); empty when nothing is left. */
Polygon3 clipNear(const Polygon3& poly, double z_min);

/** Pinhole projection (no distortion) of points with z > 0:
 * (fx x/z + cx, fy y/z + cy). */
Polygon2 projectPinhole(const Polygon3& poly, double fx, double fy, double cx, double cy);

/** A rigid transform as Eigen, for transforming many points: p_a = R p_b + t
 * for a_T_b. */
struct Rigid
{
	Eigen::Matrix3d R;
	Eigen::Vector3d t;
	Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return R * p + t; }
};

inline Rigid toRigid(const mrpt::poses::CPose3D& pose)
{
	Rigid r;
	const auto M = pose.getRotationMatrix();
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j) r.R(i, j) = M(i, j);
	r.t = {pose.x(), pose.y(), pose.z()};
	return r;
}

/** Pixel rectangle (inclusive) of the image that a set of points touches,
 * grown by \a grow px; empty when outside. */
inline cv::Rect pixelBounds(
	const std::vector<Eigen::Vector2d>& pts, int width, int height, int grow)
{
	double minx = 1e300, maxx = -1e300, miny = 1e300, maxy = -1e300;
	for (const auto& p : pts)
	{
		if (!p.allFinite()) continue;
		minx = std::min(minx, p.x());
		maxx = std::max(maxx, p.x());
		miny = std::min(miny, p.y());
		maxy = std::max(maxy, p.y());
	}
	// Clamp in double before converting: points near the near plane project
	// far outside the image.
	const double x0 = std::clamp(std::floor(minx) - grow, 0.0, double(width));
	const double x1 = std::clamp(std::ceil(maxx) + grow, -1.0, double(width - 1));
	const double y0 = std::clamp(std::floor(miny) - grow, 0.0, double(height));
	const double y1 = std::clamp(std::ceil(maxy) + grow, -1.0, double(height - 1));
	if (x1 < x0 || y1 < y0) return {};
	return cv::Rect(int(x0), int(y0), int(x1 - x0) + 1, int(y1 - y0) + 1);
}

}  // namespace codemark::sim::detail
