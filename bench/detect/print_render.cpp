#include "print_render.h"

#include <codemark/landmark/codebook.h>
#include <codemark/landmark/geometry.h>

#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>

extern "C"
{
#include <apriltag.h>
#include <tag36h11.h>
}

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

// libs/sim internals, included by path (bench/detect/CMakeLists.txt adds
// libs/sim/src to the include path): the exact coverage raster and the
// background with its seeded streams.
#include "background.h"
#include "raster.h"

namespace codemark::bench
{
namespace
{
using sim::detail::Polygon2;
using sim::detail::Polygon3;

constexpr double kNearM = 1e-3;	 // the renderer's near plane

using sim::detail::Rigid;
using sim::detail::toRigid;

Polygon3 faceRect(const Rigid& cam_T_face, double s0, double t0, double s1, double t1)
{
	return {
		cam_T_face * LandmarkGeometry::faceToLandmark(s0, t0),
		cam_T_face * LandmarkGeometry::faceToLandmark(s1, t0),
		cam_T_face * LandmarkGeometry::faceToLandmark(s1, t1),
		cam_T_face * LandmarkGeometry::faceToLandmark(s0, t1)};
}

// As libs/sim's render.cpp (anonymous there).
using sim::detail::pixelBounds;

/** A marker from its cell image: \a cells is n x n (row 0 at the top as
 * seen from the front, non-zero = white); the reference square is the
 * centred \a ref_cells x \a ref_cells block, whose cells are painted; a
 * white margin of one cell surrounds it. */
PlanarPrint markerPrint(
	PrintKind kind, int id, const cv::Mat& cells, int ref_cells, double ref_size_m)
{
	PlanarPrint p;
	p.kind = kind;
	p.id = id;
	const double cell = ref_size_m / ref_cells, h = 0.5 * ref_size_m;
	p.ref_half_m = h;
	p.sheet_half_m = h + cell;
	p.rects.push_back(
		{-p.sheet_half_m, -p.sheet_half_m, p.sheet_half_m, p.sheet_half_m, kWhite, 1});
	p.rects.push_back({-h, -h, h, h, kWhite, -1});
	p.rects.push_back({-h, -h, h, h, kBlack, 1});
	const int off = (cells.rows - ref_cells) / 2;
	for (int r = 0; r < ref_cells; ++r)
	{
		// Runs of white cells along the row: fewer, larger polygons.
		int c = 0;
		while (c < ref_cells)
		{
			if (!cells.at<uint8_t>(off + r, off + c))
			{
				++c;
				continue;
			}
			int e = c;
			while (e < ref_cells && cells.at<uint8_t>(off + r, off + e)) ++e;
			const double s0 = -h + c * cell, s1 = -h + e * cell;
			const double t1 = h - r * cell, t0 = h - (r + 1) * cell;
			p.rects.push_back({s0, t0, s1, t1, kBlack, -1});
			p.rects.push_back({s0, t0, s1, t1, kWhite, 1});
			c = e;
		}
	}
	return p;
}

/** tag36h11 cells (10 x 10 with the white ring), cached per ID. */
cv::Mat aprilTagCells(int id)
{
	apriltag_family_t* tf = tag36h11_create();
	if (id < 0 || id >= static_cast<int>(tf->ncodes))
	{
		tag36h11_destroy(tf);
		throw std::invalid_argument("tag36h11 has no ID " + std::to_string(id));
	}
	image_u8_t* im = apriltag_to_image(tf, static_cast<uint32_t>(id));
	cv::Mat cells(im->height, im->width, CV_8U);
	for (int r = 0; r < im->height; ++r)
		for (int c = 0; c < im->width; ++c) cells.at<uint8_t>(r, c) = im->buf[r * im->stride + c];
	image_u8_destroy(im);
	tag36h11_destroy(tf);
	return cells;
}
}  // namespace

const char* printKindName(PrintKind k)
{
	switch (k)
	{
		case PrintKind::Codemark:
			return "codemark";
		case PrintKind::Aruco:
			return "ArUco 4x4_50";
		default:
			return "AprilTag 36h11";
	}
}

PlanarPrint makePrint(PrintKind kind, int id, double ref_size_m)
{
	if (kind == PrintKind::Aruco)
	{
		if (id < 0 || id >= 50)
			throw std::invalid_argument("DICT_4X4_50 has no ID " + std::to_string(id));
		const auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
		cv::Mat cells;
		cv::aruco::drawMarker(dict, id, 6, cells, 1);  // one pixel per cell
		return markerPrint(kind, id, cells, 6, ref_size_m);
	}
	if (kind == PrintKind::AprilTag)
	{
		const cv::Mat cells = aprilTagCells(id);
		return markerPrint(kind, id, cells, cells.rows - 2, ref_size_m);
	}
	if (id < 0 || id > 255) throw std::invalid_argument("codemark has no ID " + std::to_string(id));
	// Our landmark as libs/sim draws it: sheet white, frame black, green
	// square, black code cells.
	const LandmarkGeometry g =
		LandmarkGeometry::scaled(ref_size_m / LandmarkGeometry().inner_size_m);
	PlanarPrint p;
	p.kind = kind;
	p.id = id;
	p.ref_half_m = g.innerHalf();
	p.sheet_half_m = g.outerHalf() + g.margin_m;
	const double s = p.sheet_half_m, o = g.outerHalf(), i = g.innerHalf(), cell = g.cell_size_m;
	p.rects.push_back({-s, -s, s, s, kWhite, 1});
	p.rects.push_back({-o, -o, o, o, kWhite, -1});
	p.rects.push_back({-o, -o, o, o, kBlack, 1});
	p.rects.push_back({-i, -i, i, i, kBlack, -1});
	p.rects.push_back({-i, -i, i, i, kGreen, 1});
	const CodeCells cells = encodeId(id);
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
		{
			if (!cells[r][c]) continue;
			const double cs = (c - 1) * cell, ct = (1 - r) * cell, hc = 0.5 * cell;
			p.rects.push_back({cs - hc, ct - hc, cs + hc, ct + hc, kGreen, -1});
			p.rects.push_back({cs - hc, ct - hc, cs + hc, ct + hc, kBlack, 1});
		}
	return p;
}

PrintTruth truthOf(
	const PlacedPrint& p, const CameraModel& cam, const mrpt::poses::CPose3D& world_T_camera)
{
	const Rigid cam_T = toRigid(p.world_T_print - world_T_camera);
	const auto project = [&](double s, double t, bool& ok)
	{
		const Eigen::Vector3d q = cam_T * LandmarkGeometry::faceToLandmark(s, t);
		ok = q.z() > kNearM;
		return Eigen::Vector2d(
			cam.fx() * q.x() / q.z() + cam.cx(), cam.fy() * q.y() / q.z() + cam.cy());
	};
	PrintTruth tr;
	tr.id = p.print.id;
	const double h = p.print.ref_half_m, S = p.print.sheet_half_m;
	const std::array<Eigen::Vector2d, 4> face{{{-1, 1}, {1, 1}, {1, -1}, {-1, -1}}};
	bool ok = true;
	for (int k = 0; k < 4; ++k)
	{
		bool in = false;
		tr.corners_px[k] = project(h * face[k].x(), h * face[k].y(), in);
		ok = ok && in;
	}
	double vmin = 1e300, vmax = -1e300, side = 0;
	for (int k = 0; k < 4; ++k)
	{
		vmin = std::min(vmin, tr.corners_px[k].y());
		vmax = std::max(vmax, tr.corners_px[k].y());
		side += 0.25 * (tr.corners_px[(k + 1) % 4] - tr.corners_px[k]).norm();
	}
	tr.ref_height_px = vmax - vmin;
	tr.ref_side_px = side;
	// The camera must be on the printed side (+X_L).
	const mrpt::poses::CPose3D print_T_camera = world_T_camera - p.world_T_print;
	bool vis = ok && print_T_camera.x() > 0;
	for (int k = 0; k < 4 && vis; ++k)
	{
		bool in = false;
		const Eigen::Vector2d q = project(S * face[k].x(), S * face[k].y(), in);
		vis = in && q.x() >= 0.5 && q.x() <= cam.width() - 1.5 && q.y() >= 0.5 &&
			  q.y() <= cam.height() - 1.5;
	}
	tr.sheet_visible = vis;
	return tr;
}

Frame renderFrame(
	const std::vector<PlacedPrint>& prints, const CameraModel& cam,
	const mrpt::poses::CPose3D& world_T_camera, const sim::RenderOptions& o, const Effects& fx,
	uint64_t seed)
{
	if (cam.hasDistortion())
		throw std::invalid_argument(
			"renderFrame: the exact-coverage path needs a camera without distortion");
	const int W = cam.width(), H = cam.height();
	cv::Mat img = sim::detail::makeBackground(o, W, H, seed);  // CV_32FC3

	Frame out;
	std::vector<Rigid> cam_T(prints.size());
	for (size_t i = 0; i < prints.size(); ++i)
	{
		cam_T[i] = toRigid(prints[i].world_T_print - world_T_camera);
		out.truth.push_back(truthOf(prints[i], cam, world_T_camera));
	}
	std::vector<size_t> order(prints.size());
	std::iota(order.begin(), order.end(), size_t(0));
	std::stable_sort(
		order.begin(), order.end(),
		[&](size_t a, size_t b) { return cam_T[a].t.norm() > cam_T[b].t.norm(); });

	const auto v3 = [](const cv::Scalar& s) { return cv::Vec3d(s[0], s[1], s[2]); };
	const std::array<cv::Vec3d, kNumPaints> col{v3(o.white_bgr), v3(o.black_bgr), v3(o.green_bgr)};
	for (size_t i : order)
	{
		const PlanarPrint& pr = prints[i].print;
		const mrpt::poses::CPose3D print_T_camera = world_T_camera - prints[i].world_T_print;
		if (!(print_T_camera.x() > 0)) continue;  // seen from behind: the wall
		const auto project = [&](const Polygon3& p)
		{
			return sim::detail::projectPinhole(
				sim::detail::clipNear(p, kNearM), cam.fx(), cam.fy(), cam.cx(), cam.cy());
		};
		const double S = pr.sheet_half_m;
		const Polygon2 sheet = project(faceRect(cam_T[i], -S, -S, S, S));
		const cv::Rect roi = pixelBounds(sheet, W, H, 1);
		if (roi.empty()) continue;
		cv::Mat c_sheet = cv::Mat::zeros(roi.size(), CV_64FC1);
		std::array<cv::Mat, kNumPaints> acc;
		for (auto& m : acc) m = cv::Mat::zeros(roi.size(), CV_64FC1);
		sim::detail::accumulateCoverage(sheet, c_sheet, roi.tl());
		for (const FaceRect& r : pr.rects)
			sim::detail::accumulateCoverage(
				project(faceRect(cam_T[i], r.s0, r.t0, r.s1, r.t1)), acc[r.paint], roi.tl(),
				r.weight);
		for (int y = 0; y < roi.height; ++y)
		{
			cv::Vec3f* px = img.ptr<cv::Vec3f>(roi.y + y) + roi.x;
			const double* c0 = c_sheet.ptr<double>(y);
			const double* aw = acc[kWhite].ptr<double>(y);
			const double* ab = acc[kBlack].ptr<double>(y);
			const double* ag = acc[kGreen].ptr<double>(y);
			for (int x = 0; x < roi.width; ++x)
			{
				if (c0[x] == 0) continue;
				const cv::Vec3d bg(px[x][0], px[x][1], px[x][2]);
				const cv::Vec3d v = bg * (1 - c0[x]) + col[kWhite] * aw[x] + col[kBlack] * ab[x] +
									col[kGreen] * ag[x];
				px[x] = cv::Vec3f(float(v[0]), float(v[1]), float(v[2]));
			}
		}
	}
	// The camera: sim::render()'s pipeline with the effects' blur and noise.
	sim::RenderOptions camera = o;
	camera.blur_sigma_px = fx.blur_sigma_px;
	camera.noise_sigma = fx.noise_sigma;
	out.bgr = sim::cameraImage(img, camera.drawn(seed), cam.cx(), cam.cy(), seed);
	return out;
}

double checkAgainstSim(
	const MapLandmark& lm, const CameraModel& cam, const mrpt::poses::CPose3D& world_T_camera,
	const sim::RenderOptions& background, const Effects& effects, uint64_t seed)
{
	sim::Scene scene;
	scene.map.landmarks.push_back(lm);
	scene.camera = cam;
	scene.world_T_camera = world_T_camera;
	sim::RenderOptions o = background;
	o.blur_sigma_px = effects.blur_sigma_px;
	o.noise_sigma = effects.noise_sigma;
	const sim::Render ref = sim::render(scene, o, seed);
	PlacedPrint p{
		makePrint(PrintKind::Codemark, lm.id, lm.geometry().inner_size_m), lm.world_T_landmark()};
	const Frame mine = renderFrame({p}, cam, world_T_camera, background, effects, seed);
	cv::Mat diff;
	cv::absdiff(ref.image, mine.bgr, diff);
	double mx = 0;
	cv::minMaxLoc(diff.reshape(1), nullptr, &mx);
	return mx;
}

}  // namespace codemark::bench
