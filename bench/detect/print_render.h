#pragma once
/** \file print_render.h
 * Bench-only: renders printed planar patterns (our landmark, an ArUco
 * DICT_4X4_50 marker, an AprilTag tag36h11 tag) with the exact pixel
 * coverage of libs/sim, so that every detector of the benchmark sees the
 * same camera, poses, background, blur and noise. libs/sim draws only our
 * landmark, so the peers' markers are drawn here from libs/sim's internal
 * raster (src/raster.h) and background (src/background.h); our landmark is
 * drawn by the same code path, and checkAgainstSim() confirms that it gives
 * sim::render()'s image.
 */
#include <codemark/landmark/camera.h>
#include <codemark/landmark/map.h>
#include <codemark/sim/render.h>
#include <mrpt/poses/CPose3D.h>

#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace codemark::bench
{
/** Which pattern is printed. */
enum class PrintKind
{
	Codemark,  //!< our landmark (LandmarkGeometry, ID 0..255)
	Aruco,	//!< OpenCV ArUco DICT_4X4_50 (ID 0..49), 6 x 6 cells with its black border
	AprilTag  //!< AprilTag 3 tag36h11 (ID 0..586), 8 x 8 cells inside its white ring
};

/** Printed paint of a region of the sheet. */
enum Paint : int
{
	kWhite = 0,
	kBlack,
	kGreen,
	kNumPaints
};

/** An axis-aligned rectangle of the face [m] (s right, t up, seen from the
 * front) whose exact image coverage, times \a weight, is added to the
 * coverage of \a paint. Nested regions are written with +1/-1 weights (e.g.
 * black frame = +black outer square, -black inner square), which keeps the
 * mix exact where one pixel straddles several edges. */
struct FaceRect
{
	double s0, t0, s1, t1;
	Paint paint;
	double weight;
};

/** A printed sheet: its outline (a square of half-size sheet_half [m]
 * covering the background) and the painted rectangles on it. */
struct PlanarPrint
{
	PrintKind kind = PrintKind::Codemark;
	int id = 0;
	double sheet_half_m = 0;  //!< half the sheet's side, quiet margin included [m]
	/** Half the side of the reference square whose corners are the ground
	 * truth: our inner frame edge; the markers' outer black edge [m]. */
	double ref_half_m = 0;
	std::vector<FaceRect> rects;
};

/** The print of \a kind with \a id and a reference square of
 * \a ref_size_m [m] (160 mm for all in the benchmark). Codemark uses
 * LandmarkGeometry scaled so that inner_size_m = ref_size_m. Markers get a
 * white quiet margin of one cell (AprilTag: its own white ring). Throws
 * std::invalid_argument for an ID outside the family. */
PlanarPrint makePrint(PrintKind kind, int id, double ref_size_m);

/** One print placed in the world: frame L of \a pose (CPose3D(x, y, z,
 * yaw, 0, 0), X_L the outward normal, face (s, t) at (0, s, t) in L). */
struct PlacedPrint
{
	PlanarPrint print;
	mrpt::poses::CPose3D world_T_print;
};

/** Ground truth of one placed print. */
struct PrintTruth
{
	int id = -1;
	/** Corners of the reference square in pixels (pixel (0,0) = centre of
	 * the top-left pixel), TL, TR, BR, BL as seen from the front. */
	std::array<Eigen::Vector2d, 4> corners_px;
	/** Whole sheet in front of the camera and at least 1 px inside the image. */
	bool sheet_visible = false;
	double ref_height_px = 0;  //!< vertical extent of the reference square [px]
	double ref_side_px = 0;	 //!< mean side length of the reference square [px]
};

/** Post-effects applied identically to every frame: blur then noise, as
 * sim::render orders them. */
struct Effects
{
	double blur_sigma_px = 0.8;	 //!< Gaussian blur [px]
	double noise_sigma = 2.0;  //!< Gaussian noise [grey levels]
};

/** A rendered frame and the truth of each print in it. */
struct Frame
{
	cv::Mat bgr;  //!< CV_8UC3
	std::vector<PrintTruth> truth;	//!< one per print, input order
};

/** Ground truth only (cheap). \a camera must have no lens distortion. */
PrintTruth truthOf(
	const PlacedPrint& p, const CameraModel& camera, const mrpt::poses::CPose3D& world_T_camera);

/** Renders \a prints over \a background's background (sim's
 * makeBackground with its distractors, seed \a seed), far to near by exact
 * coverage, then blur (BORDER_REPLICATE) and noise (sim's noise stream of
 * \a seed), rounding to 8 bits: for our landmark alone this is
 * sim::render() with the same options and seed. Throws
 * std::invalid_argument for a camera with lens distortion. */
Frame renderFrame(
	const std::vector<PlacedPrint>& prints, const CameraModel& camera,
	const mrpt::poses::CPose3D& world_T_camera, const sim::RenderOptions& background,
	const Effects& effects, uint64_t seed);

/** Largest absolute difference (grey levels) between renderFrame() of our
 * landmark \a lm and sim::render() of the same scene, options and seed. */
double checkAgainstSim(
	const MapLandmark& lm, const CameraModel& camera, const mrpt::poses::CPose3D& world_T_camera,
	const sim::RenderOptions& background, const Effects& effects, uint64_t seed);

const char* printKindName(PrintKind k);

}  // namespace codemark::bench
