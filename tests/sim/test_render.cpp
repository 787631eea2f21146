#include <codemark/landmark/codebook.h>
#include <codemark/landmark/primary.h>
#include <codemark/sim/render.h>
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "raster.h"

using namespace codemark;
using namespace codemark::sim;
using mrpt::poses::CPose3D;

namespace
{
constexpr double kDeg = M_PI / 180;

MapLandmark makeLandmark(int id = 37, double scale = 1.0)
{
	MapLandmark lm;
	lm.id = id;
	lm.x_m = 2.0;
	lm.y_m = 1.0;
	lm.z_m = 0.6;
	lm.yaw_rad = 0.7;
	lm.scale = scale;
	return lm;
}

Scene makeScene(
	const MapLandmark& lm, const CPose3D& world_T_camera, const CameraModel& cam = CameraModel())
{
	Scene s;
	s.map.landmarks.push_back(lm);
	s.camera = cam;
	s.world_T_camera = world_T_camera;
	return s;
}

/** Options whose only edges in the green channel are the inner frame edges
 * and the code board: everything outside the reference square is as dark as
 * the printed black, so the area identity applies across the whole window. */
RenderOptions edgeOptions()
{
	RenderOptions o;
	o.background_grey = 25;
	o.black_bgr = o.white_bgr = cv::Scalar(25, 25, 25);
	o.green_bgr = cv::Scalar(0, 255, 0);
	return o;
}

/** Green fraction (G - 25) / (255 - 25) of every pixel, CV_64F. */
cv::Mat greenFraction(const cv::Mat& bgr)
{
	cv::Mat g;
	cv::extractChannel(bgr, g, 1);
	g.convertTo(g, CV_64F, 1.0 / 230, -25.0 / 230);
	return g;
}

/** Raw pixel of the face point (s right, t up) [m]. */
Eigen::Vector2d facePixel(const LandmarkTruth& tr, const CameraModel& cam, double s, double t)
{
	const auto p = tr.landmark_T_camera.inverseComposePoint(mrpt::math::TPoint3D(0, s, t));
	const auto px = cam.project({p.x, p.y, p.z});
	return px ? *px : Eigen::Vector2d(NAN, NAN);
}

/** A straight image line through a and b. */
struct Line
{
	Eigen::Vector2d a, b;
	double xAt(double y) const { return a.x() + (b.x() - a.x()) * (y - a.y()) / (b.y() - a.y()); }
	double yAt(double x) const { return a.y() + (b.y() - a.y()) * (x - a.x()) / (b.x() - a.x()); }
	double dxdy() const { return (b.x() - a.x()) / (b.y() - a.y()); }
	Line swapped() const { return {{a.y(), a.x()}, {b.y(), b.x()}}; }
};

/** Measures a mostly vertical dark/green edge row by row with the area
 * identity: over a row window whose end pixels are pure, the sum of the
 * green fractions equals the distance from the window's green end to the
 * edge. \a board is the far boundary of the green strip (the code board),
 * \a perp1/\a perp2 the perpendicular inner edges (rows must stay clear of
 * them over the whole window). Returns measured - true edge x, per row. */
std::vector<double> rowEdgeErrors(
	const cv::Mat& g, const Line& edge, const Line& board, const Line& perp1, const Line& perp2,
	bool green_right)
{
	std::vector<double> errs;
	const double m = 0.5 * std::abs(edge.dxdy()) + 1e-9, mb = 0.5 * std::abs(board.dxdy()) + 1e-9;
	const int v0 = static_cast<int>(std::ceil(std::min(edge.a.y(), edge.b.y())));
	const int v1 = static_cast<int>(std::floor(std::max(edge.a.y(), edge.b.y())));
	for (int v = std::max(v0, 0); v <= std::min(v1, g.rows - 1); ++v)
	{
		const double e = edge.xAt(v), xb = board.xAt(v);
		int ua, ub;
		if (green_right)
		{
			ua = static_cast<int>(std::floor(e - m - 0.5)) - 2;
			ub = static_cast<int>(std::floor(xb - mb - 0.5));
			if (ub - 0.5 < e + m) continue;
		}
		else
		{
			ua = static_cast<int>(std::ceil(xb + mb + 0.5));
			ub = static_cast<int>(std::ceil(e + m + 0.5)) + 2;
			if (ua + 0.5 > e - m) continue;
		}
		if (ua < 0 || ub >= g.cols) continue;
		// The row band [v - 0.5, v + 0.5] must lie between the perpendicular
		// edges over the whole window.
		const double l = ua - 0.5, r = ub + 0.5;
		const bool p1_first = perp1.yAt(0.5 * (l + r)) < perp2.yAt(0.5 * (l + r));
		const Line& upper = p1_first ? perp1 : perp2;
		const Line& lower = p1_first ? perp2 : perp1;
		if (!(v - 1.0 > std::max(upper.yAt(l), upper.yAt(r)) &&
			  v + 1.0 < std::min(lower.yAt(l), lower.yAt(r))))
			continue;
		double sum = 0;
		for (int u = ua; u <= ub; ++u) sum += g.at<double>(v, u);
		const double measured = green_right ? ub + 0.5 - sum : ua - 0.5 + sum;
		errs.push_back(measured - e);
	}
	return errs;
}

double maxAbs(const std::vector<double>& v)
{
	double m = 0;
	for (double x : v) m = std::max(m, std::abs(x));
	return m;
}

/** Errors of the four inner edges (left, right, top, bottom) of \a tr in the
 * green fraction image \a g, no distortion. */
std::array<std::vector<double>, 4> innerEdgeErrors(
	const cv::Mat& g, const LandmarkTruth& tr, const CameraModel& cam, double cell)
{
	const auto& c = tr.corners_ideal_px;
	const double b = 1.5 * cell;
	const Line left{c[0], c[3]}, right{c[1], c[2]}, top{c[0], c[1]}, bottom{c[3], c[2]};
	const Line board_left{facePixel(tr, cam, -b, b), facePixel(tr, cam, -b, -b)};
	const Line board_right{facePixel(tr, cam, b, b), facePixel(tr, cam, b, -b)};
	const Line board_top{facePixel(tr, cam, -b, b), facePixel(tr, cam, b, b)};
	const Line board_bottom{facePixel(tr, cam, -b, -b), facePixel(tr, cam, b, -b)};
	cv::Mat gt;
	cv::transpose(g, gt);
	return {
		rowEdgeErrors(g, left, board_left, top, bottom, true),
		rowEdgeErrors(g, right, board_right, top, bottom, false),
		rowEdgeErrors(
			gt, top.swapped(), board_top.swapped(), left.swapped(), right.swapped(), true),
		rowEdgeErrors(
			gt, bottom.swapped(), board_bottom.swapped(), left.swapped(), right.swapped(), false)};
}
}  // namespace

