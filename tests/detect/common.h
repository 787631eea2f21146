#pragma once
// Shared helpers of the detector tests: render one or more landmarks with
// codemark::sim and compare detections with the exact projections.
#include <codemark/detect/detector.h>
#include <codemark/landmark/codebook.h>
#include <codemark/sim/render.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace codemark::detect::test
{
constexpr double kDeg = M_PI / 180;

/** The nominal conditions that a range varies one at a time. */
inline sim::RenderOptions nominalRender()
{
	sim::RenderOptions o;
	o.background = sim::Background::Textured;
	o.noise_sigma = 2;
	o.blur_sigma_px = 0.8;
	return o;
}

struct Shot
{
	sim::Scene scene;
	sim::Render render;
};

/** One landmark \a id at the world origin (facing +x), seen by the paper's
 * camera from \a distance_m at \a angle_rad, the landmark \a bearing_rad
 * left of the optical axis, the camera \a height_m above its centre. */
inline Shot shoot(
	int id, double distance_m, double angle_rad, const sim::RenderOptions& o, uint64_t seed,
	double bearing_rad = 0, double height_m = 0)
{
	Shot s;
	MapLandmark lm;
	lm.id = id;
	s.scene.map.landmarks.push_back(lm);
	s.scene.world_T_camera =
		sim::levelCameraLookingAt(lm, distance_m, angle_rad, height_m, bearing_rad);
	s.render = sim::render(s.scene, o, seed);
	return s;
}

inline DetectionResult run(const cv::Mat& img, const std::string& debug_dir = {})
{
	return detect(img, CameraModel(), LandmarkGeometry(), DetectorOptions(), debug_dir);
}

/** Largest distance between detected and true corners [px]. */
inline double maxCornerError(const Detection& d, const sim::LandmarkTruth& t)
{
	double e = 0;
	for (int k = 0; k < 4; ++k) e = std::max(e, (d.corners[k] - t.corners_px[k]).norm());
	return e;
}

/** Paints a region of the landmark's face, given in face coordinates
 * (s right, t up) [m] as a quadrilateral, with \a colour (BGR), through the
 * homography of the true corners (no distortion). */
inline void paintFace(
	cv::Mat& img, const sim::LandmarkTruth& t, const LandmarkGeometry& g,
	const std::array<Eigen::Vector2d, 4>& face_pts, const cv::Scalar& colour)
{
	const double h = g.innerHalf();
	std::vector<cv::Point2f> src = {
		{float(-h), float(h)}, {float(h), float(h)}, {float(h), float(-h)}, {float(-h), float(-h)}};
	std::vector<cv::Point2f> dst;
	for (int k = 0; k < 4; ++k)
		dst.emplace_back(float(t.corners_ideal_px[k].x()), float(t.corners_ideal_px[k].y()));
	const cv::Mat H = cv::getPerspectiveTransform(src, dst);
	std::vector<cv::Point2f> in, out;
	for (const auto& p : face_pts) in.emplace_back(float(p.x()), float(p.y()));
	cv::perspectiveTransform(in, out, H);
	std::vector<cv::Point> poly;
	for (const auto& p : out) poly.emplace_back(cvRound(p.x * 16), cvRound(p.y * 16));
	cv::fillConvexPoly(img, poly, colour, cv::LINE_AA, 4);
}

/** Paints code cell (row, col) black or green. */
inline void paintCell(cv::Mat& img, const sim::LandmarkTruth& t, int row, int col, bool black)
{
	const LandmarkGeometry g;
	const Eigen::Vector2d c = g.cellCentreFace(row, col);
	const double a = 0.5 * g.cell_size_m;
	paintFace(
		img, t, g,
		{Eigen::Vector2d(c.x() - a, c.y() + a), Eigen::Vector2d(c.x() + a, c.y() + a),
		 Eigen::Vector2d(c.x() + a, c.y() - a), Eigen::Vector2d(c.x() - a, c.y() - a)},
		black ? cv::Scalar(25, 25, 25) : cv::Scalar(0, 255, 0));
}

}  // namespace codemark::detect::test
