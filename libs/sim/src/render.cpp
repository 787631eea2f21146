#include <codemark/landmark/codebook.h>
#include <codemark/landmark/primary.h>
#include <codemark/sim/render.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>

#include "background.h"
#include "raster.h"

namespace codemark::sim
{
using detail::Polygon2;
using detail::Polygon3;

namespace
{
/** Near clipping plane of the camera [m]. */
constexpr double kNearM = 1e-3;
/** Grey level of the occluding bar at gain 1. */
constexpr double kOccluderGrey = 100.0;

using detail::Rigid;
using detail::toRigid;

/** What covers a point of the landmark's plane. */
enum Paint : int
{
	kBackground = 0,
	kWhite,
	kBlack,
	kGreen,
	kOccluder,
	kNumPaints
};

/** The landmark's face as nested squares in face coordinates (s right,
 * t up, as seen from the front) [m], and the optional occluding bar. */
struct Face
{
	double sheet_half, outer_half, inner_half, cell;
	CodeCells cells;
	bool has_occluder = false;
	double occ_s0 = 0, occ_t0 = 0, occ_s1 = 0, occ_t1 = 0;

	Face(const LandmarkGeometry& g, int id)
		: sheet_half(g.outerHalf() + g.margin_m),
		  outer_half(g.outerHalf()),
		  inner_half(g.innerHalf()),
		  cell(g.cell_size_m),
		  cells(encodeId(id))
	{
	}

	/** Hides \a fraction of the reference square behind a bar from \a side
	 * (0 left, 1 right, 2 bottom, 3 top as seen from the front). */
	void setOccluder(double fraction, int side)
	{
		has_occluder = fraction > 0;
		const double far = 1.3 * sheet_half, h = inner_half, edge = -h + 2 * h * fraction;
		switch (side)
		{
			case 0:
				occ_s0 = -far, occ_s1 = edge, occ_t0 = -far, occ_t1 = far;
				break;
			case 1:
				occ_s0 = -edge, occ_s1 = far, occ_t0 = -far, occ_t1 = far;
				break;
			case 2:
				occ_s0 = -far, occ_s1 = far, occ_t0 = -far, occ_t1 = edge;
				break;
			default:
				occ_s0 = -far, occ_s1 = far, occ_t0 = -edge, occ_t1 = far;
				break;
		}
	}