TEST(Raster, PixelCoverageOfKnownShapes)
{
	using detail::pixelCoverage;
	// A half-plane x <= 10.3 over pixel 10 (spans 9.5..10.5): 0.8.
	const detail::Polygon2 big{{-100, -100}, {10.3, -100}, {10.3, 100}, {-100, 100}};
	EXPECT_NEAR(pixelCoverage(big, 10, 0), 0.8, 1e-12);
	EXPECT_NEAR(pixelCoverage(big, 12, 0), 0.0, 1e-12);
	EXPECT_NEAR(pixelCoverage(big, 3, 0), 1.0, 1e-12);
	// A triangle cutting a pixel corner: legs 0.5 -> area 0.125.
	const detail::Polygon2 tri{{0.5, 0.5}, {0.0, 0.5}, {0.5, 0.0}};
	EXPECT_NEAR(pixelCoverage(tri, 0, 0), 0.125, 1e-12);
	// The total coverage of any convex polygon is its area.
	const detail::Polygon2 quad{{3.3, 2.7}, {17.9, 5.1}, {15.2, 19.6}, {1.1, 12.4}};
	cv::Mat acc = cv::Mat::zeros(30, 30, CV_64F);
	detail::accumulateCoverage(quad, acc, {0, 0});
	EXPECT_NEAR(cv::sum(acc)[0], std::abs(detail::signedArea(quad)), 1e-9);
}

TEST(Raster, ClipNearKeepsTheFrontPart)
{
	const detail::Polygon3 sq{{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
	const auto c = detail::clipNear(sq, 0.5);
	ASSERT_EQ(c.size(), 4u);
	for (const auto& p : c) EXPECT_GE(p.z(), 0.5 - 1e-12);
	EXPECT_TRUE(detail::clipNear(sq, 2.0).empty());
}

TEST(Render, EdgesWithinTwoHundredthsOfAPixel)
{
	const MapLandmark lm = makeLandmark();
	const CameraModel cam;
	const RenderOptions o = edgeOptions();
	double worst = 0;
	int configs = 0;
	for (double d : {0.5, 1.0, 2.0, 3.5, 5.0})
		for (double a_deg : {0.0, 15.0, -30.0, 45.0, -60.0, 60.0})
		{
			const double a = a_deg * kDeg;
			// Alternate a roll about the optical axis so edges are slanted
			// in the image, not only vertical.
			const double roll = (configs % 2) ? 0.15 : 0.0;
			const CPose3D pose =
				levelCameraLookingAt(lm, d, a, 0.05 * d, 0.03) + CPose3D(0, 0, 0, roll, 0, 0);
			const Scene scene = makeScene(lm, pose, cam);
			const Render r = render(scene, o, 1);
			const LandmarkTruth& tr = r.truth[0];
			// The reference square must be in the image (at 0.5 m and 60 deg
			// the outer frame is not entirely).
			for (const auto& c : tr.corners_px)
				ASSERT_TRUE(c.x() > 4 && c.x() < 635 && c.y() > 4 && c.y() < 475)
					<< "d " << d << " a " << a_deg << " corner " << c.transpose();
			const auto errs =
				innerEdgeErrors(greenFraction(r.image), tr, cam, lm.geometry().cell_size_m);
			const char* names[] = {"left", "right", "top", "bottom"};
			for (int e = 0; e < 4; ++e)
			{
				EXPECT_GE(errs[e].size(), 3u) << names[e] << " edge, d " << d << " a " << a_deg;
				EXPECT_LT(maxAbs(errs[e]), 0.02) << names[e] << " edge, d " << d << " a " << a_deg;
				worst = std::max(worst, maxAbs(errs[e]));
			}
			++configs;
		}
	RecordProperty("worst_edge_error_px", std::to_string(worst));
	std::cout << "worst edge error over " << configs << " views: " << worst << " px\n";
}

TEST(Render, CodeCellsWhereEncodeIdSays)
{
	for (const Background bg : {Background::Flat, Background::Cluttered})
		for (int id : {0, 37, 170, 201, 255})
		{
			const MapLandmark lm = makeLandmark(id);
			RenderOptions o;
			o.background = bg;
			o.distractors = 40;	 // drawn under the landmark, never over it
			const Scene scene = makeScene(lm, levelCameraLookingAt(lm, 1.2, 25 * kDeg, 0.1, -0.05));
			const Render r = render(scene, o, 7 + id);
			const LandmarkGeometry g = lm.geometry();
			CodeCells seen{};
			for (int row = 0; row < 3; ++row)
				for (int col = 0; col < 3; ++col)
				{
					const Eigen::Vector2d f = g.cellCentreFace(row, col);
					const Eigen::Vector2d px = facePixel(r.truth[0], scene.camera, f.x(), f.y());
					const cv::Vec3b v =
						r.image.at<cv::Vec3b>(int(std::lround(px.y())), int(std::lround(px.x())));
					EXPECT_TRUE(v[1] < 60 || v[1] > 200)
						<< "cell " << row << col << " G " << int(v[1]);
					seen[row][col] = v[1] < 128;
				}
			EXPECT_EQ(seen, encodeId(id)) << "id " << id;
			EXPECT_EQ(decodeCells(seen), std::optional<int>(id));
		}
}

TEST(Render, DeterministicForASeed)
{
	const MapLandmark lm = makeLandmark();
	RenderOptions o;
	o.background = Background::Cluttered;
	o.distractors = 12;
	o.noise_sigma = 3;
	o.blur_sigma_px = 0.8;
	o.motion_blur_px = 2;
	o.gradient = 0.3;
	o.jpeg_quality = 80;
	o.occlusion = 0.2;
	const Scene scene = makeScene(lm, levelCameraLookingAt(lm, 1.5, 20 * kDeg));
	const Render a = render(scene, o, 11), b = render(scene, o, 11), c = render(scene, o, 12);
	EXPECT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0.0);
	EXPECT_GT(cv::norm(a.image, c.image, cv::NORM_L1), 0.0);
}

TEST(Render, TruthMatchesTheScene)
{
	const MapLandmark lm = makeLandmark();
	const CameraModel cam;
	for (double d : {0.8, 2.5})
		for (double a : {-0.6, 0.0, 0.4})
			for (double bearing : {-0.1, 0.0, 0.2})
			{
				const double height = 0.12;
				const CPose3D pose = levelCameraLookingAt(lm, d, a, height, bearing);
				EXPECT_NEAR(pose.z(), lm.z_m + height, 1e-12);
				const Scene scene = makeScene(lm, pose, cam);
				const LandmarkTruth tr = render(scene, RenderOptions(), 1).truth[0];
				EXPECT_EQ(tr.id, lm.id);
				EXPECT_TRUE(tr.in_front);
				EXPECT_TRUE(tr.facing);
				// L = (horizontal distance, bearing, view angle - bearing):
				// phi1 + phi2 is the direction of the camera seen from L.
				EXPECT_NEAR(tr.sighting.L[0], d, 1e-9);
				EXPECT_NEAR(tr.sighting.L[1], bearing, 1e-9);
				EXPECT_NEAR(tr.sighting.L[2], a - bearing, 1e-9);
				EXPECT_NEAR(tr.sighting.pose_in_landmark[0], d * std::cos(a), 1e-9);
				EXPECT_NEAR(tr.sighting.pose_in_landmark[1], d * std::sin(a), 1e-9);
				EXPECT_NEAR(
					std::atan2(tr.sighting.pose_in_landmark[1], tr.sighting.pose_in_landmark[0]),
					tr.sighting.L[1] + tr.sighting.L[2], 1e-9);
				EXPECT_NEAR(tr.landmark_T_camera.z(), height, 1e-9);
				// Corners: the camera model on the reference points.
				const auto ref = lm.geometry().referencePoints();
				for (int i = 0; i < 4; ++i)
				{
					const auto p = tr.landmark_T_camera.inverseComposePoint(
						mrpt::math::TPoint3D(ref[i].x(), ref[i].y(), ref[i].z()));
					const auto px = cam.project({p.x, p.y, p.z});
					ASSERT_TRUE(px.has_value());
					EXPECT_NEAR((tr.corners_px[i] - *px).norm(), 0.0, 1e-9);
					EXPECT_NEAR((tr.corners_ideal_px[i] - *px).norm(), 0.0, 1e-9);
				}
				// TL left of TR and above BL in the image.
				EXPECT_LT(tr.corners_px[0].x(), tr.corners_px[1].x());
				EXPECT_LT(tr.corners_px[0].y(), tr.corners_px[3].y());
				const Eigen::Vector4d P = primaryMeasurementFromIdeal(tr.corners_ideal_px, cam);
				EXPECT_NEAR((tr.P - P).norm(), 0.0, 1e-12);
				// The reference square's image area, against the same area
				// from the inner edges' lengths: a rough independent check.
				const double w = 0.5 * ((tr.corners_px[1] - tr.corners_px[0]).norm() +
										(tr.corners_px[2] - tr.corners_px[3]).norm());
				const double h = 0.5 * ((tr.corners_px[3] - tr.corners_px[0]).norm() +
										(tr.corners_px[2] - tr.corners_px[1]).norm());
				EXPECT_NEAR(tr.area_px, w * h, 0.05 * w * h);
			}
}

TEST(Render, DistortedCornersWhereTheCameraProjects)
{
	mrpt::img::TCamera p = CameraModel().params();
	p.distortion = mrpt::img::DistortionModel::plumb_bob;
	p.dist.fill(0);
	p.dist[0] = -0.28;
	p.dist[1] = 0.09;
	p.dist[2] = 0.001;
	p.dist[3] = -0.0015;
	const CameraModel cam(p);
	ASSERT_TRUE(cam.hasDistortion());
	const MapLandmark lm = makeLandmark();
	const LandmarkGeometry g = lm.geometry();
	double worst = 0;
	for (double d : {0.9, 1.6})
	{
		// Off-centre, where the distortion bends the edges most.
		const Scene scene =
			makeScene(lm, levelCameraLookingAt(lm, d, 30 * kDeg, 0.12 * d, 0.2), cam);
		const Render r = render(scene, edgeOptions(), 3);
		const LandmarkTruth& tr = r.truth[0];
		ASSERT_TRUE(tr.fully_visible) << "d " << d << " corner " << tr.corners_px[0].transpose();
		const cv::Mat gf = greenFraction(r.image);
		// The true (curved) image of a face segment at image row v, by
		// bisection on the segment (v is monotonic along it).
		const auto curveX = [&](double s, double t0, double t1, double v)
		{
			double lo = t0, hi = t1;
			const bool up = facePixel(tr, cam, s, lo).y() < facePixel(tr, cam, s, hi).y();
			for (int i = 0; i < 60; ++i)
			{
				const double mid = 0.5 * (lo + hi);
				if ((facePixel(tr, cam, s, mid).y() < v) == up)
					lo = mid;
				else
					hi = mid;
			}
			return facePixel(tr, cam, s, 0.5 * (lo + hi)).x();
		};
		const double h = g.innerHalf(), b = 1.5 * g.cell_size_m;
		int rows = 0;
		for (int side : {-1, +1})  // left edge (green to its right), right edge
		{
			const double top_v =
				std::max(tr.corners_px[side < 0 ? 0 : 1].y(), tr.corners_px[side < 0 ? 1 : 0].y());
			const double bot_v =
				std::min(tr.corners_px[side < 0 ? 3 : 2].y(), tr.corners_px[side < 0 ? 2 : 3].y());
			for (int v = int(std::ceil(top_v + 3)); v <= int(std::floor(bot_v - 3)); ++v)
			{
				const double e = curveX(side * h, h, -h, v), xb = curveX(side * b, h, -h, v);
				int ua, ub;
				if (side < 0)
				{
					ua = int(std::floor(e)) - 3;
					ub = int(std::floor(xb - 1.5));
					if (ub - 0.5 < e + 1) continue;
				}
				else
				{
					ua = int(std::ceil(xb + 1.5));
					ub = int(std::ceil(e)) + 3;
					if (ua + 0.5 > e - 1) continue;
				}
				double sum = 0;
				for (int u = ua; u <= ub; ++u) sum += gf.at<double>(v, u);
				const double measured = side < 0 ? ub + 0.5 - sum : ua - 0.5 + sum;
				EXPECT_LT(std::abs(measured - e), 0.1)
					<< "d " << d << " side " << side << " row " << v;
				worst = std::max(worst, std::abs(measured - e));
				++rows;
			}
		}
		EXPECT_GT(rows, 20);
		// The truth's corners are the camera's projection of the reference points.
		const auto ref = g.referencePoints();
		for (int i = 0; i < 4; ++i)
		{
			const Eigen::Vector2d px = facePixel(tr, cam, ref[i].y(), ref[i].z());
			EXPECT_NEAR((tr.corners_px[i] - px).norm(), 0.0, 1e-9);
			EXPECT_NEAR((tr.corners_ideal_px[i] - cam.undistortPixel(px)).norm(), 0.0, 1e-6);
		}
	}
	std::cout << "worst distorted edge error: " << worst << " px\n";

	// Partly beyond the field of view, and partly behind the camera: drawn
	// where visible, never fully visible, no crash.
	for (const double bearing : {0.5, 1.2})
	{
		const Scene scene = makeScene(lm, levelCameraLookingAt(lm, 0.4, 0.2, 0.0, bearing), cam);
		const Render r = render(scene, RenderOptions(), 3);
		EXPECT_FALSE(r.truth[0].fully_visible) << "bearing " << bearing;
	}
	const Scene grazing = makeScene(lm, levelCameraLookingAt(lm, 0.05, 80 * kDeg, 0.0, -1.3), cam);
	EXPECT_EQ(render(grazing, RenderOptions(), 1).image.size(), cv::Size(640, 480));
}

TEST(Render, PartlyOutsideIsNotFullyVisible)
{
	const MapLandmark lm = makeLandmark();
	// The landmark centre near the left image border (half FOV is 0.38 rad).
	const Scene scene = makeScene(lm, levelCameraLookingAt(lm, 1.0, 0.2, 0.0, 0.36));
	const Render r = render(scene, RenderOptions(), 1);
	const LandmarkTruth& tr = r.truth[0];
	EXPECT_TRUE(tr.in_front);
	EXPECT_TRUE(tr.facing);
	EXPECT_FALSE(tr.fully_visible);
	EXPECT_LT(std::min(tr.corners_px[0].x(), tr.corners_px[3].x()), 0.5);
	// What is inside the image is drawn: green pixels exist.
	cv::Mat green;
	cv::inRange(r.image, cv::Scalar(0, 200, 0), cv::Scalar(60, 255, 60), green);
	EXPECT_GT(cv::countNonZero(green), 100);
}

TEST(Render, BehindTheCameraDrawsNothing)
{
	const MapLandmark lm = makeLandmark();
	const Scene scene = makeScene(lm, levelCameraLookingAt(lm, 1.0, 0.1, 0.0, M_PI));
	const Render r = render(scene, RenderOptions(), 1);
	const LandmarkTruth& tr = r.truth[0];
	EXPECT_FALSE(tr.in_front);
	EXPECT_FALSE(tr.fully_visible);
	EXPECT_TRUE(std::isnan(tr.corners_px[0].x()));
	EXPECT_EQ(
		cv::norm(r.image, cv::Mat(r.image.size(), CV_8UC3, cv::Scalar::all(128)), cv::NORM_INF),
		0.0);
	// Half behind the camera (the camera inside the landmark's plane
	// region, looking along it): clipped at the near plane, no crash.
	const Scene grazing = makeScene(lm, levelCameraLookingAt(lm, 0.05, 80 * kDeg, 0.0, -1.3));
	const Render g = render(grazing, RenderOptions(), 1);
	EXPECT_EQ(g.image.size(), cv::Size(640, 480));
}

TEST(Render, CameraBehindTheLandmarkIsNotFacing)
{
	const MapLandmark lm = makeLandmark();
	// From behind the wall (view angle pi), looking at the landmark centre.
	const Scene scene = makeScene(lm, levelCameraLookingAt(lm, 1.5, M_PI - 0.2, 0.0, 0.0));
	const Render r = render(scene, RenderOptions(), 1);
	const LandmarkTruth& tr = r.truth[0];
	EXPECT_TRUE(tr.in_front);
	EXPECT_FALSE(tr.facing);
	EXPECT_FALSE(tr.fully_visible);
	EXPECT_LT(tr.sighting.pose_in_landmark[0], 0.0);
	EXPECT_EQ(
		cv::norm(r.image, cv::Mat(r.image.size(), CV_8UC3, cv::Scalar::all(128)), cv::NORM_INF),
		0.0);
}

TEST(Render, OcclusionHidesTheRequestedFraction)
{
	const MapLandmark lm = makeLandmark();
	RenderOptions o;
	o.occlusion = 0.4;
	for (uint64_t seed : {1, 2, 3, 4})
	{
		const Scene scene = makeScene(lm, levelCameraLookingAt(lm, 1.0, 0.3));
		const Render r = render(scene, o, seed);
		const LandmarkTruth& tr = r.truth[0];
		EXPECT_DOUBLE_EQ(tr.occluded_fraction, 0.4);
		const double h = lm.geometry().innerHalf();
		int grey = 0, total = 0;
		for (int i = 0; i < 40; ++i)
			for (int j = 0; j < 40; ++j)
			{
				const double s = -h + (i + 0.5) * 2 * h / 40, t = -h + (j + 0.5) * 2 * h / 40;
				const Eigen::Vector2d px = facePixel(tr, scene.camera, s, t);
				const cv::Vec3b v =
					r.image.at<cv::Vec3b>(int(std::lround(px.y())), int(std::lround(px.x())));
				grey += std::abs(v[0] - 100) < 3 && std::abs(v[1] - 100) < 3;
				++total;
			}
		EXPECT_NEAR(double(grey) / total, 0.4, 0.03) << "seed " << seed;
	}
}

TEST(Render, EffectsChangeTheImageAsAsked)
{
	const MapLandmark lm = makeLandmark();
	const Scene scene = makeScene(lm, levelCameraLookingAt(lm, 1.0, 0.0));
	const Render base = render(scene, RenderOptions(), 5);
	// Gain halves every level.
	RenderOptions o;
	o.gain = 0.5;
	const Render dim = render(scene, o, 5);
	cv::Mat half;
	base.image.convertTo(half, CV_32F, 0.5);
	cv::Mat dimf;
	dim.image.convertTo(dimf, CV_32F);
	EXPECT_LE(cv::norm(half, dimf, cv::NORM_INF), 1.0);
	// Noise: the flat background's standard deviation is sigma.
	o = RenderOptions();
	o.noise_sigma = 4;
	const Render noisy = render(scene, o, 5);
	cv::Scalar mean, sd;
	cv::meanStdDev(noisy.image(cv::Rect(0, 0, 100, 100)), mean, sd);
	EXPECT_NEAR(sd[0], 4.0, 0.3);
	EXPECT_NEAR(mean[0], 128.0, 0.5);
	// Blur (Gaussian or motion) spreads an edge over more pixels.
	const auto spread = [&](const cv::Mat& img)
	{
		const LandmarkTruth& tr = base.truth[0];
		const int v = int(std::lround(0.5 * (tr.corners_px[0].y() + tr.corners_px[3].y())));
		const int u = int(std::lround(tr.corners_px[0].x()));
		int n = 0;
		for (int k = u - 8; k <= u + 8; ++k)
		{
			const int gch = img.at<cv::Vec3b>(v, k)[1];
			n += gch > 35 && gch < 245;
		}
		return n;
	};
	o = RenderOptions();
	o.blur_sigma_px = 2;
	EXPECT_GE(spread(render(scene, o, 5).image), spread(base.image) + 3);
	o = RenderOptions();
	o.motion_blur_px = 6;
	EXPECT_GE(spread(render(scene, o, 5).image), spread(base.image) + 3);
	// Motion along the (vertical) edge leaves it sharp.
	o.motion_blur_angle_rad = M_PI / 2;
	EXPECT_LE(spread(render(scene, o, 5).image), spread(base.image) + 1);
	// The gradient darkens one side and brightens the other.
	o = RenderOptions();
	o.gradient = 0.5;
	const Render grad = render(scene, o, 5);
	EXPECT_NEAR(grad.image.at<cv::Vec3b>(240, 0)[0], 128 * 0.75, 1.5);
	EXPECT_NEAR(grad.image.at<cv::Vec3b>(240, 639)[0], 128 * 1.25, 1.5);
	o.gradient_angle_rad = M_PI / 2;  // brighter towards the top
	const Render up = render(scene, o, 5);
	EXPECT_NEAR(up.image.at<cv::Vec3b>(0, 5)[0], 128 * 1.25, 1.5);
	EXPECT_NEAR(up.image.at<cv::Vec3b>(479, 5)[0], 128 * 0.75, 1.5);
	// JPEG changes the pixels a little.
	o = RenderOptions();
	o.jpeg_quality = 70;
	const Render jpg = render(scene, o, 5);
	EXPECT_GT(cv::norm(jpg.image, base.image, cv::NORM_INF), 0.0);
	EXPECT_LT(cv::norm(jpg.image, base.image, cv::NORM_L1) / base.image.total(), 6.0);
	// A textured background is not flat.
	o = RenderOptions();
	o.background = Background::Textured;
	cv::meanStdDev(render(scene, o, 5).image(cv::Rect(0, 0, 100, 100)), mean, sd);
	EXPECT_GT(sd[0], 3.0);
}

TEST(Render, EdgesWithDefaultColoursOverClutter)
{
	// The printed colours over a cluttered wall: the inner edges are still
	// exact (measured where the black frame is wide enough for a pure dark
	// pixel: up to 2 m and 45 deg).
	const MapLandmark lm = makeLandmark();
	const CameraModel cam;
	RenderOptions o;
	o.background = Background::Cluttered;
	o.distractors = 30;
	double worst = 0;
	for (double d : {0.7, 1.5, 2.0})
		for (double a_deg : {0.0, 30.0, -45.0})
		{
			const Scene scene =
				makeScene(lm, levelCameraLookingAt(lm, d, a_deg * kDeg, 0.04 * d, -0.05), cam);
			const Render r = render(scene, o, 9);
			const auto errs =
				innerEdgeErrors(greenFraction(r.image), r.truth[0], cam, lm.geometry().cell_size_m);
			for (int e = 0; e < 4; ++e)
			{
				EXPECT_GE(errs[e].size(), 3u) << "edge " << e << " d " << d << " a " << a_deg;
				EXPECT_LT(maxAbs(errs[e]), 0.02) << "edge " << e << " d " << d << " a " << a_deg;
				worst = std::max(worst, maxAbs(errs[e]));
			}
		}
	std::cout << "worst edge error, printed colours: " << worst << " px\n";
}

TEST(Render, NearerLandmarksCoverFartherOnes)
{
	MapLandmark far = makeLandmark(255), near = makeLandmark(0);
	// near: 1 m in front of far, slightly to the side, both facing the camera.
	near.x_m = far.x_m + std::cos(far.yaw_rad) * 1.0 + 0.05;
	near.y_m = far.y_m + std::sin(far.yaw_rad) * 1.0;
	near.yaw_rad = far.yaw_rad;
	Scene scene;
	scene.map.landmarks = {near, far};	// map order is not drawing order
	scene.world_T_camera = levelCameraLookingAt(far, 2.0, 0.0);
	const Render r = render(scene, RenderOptions(), 1);
	ASSERT_EQ(r.truth.size(), 2u);
	EXPECT_EQ(r.truth[0].id, 0);
	EXPECT_EQ(r.truth[1].id, 255);
	// The centre of the near landmark's code board: all its cells but the
	// centre are green (ID 0), although the far one (all black) is behind.
	const LandmarkGeometry g = near.geometry();
	for (int row = 0; row < 3; ++row)
		for (int col = 0; col < 3; ++col)
		{
			const Eigen::Vector2d f = g.cellCentreFace(row, col);
			const Eigen::Vector2d px = facePixel(r.truth[0], scene.camera, f.x(), f.y());
			const cv::Vec3b v =
				r.image.at<cv::Vec3b>(int(std::lround(px.y())), int(std::lround(px.x())));
			EXPECT_EQ(v[1] < 128, row == 1 && col == 1) << "cell " << row << col;
		}
}

TEST(Render, SampledPathAgreesWithExactCoverage)
{
	// A negligible distortion switches to the supersampled path; the image
	// must match the exact-coverage one up to the sampling error.
	mrpt::img::TCamera p = CameraModel().params();
	p.distortion = mrpt::img::DistortionModel::plumb_bob;
	p.dist.fill(0);
	p.dist[0] = 1e-12;
	const CameraModel sampled(p), exact;
	ASSERT_TRUE(sampled.hasDistortion());
	const MapLandmark lm = makeLandmark(170);
	RenderOptions o;
	o.occlusion = 0.3;
	const CPose3D pose = levelCameraLookingAt(lm, 1.3, 35 * kDeg, 0.1, 0.05);
	const cv::Mat a = render(makeScene(lm, pose, exact), o, 4).image;
	const cv::Mat b = render(makeScene(lm, pose, sampled), o, 4).image;
	cv::Mat diff;
	cv::absdiff(a, b, diff);
	// 64 samples per pixel: a pixel's coverage is off by at most 1/64 of a
	// 255 contrast along straight edges (more only at corners).
	EXPECT_LT(cv::mean(diff)[1], 0.05);
	double worst = 0;
	cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
	EXPECT_LT(worst, 40.0);
	const int differ = cv::countNonZero(diff.reshape(1) > 0),
			  big = cv::countNonZero(diff.reshape(1) > 8);
	std::cout << "sampled vs exact: mean " << cv::mean(diff)[1] << ", worst " << worst
			  << " grey levels, " << big << " of " << differ << " differing values above 8\n";
	EXPECT_GT(differ, 0);  // the two paths really differ (the sampled one ran)
	EXPECT_LT(big, differ / 10);
}