	Paint paintAt(double s, double t) const
	{
		if (has_occluder && s >= occ_s0 && s <= occ_s1 && t >= occ_t0 && t <= occ_t1)
			return kOccluder;
		const double m = std::max(std::abs(s), std::abs(t));
		if (m > sheet_half) return kBackground;
		if (m > outer_half) return kWhite;
		if (m > inner_half) return kBlack;
		if (m > 1.5 * cell) return kGreen;
		const int col = std::clamp(static_cast<int>(std::floor(s / cell + 1.5)), 0, 2);
		const int row = std::clamp(static_cast<int>(std::floor(1.5 - t / cell)), 0, 2);
		return cells[row][col] ? kBlack : kGreen;
	}
};

/** The face rectangle [s0, s1] x [t0, t1] in the camera frame. */
Polygon3 faceRect(const Rigid& cam_T_lm, double s0, double t0, double s1, double t1)
{
	return {
		cam_T_lm * LandmarkGeometry::faceToLandmark(s0, t0),
		cam_T_lm * LandmarkGeometry::faceToLandmark(s1, t0),
		cam_T_lm * LandmarkGeometry::faceToLandmark(s1, t1),
		cam_T_lm * LandmarkGeometry::faceToLandmark(s0, t1)};
}

Polygon3 faceSquare(const Rigid& cam_T_lm, double half)
{
	return faceRect(cam_T_lm, -half, -half, half, half);
}

using detail::pixelBounds;

std::array<cv::Vec3d, kNumPaints> paintColours(const RenderOptions& o)
{
	const auto v = [](const cv::Scalar& s) { return cv::Vec3d(s[0], s[1], s[2]); };
	return {
		cv::Vec3d(0, 0, 0), v(o.white_bgr), v(o.black_bgr), v(o.green_bgr),
		cv::Vec3d(kOccluderGrey, kOccluderGrey, kOccluderGrey)};
}

/** Without lens distortion: exact area coverage of the projected nested
 * squares, mixed by coverage over what is already in \a img. */
void drawLandmarkExact(
	cv::Mat& img, const CameraModel& cam, const Rigid& cam_T_lm, const Face& face,
	const RenderOptions& o)
{
	const auto project = [&](const Polygon3& p)
	{
		return detail::projectPinhole(
			detail::clipNear(p, kNearM), cam.fx(), cam.fy(), cam.cx(), cam.cy());
	};
	// Layers, each nested in the one before, except the occluder.
	const Polygon2 sheet = project(faceSquare(cam_T_lm, face.sheet_half));
	Polygon2 occluder;
	if (face.has_occluder)
		occluder = project(faceRect(cam_T_lm, face.occ_s0, face.occ_t0, face.occ_s1, face.occ_t1));
	std::vector<Eigen::Vector2d> all = sheet;
	all.insert(all.end(), occluder.begin(), occluder.end());
	const cv::Rect roi = pixelBounds(all, img.cols, img.rows, 1);
	if (roi.empty()) return;

	enum
	{
		kSheet,
		kOuter,
		kInner,
		kCells,
		kOcc,
		kLayers
	};
	std::array<cv::Mat, kLayers> cov;
	for (auto& m : cov) m = cv::Mat::zeros(roi.size(), CV_64FC1);
	const cv::Point origin = roi.tl();
	detail::accumulateCoverage(sheet, cov[kSheet], origin);
	detail::accumulateCoverage(project(faceSquare(cam_T_lm, face.outer_half)), cov[kOuter], origin);
	detail::accumulateCoverage(project(faceSquare(cam_T_lm, face.inner_half)), cov[kInner], origin);
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
		{
			if (!face.cells[r][c]) continue;
			const double s = (c - 1) * face.cell, t = (1 - r) * face.cell, h = 0.5 * face.cell;
			detail::accumulateCoverage(
				project(faceRect(cam_T_lm, s - h, t - h, s + h, t + h)), cov[kCells], origin);
		}
	if (!occluder.empty()) detail::accumulateCoverage(occluder, cov[kOcc], origin);

	const auto col = paintColours(o);
	for (int y = 0; y < roi.height; ++y)
	{
		cv::Vec3f* px = img.ptr<cv::Vec3f>(roi.y + y) + roi.x;
		const double* c0 = cov[kSheet].ptr<double>(y);
		const double* c1 = cov[kOuter].ptr<double>(y);
		const double* c2 = cov[kInner].ptr<double>(y);
		const double* c3 = cov[kCells].ptr<double>(y);
		const double* co = cov[kOcc].ptr<double>(y);
		for (int x = 0; x < roi.width; ++x)
		{
			if (c0[x] == 0 && co[x] == 0) continue;
			const cv::Vec3d bg(px[x][0], px[x][1], px[x][2]);
			cv::Vec3d v = bg * (1 - c0[x]) + col[kWhite] * (c0[x] - c1[x]) +
						  col[kBlack] * (c1[x] - c2[x] + c3[x]) + col[kGreen] * (c2[x] - c3[x]);
			v = v * (1 - co[x]) + col[kOccluder] * co[x];
			px[x] = cv::Vec3f(float(v[0]), float(v[1]), float(v[2]));
		}
	}
}

/** Undistorted normalised coordinates of every pixel corner of the image:
 * xn[j * width + i] is corner (i - 0.5, j - 0.5), width = image width + 1.
 * Samples inside a pixel interpolate its four corners bilinearly: the
 * distortion is smooth, so the interpolation error (h^2/8 times its second
 * derivative: about 1e-4 px for |k1| = 0.3 at 800 px focal length) is far
 * below the sampling error, and it
 * saves n^2 iterative inversions per pixel. */
struct CornerGrid
{
	std::vector<double> key;  //!< the camera it belongs to
	int width = 0;
	std::vector<Eigen::Vector2d> xn;
	double max_r2 = 0;	//!< largest |xn|^2 over the image: the field of view
};

/** The corner grid of \a cam, computed once and cached for the last camera
 * used (a dataset renders many frames with one camera). Thread-safe. */
std::shared_ptr<const CornerGrid> cornerGrid(const CameraModel& cam)
{
	const auto& p = cam.params();
	std::vector<double> key{double(p.ncols), double(p.nrows), cam.fx(),
							cam.fy(),		 cam.cx(),		  cam.cy()};
	key.insert(key.end(), p.dist.begin(), p.dist.end());
	static std::mutex mutex;
	static std::shared_ptr<const CornerGrid> cached;
	std::lock_guard<std::mutex> lock(mutex);
	if (cached && cached->key == key) return cached;
	auto g = std::make_shared<CornerGrid>();
	g->key = key;
	g->width = cam.width() + 1;
	g->xn.resize(static_cast<size_t>(g->width) * (cam.height() + 1));
	for (int j = 0; j <= cam.height(); ++j)
		for (int i = 0; i <= cam.width(); ++i)
		{
			const Eigen::Vector2d xn = cam.undistortToNormalized({i - 0.5, j - 0.5});
			g->xn[static_cast<size_t>(j) * g->width + i] = xn;
			g->max_r2 = std::max(g->max_r2, xn.squaredNorm());
		}
	cached = g;
	return cached;
}

/** With lens distortion: n x n samples per pixel, each undistorted and cast
 * through the inverse homography onto the landmark plane. */
void drawLandmarkSampled(
	cv::Mat& img, const CameraModel& cam, const Rigid& cam_T_lm, const Face& face,
	const RenderOptions& o, const CornerGrid* corners)
{
	// Bounds from the distorted projections of the (near-clipped) outlines.
	// The lens model only holds inside the field of view (beyond it the
	// polynomial may fold points back into the image), so an outline that
	// leaves the field of view makes the whole image the region.
	const CornerGrid& grid = *corners;
	std::vector<Eigen::Vector2d> outline;
	bool leaves_view = false;
	const auto addOutline = [&](const Polygon3& poly)
	{
		const Polygon3 p = detail::clipNear(poly, kNearM);
		for (size_t i = 0; i < p.size(); ++i)
			for (int k = 0; k < 64; ++k)
			{
				const Eigen::Vector3d q = p[i] + (p[(i + 1) % p.size()] - p[i]) * (k / 64.0);
				const Eigen::Vector2d xn(q.x() / q.z(), q.y() / q.z());
				if (xn.squaredNorm() > grid.max_r2 * 1.21)
					leaves_view = true;
				else if (auto px = cam.project(q))
					outline.push_back(*px);
			}
	};
	addOutline(faceSquare(cam_T_lm, face.sheet_half));
	if (face.has_occluder)
		addOutline(faceRect(cam_T_lm, face.occ_s0, face.occ_t0, face.occ_s1, face.occ_t1));
	if (leaves_view) outline = {{0.0, 0.0}, {img.cols - 1.0, img.rows - 1.0}};
	const cv::Rect roi = pixelBounds(outline, img.cols, img.rows, 2);
	if (roi.empty()) return;

	// camera point = M (s, t, 1): the plane's homography.
	Eigen::Matrix3d M;
	M << cam_T_lm.R.col(1), cam_T_lm.R.col(2), cam_T_lm.t;
	if (!(std::abs(M.determinant()) > 1e-15)) return;  // seen edge-on
	const Eigen::Matrix3d Minv = M.inverse();

	const int gw = grid.width;
	const int n = o.supersampling;
	const int nn = n * n;
	const auto col = paintColours(o);
	const double w_sample = 1.0 / (n * n);
	for (int y = 0; y < roi.height; ++y)
	{
		cv::Vec3f* px = img.ptr<cv::Vec3f>(roi.y + y) + roi.x;
		for (int x = 0; x < roi.width; ++x)
		{
			const size_t i00 = static_cast<size_t>(roi.y + y) * gw + roi.x + x;
			const Eigen::Vector2d& g00 = grid.xn[i00];
			const Eigen::Vector2d& g10 = grid.xn[i00 + 1];
			const Eigen::Vector2d& g01 = grid.xn[i00 + gw];
			const Eigen::Vector2d& g11 = grid.xn[i00 + gw + 1];
			const auto paintOf = [&](const Eigen::Vector2d& xn)
			{
				const Eigen::Vector3d q = Minv * Eigen::Vector3d(xn.x(), xn.y(), 1.0);
				// q = (s, t, 1) / depth: behind the camera when q.z <= 0.
				return q.z() > 0 ? face.paintAt(q.x() / q.z(), q.y() / q.z()) : kBackground;
			};
			// Fast path: the four corners and the centre of the pixel see one
			// paint. The smallest printed feature (the 5 mm margin) is a
			// strip that reaches across the pixel, so it cannot hide between
			// the probes.
			const Paint p00 = paintOf(g00);
			if (paintOf(g10) == p00 && paintOf(g01) == p00 && paintOf(g11) == p00 &&
				paintOf(0.25 * (g00 + g10 + g01 + g11)) == p00)
			{
				if (p00 != kBackground)
					px[x] = cv::Vec3f(float(col[p00][0]), float(col[p00][1]), float(col[p00][2]));
				continue;
			}
			// n x n samples in the canonical multi-jittered arrangement (one
			// per cell of an n x n grid, and all n^2 x and y offsets
			// distinct), so that straight edges in any direction see n^2
			// coverage levels instead of n.
			std::array<int, kNumPaints> count{};
			for (int a = 0; a < n; ++a)
				for (int b = 0; b < n; ++b)
				{
					const double fx = (a * n + b + 0.5) / nn, fy = (b * n + a + 0.5) / nn;
					const Eigen::Vector2d l = g00 + (g01 - g00) * fy, r = g10 + (g11 - g10) * fy;
					++count[paintOf(l + (r - l) * fx)];
				}
			if (count[kBackground] == n * n) continue;
			cv::Vec3d v = cv::Vec3d(px[x][0], px[x][1], px[x][2]) * (count[kBackground] * w_sample);
			for (int k = kWhite; k < kNumPaints; ++k) v += col[k] * (count[k] * w_sample);
			px[x] = cv::Vec3f(float(v[0]), float(v[1]), float(v[2]));
		}
	}
}

LandmarkTruth truthOf(const MapLandmark& lm, const Scene& scene, Rigid* cam_T_lm_out)
{
	const CameraModel& cam = scene.camera;
	const LandmarkGeometry g = lm.geometry();
	const mrpt::poses::CPose3D world_T_lm = lm.world_T_landmark();
	LandmarkTruth tr;
	tr.id = lm.id;
	tr.landmark_T_camera = scene.world_T_camera - world_T_lm;
	const Rigid cam_T_lm = toRigid(world_T_lm - scene.world_T_camera);
	if (cam_T_lm_out) *cam_T_lm_out = cam_T_lm;
	tr.in_front = cam_T_lm.t.z() > 0;
	tr.facing = tr.landmark_T_camera.x() > 0;

	const double nan = std::numeric_limits<double>::quiet_NaN();
	const auto ref = g.referencePoints();
	bool all_in_front = true;
	for (int i = 0; i < 4; ++i)
	{
		const Eigen::Vector3d p = cam_T_lm * ref[i];
		if (auto px = cam.project(p))
		{
			tr.corners_px[i] = *px;
			tr.corners_ideal_px[i] = {
				cam.fx() * p.x() / p.z() + cam.cx(), cam.fy() * p.y() / p.z() + cam.cy()};
		}
		else
		{
			tr.corners_px[i] = tr.corners_ideal_px[i] = {nan, nan};
			all_in_front = false;
		}
	}
	if (all_in_front)
	{
		double a = 0;
		for (int i = 0; i < 4; ++i)
		{
			const auto& p0 = tr.corners_px[i];
			const auto& p1 = tr.corners_px[(i + 1) % 4];
			a += p0.x() * p1.y() - p1.x() * p0.y();
		}
		tr.area_px = 0.5 * std::abs(a);
		tr.P = primaryMeasurementFromIdeal(tr.corners_ideal_px, cam);
	}

	// Fully visible: the whole outer frame outline (sampled densely, since
	// lens distortion bends its edges) is in front and at least 1 px inside.
	bool inside = tr.facing;
	const double h = g.outerHalf();
	const std::array<Eigen::Vector2d, 4> oc{{{-h, h}, {h, h}, {h, -h}, {-h, -h}}};
	for (int i = 0; i < 4 && inside; ++i)
		for (int k = 0; k < 16 && inside; ++k)
		{
			const Eigen::Vector2d f = oc[i] + (oc[(i + 1) % 4] - oc[i]) * (k / 16.0);
			const Eigen::Vector3d p = cam_T_lm * LandmarkGeometry::faceToLandmark(f.x(), f.y());
			const auto px = cam.project(p);
			inside = px && px->x() >= 0.5 && px->x() <= cam.width() - 1.5 && px->y() >= 0.5 &&
					 px->y() <= cam.height() - 1.5;
			// Beyond the field of view a lens polynomial can fold points
			// back into the image: such a pixel does not undistort back.
			if (inside && cam.hasDistortion())
				inside =
					(cam.undistortToNormalized(*px) - Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()))
						.norm() < 1e-6;
		}
	tr.fully_visible = inside;
	tr.sighting = sightingTruth(tr.landmark_T_camera);
	return tr;
}

void applyIllumination(cv::Mat& img, const RenderOptions& o)
{
	if (o.gain == 1.0 && o.gradient == 0.0) return;
	const double ca = std::cos(o.gradient_angle_rad), sa = std::sin(o.gradient_angle_rad);
	// The projection on the gradient direction spans +-extent/2 over the
	// image, so the factor spans gain * (1 +- gradient / 2).
	const double extent = std::abs(img.cols * ca) + std::abs(img.rows * sa);
	const double cu = 0.5 * (img.cols - 1), cv_ = 0.5 * (img.rows - 1);
	for (int v = 0; v < img.rows; ++v)
	{
		cv::Vec3f* p = img.ptr<cv::Vec3f>(v);
		for (int u = 0; u < img.cols; ++u)
		{
			// Counter-clockwise as displayed: v grows downwards.
			const double d = ((u - cu) * ca - (v - cv_) * sa) / extent;
			p[u] *= static_cast<float>(o.gain * (1 + o.gradient * d));
		}
	}
}

}  // namespace

std::vector<LandmarkTruth> groundTruth(const Scene& scene)
{
	std::vector<LandmarkTruth> out;
	out.reserve(scene.map.landmarks.size());
	for (const auto& lm : scene.map.landmarks) out.push_back(truthOf(lm, scene, nullptr));
	return out;
}

Render render(const Scene& scene, const RenderOptions& o, uint64_t seed)
{
	o.validate();
	const CameraModel& cam = scene.camera;
	const int W = cam.width(), H = cam.height();
	cv::Mat img = detail::makeBackground(o, W, H, seed);

	Render out;
	const auto& lms = scene.map.landmarks;
	std::vector<Rigid> cam_T_lm(lms.size());
	out.truth.reserve(lms.size());
	for (size_t i = 0; i < lms.size(); ++i)
		out.truth.push_back(truthOf(lms[i], scene, &cam_T_lm[i]));

	// Far to near, so that nearer landmarks cover farther ones.
	std::vector<size_t> order(lms.size());
	std::iota(order.begin(), order.end(), size_t(0));
	std::stable_sort(
		order.begin(), order.end(),
		[&](size_t a, size_t b) { return cam_T_lm[a].t.norm() > cam_T_lm[b].t.norm(); });
	cv::RNG occ_rng(detail::streamSeed(seed, 3));
	std::shared_ptr<const CornerGrid> corners;
	if (cam.hasDistortion()) corners = cornerGrid(cam);
	for (size_t i : order)
	{
		const int side = occ_rng.uniform(0, 4);
		LandmarkTruth& tr = out.truth[i];
		// The back of a landmark is the wall it hangs on: nothing to draw.
		if (!tr.facing) continue;
		Face face(lms[i].geometry(), lms[i].id);
		face.setOccluder(o.occlusion, side);
		tr.occluded_fraction = o.occlusion;
		if (corners)
			drawLandmarkSampled(img, cam, cam_T_lm[i], face, o, corners.get());
		else
			drawLandmarkExact(img, cam, cam_T_lm[i], face, o);
	}

	// The scene's light, then the camera with this frame's draws.
	applyIllumination(img, o);
	out.image = cameraImage(img, o.drawn(seed), cam.cx(), cam.cy(), seed);
	return out;
}

Scene singleLandmarkScene(const CameraModel& camera, int id, double z_m)
{
	Scene scene;
	MapLandmark lm;
	lm.id = id;
	lm.z_m = z_m;
	scene.map.landmarks.push_back(lm);
	scene.camera = camera;
	return scene;
}

mrpt::poses::CPose3D levelCameraLookingAt(
	const MapLandmark& landmark, double distance_m, double view_angle_rad, double height_m,
	double bearing_rad)
{
	// Optical centre in frame L, then the heading of the optical axis in L:
	// the line of sight to the landmark centre (view angle + pi) turned
	// clockwise by the bearing, so the centre appears bearing_rad to the left.
	const mrpt::poses::CPose3D lm_T_body(
		distance_m * std::cos(view_angle_rad), distance_m * std::sin(view_angle_rad), height_m,
		view_angle_rad + M_PI - bearing_rad, 0, 0);
	return landmark.world_T_landmark() + lm_T_body +
		   mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
}

}  // namespace codemark::sim
