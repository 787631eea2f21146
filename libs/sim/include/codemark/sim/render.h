#pragma once
/** \file render.h
 * The test renderer: landmarks of a map seen by a camera, with exact
 * perspective and exact ground truth (corners, visibility, L, the camera's
 * pose in each landmark frame). Deterministic for a seed.
 */
#include <codemark/landmark/camera.h>
#include <codemark/landmark/map.h>
#include <codemark/landmark/truth.h>
#include <codemark/sim/camera_pipeline.h>
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/poses/CPose3D.h>

#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace codemark::sim
{
/** What is behind the landmarks. */
enum class Background
{
	Flat,  //!< uniform grey
	Textured,  //!< smooth random texture (a wall)
	Cluttered  //!< texture plus distractors: green shapes, black rectangles, posters
};

/** Renderer settings. Every effect is off at its default except a flat
 * background, so that a default render is exact. */
struct RenderOptions : public mrpt::config::CLoadableOptions
{
	Background background = Background::Flat;
	double background_grey = 128;  //!< Flat background level, mean of the texture [0..255]
	/** Number of distractor shapes with Cluttered (green blobs and
	 * rectangles, black frames filled with red, blue, white or grey,
	 * posters with black and green print, marker-like grids), drawn under
	 * the landmarks. */
	int distractors = 0;

	/** Colours at gain 1, BGR [0..255]. Black is printed black, not 0. */
	cv::Scalar black_bgr{25, 25, 25};
	cv::Scalar white_bgr{235, 235, 235};  //!< the sheet's white (quiet margin)
	cv::Scalar green_bgr{0, 255, 0};  //!< fluorescent green: sRGB #00FF00

	double gain = 1.0;	//!< illumination gain (multiplies all intensities)
	/** Relative gain change across the image along gradient_angle_rad:
	 * the gain grows linearly from gain * (1 - gradient/2) to
	 * gain * (1 + gradient/2) (0.5: +-25% from the centre); |gradient| < 2. */
	double gradient = 0.0;
	/** Direction in which the gain grows, counter-clockwise from +u as
	 * displayed (pi/2: brighter towards the top) [rad]. */
	double gradient_angle_rad = 0.0;

	double noise_sigma = 0.0;  //!< Gaussian pixel noise [grey levels]
	double blur_sigma_px = 0.0;	 //!< Gaussian blur [px]
	double motion_blur_px = 0.0;  //!< length of linear motion blur [px]
	/** Direction of the motion, counter-clockwise from +u as displayed [rad]. */
	double motion_blur_angle_rad = 0.0;
	int jpeg_quality = 0;  //!< 0 = no JPEG round trip, else 1..100

	/** @name The camera pipeline (camera_pipeline.h), after the optics above
	 * (blur_sigma_px, motion blur) and before the codec (jpeg_quality).
	 * Every stage is off at its default.
	 * @{ */
	/** Name of the preset these keys started from ("" = none); see
	 * applyPreset(). */
	std::string preset;
	double defocus_radius_px = 0;  //!< defocus disc radius, linear light [px]
	/** Lateral chromatic aberration: radial shift of R against G at the
	 * farthest image corner, outwards positive [px]. */
	double ca_red_px = 0;
	double ca_blue_px = 0;	//!< the same for B [px]
	double vignetting = 0;	//!< relative loss of light at the farthest corner [0..0.9]
	double exposure = 1;  //!< exposure gain of the sensor signal (> 0)
	double wb_red = 1;	//!< white-balance gain of R against G
	double wb_blue = 1;	 //!< white-balance gain of B against G
	/** Electrons at full scale (255); 0 = no shot and read noise. */
	double full_well_e = 0;
	double read_noise_e = 0;  //!< read noise RMS [e-] (with full_well_e > 0)
	BayerLayout bayer = BayerLayout::None;	//!< colour filter array
	Demosaic demosaic = Demosaic::Bilinear;	 //!< demosaicing, with a Bayer layout
	Transfer transfer = Transfer::Linear;  //!< transfer curve
	double gamma = 2.2;	 //!< exponent of Transfer::Gamma
	double filmic_strength = 0.25;	//!< strength of Transfer::Filmic's S-curve [0..0.9]
	double unsharp_sigma_px = 1.0;	//!< unsharp mask radius [px]
	double unsharp_amount = 0;	//!< unsharp mask amount; 0 = no sharpening
	/** Chroma subsampling of the delivered 8-bit image, before any JPEG
	 * (which subsamples 4:2:0 on its own). */
	ChromaSubsampling chroma_subsampling = ChromaSubsampling::None;
	/** @} */

	/** A numeric key drawn per frame, uniformly in [lo, hi]. */
	struct RangeDraw
	{
		std::string key;
		double lo = 0, hi = 0;
	};
	/** A named choice (bayer, demosaic, transfer, chroma_subsampling) drawn per frame among
	 * \a names, each equally likely. */
	struct ChoiceDraw
	{
		std::string key;
		std::vector<std::string> names;
	};
	std::vector<RangeDraw> range_draws;	 //!< set from "key = lo hi" in an ini
	std::vector<ChoiceDraw> choice_draws;  //!< set from "key = NAME NAME ..." or "any"

	/** These options with every range and choice drawn for one frame:
	 * deterministic for \a seed, no draws left. */
	RenderOptions drawn(uint64_t seed) const;
	/** True when a stage of the camera pipeline beyond the renderer's own
	 * (blur, motion blur, noise, JPEG) is on, or anything is drawn. */
	bool hasCameraStages() const;

	/** Sets the camera pipeline's keys (and the optics', noise's and codec's:
	 * blur_sigma_px, noise_sigma, jpeg_quality) to the preset \a name, the
	 * scene's keys (background, colours, light, occlusion) untouched:
	 *  - `linear`: no stage but sensor noise (full well 10000 e-, read 5 e-);
	 *  - `machine-vision`: linear transfer, optics sigma 0.5 px, vignetting
	 *    0.05, full well 20000 e-, read 3 e-, lossless (PNG);
	 *  - `webcam`: optics sigma 0.6 px, CA +0.3 / -0.3 px, vignetting 0.2,
	 *    white balance R 1.05 B 0.95, full well 8000 e-, read 6 e-, RGGB
	 *    with bilinear demosaicing, sRGB, unsharp sigma 1.0 amount 0.5,
	 *    JPEG 85;
	 *  - `phone`: optics sigma 0.5 px, CA +0.2 / -0.2 px, vignetting 0.1,
	 *    full well 5000 e-, read 3 e-, BGGR with edge-aware demosaicing,
	 *    filmic 0.25, unsharp sigma 1.0 amount 0.9, JPEG 75;
	 *  - `family`: every range drawn per frame: optics sigma 0-1.2 px,
	 *    defocus 0-1.5 px, CA -0.7..0.7 px, vignetting 0-0.35, exposure
	 *    0.5-1.5, white balance 0.75-1.3, full well 5000-20000 e-, read
	 *    2-10 e-, any Bayer layout and demosaicing, any transfer curve
	 *    (gamma 1.8-2.6, filmic 0-0.35), unsharp sigma 0.6-1.5 amount 0-1,
	 *    JPEG 60-95.
	 * Throws std::invalid_argument naming the key 'preset' and the presets. */
	void applyPreset(const std::string& name);
	/** The presets' names, in the order above. */
	static std::vector<std::string> presetNames();
	/** The keys that preset \a name sets, as lines of an ini section
	 * ("key = value"); throws std::invalid_argument for an unknown name. */
	static std::string presetKeys(const std::string& name);

	/** Fraction [0..1] of each landmark's reference square to hide behind an
	 * occluder (a grey bar, level 100 at gain 1, in the landmark's plane,
	 * covering the square from one side chosen from the seed per landmark,
	 * and beyond the sheet on that side); 0 = none. */
	double occlusion = 0.0;

	/** Samples per pixel side (n x n per pixel) used only when the camera
	 * has lens distortion; without distortion the coverage is exact. */
	int supersampling = 8;

	/** Throws std::invalid_argument naming the key of the first bad value
	 * (e.g. a negative sigma, jpeg_quality outside 0..100, gain <= 0). */
	void validate() const;

	/** Reads the keys of this struct from \a section (background by name:
	 * Flat, Textured or Cluttered; colours as "B G R"), then validate().
	 * A `preset` key is applied first, so the section's other keys override
	 * it. The camera pipeline's numeric keys, blur_sigma_px, noise_sigma and
	 * jpeg_quality also take "lo hi" (drawn per frame); bayer, demosaic,
	 * transfer and chroma_subsampling take several names or `any`. An unknown name or a value out
	 * of its range throws std::invalid_argument naming the key. */
	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;
};

/** What to render. */
struct Scene
{
	LandmarkMap map;
	CameraModel camera;
	/** Optical frame of the camera in the world (MRPT camera convention:
	 * z along the optical axis, x right, y down). */
	mrpt::poses::CPose3D world_T_camera;
};

/** Exact ground truth of one landmark of the map. */
struct LandmarkTruth
{
	int id = -1;
	/** Reference points (inner frame corners) in raw (distorted) pixels, in
	 * the landmark's own order TL, TR, BR, BL as seen from the front (the
	 * order as they appear in the image for a camera with little roll).
	 * NaN for a corner that is not in front of the camera. */
	std::array<Eigen::Vector2d, 4> corners_px;
	/** The same corners undistorted (ideal pixels, same fx, fy, cx, cy);
	 * NaN for a corner that is not in front of the camera. */
	std::array<Eigen::Vector2d, 4> corners_ideal_px;
	/** All of the landmark's outer frame is in front of the camera, inside
	 * the image with a border of at least 1 px (0.5 <= u <= width - 1.5,
	 * likewise v), and seen from the front side. Geometric: occlusion by
	 * another landmark or by the occluder bar does not change it. */
	bool fully_visible = false;
	bool in_front = false;	//!< the landmark centre is in front of the camera
	bool facing = false;  //!< the camera is on the printed side
	double occluded_fraction =
		0;	//!< fraction of the reference square behind the occluder bar, as rendered
	double area_px = 0;	 //!< area of the reference square in the image (raw corners) [px^2]; 0
						 //!< unless all corners are in front
	/** Exact primary measurement (primaryMeasurementFromIdeal of
	 * corners_ideal_px); zero unless all corners are in front. */
	Eigen::Vector4d P = Eigen::Vector4d::Zero();
	SightingTruth sighting;	 //!< L and the camera's planar pose in frame L
	mrpt::poses::CPose3D landmark_T_camera;	 //!< exact 6-DoF pose
};

/** One rendered image. */
struct Render
{
	cv::Mat image;	//!< CV_8UC3, BGR, camera resolution
	std::vector<LandmarkTruth> truth;  //!< one per map landmark, map order
};

/** Renders \a scene. Deterministic for a given seed. In order: the
 * background (with its distractors); the landmarks far to near, each mixed
 * in by its exact pixel coverage (or by n x n samples per pixel with lens
 * distortion) together with its occluder, a landmark seen from behind (not
 * facing) not drawn (its back is the wall it hangs on); illumination gain
 * and gradient; then the camera pipeline (camera_pipeline.h) with the
 * options drawn for this frame (RenderOptions::drawn(seed)). Throws
 * std::invalid_argument on invalid options. */
Render render(const Scene& scene, const RenderOptions& options, uint64_t seed);

/** A renderer: the scene's linear light through the camera pipeline, with
 * exact ground truth (render() is the project's own; povray.h has an
 * independent one). */
using Renderer = std::function<Render(const Scene&, const RenderOptions&, uint64_t seed)>;

/** The ground truth of render() without rendering (cheap): one entry per
 * map landmark, map order; occluded_fraction is 0. */
std::vector<LandmarkTruth> groundTruth(const Scene& scene);

/** The name of \a b as read by RenderOptions ("Flat", "Textured", "Cluttered"). */
const char* backgroundName(Background b);
/** The Background named \a name (case-insensitive); throws
 * std::invalid_argument otherwise. */
Background backgroundFromName(const std::string& name);

/** A scene of one landmark (ID \a id, the spec's size, its centre \a z_m
 * above the floor at the world's origin) seen by \a camera: the setup of
 * the pose calibration, the accuracy map and their tests. Place the camera
 * with levelCameraLookingAt(scene.map.landmarks[0], ...). */
Scene singleLandmarkScene(
	const CameraModel& camera = CameraModel::paperDefault(), int id = 37, double z_m = 0.5);

/** A level camera (optical axis horizontal, no roll) at horizontal distance
 * \a distance_m [m] from \a landmark's centre, seen at \a view_angle_rad between
 * the line of sight and the landmark's outward normal (counter-clockwise
 * positive, seen from above), at \a height_m above the landmark centre,
 * turned so that the landmark centre appears \a bearing_rad left of the
 * optical axis (phi1). The optical centre is at (d cos a, d sin a, h) in
 * frame L, so sightingTruth() gives L = (d, bearing, a - bearing). Returns
 * world_T_camera (optical frame). */
mrpt::poses::CPose3D levelCameraLookingAt(
	const MapLandmark& landmark, double distance_m, double view_angle_rad, double height_m = 0.0,
	double bearing_rad = 0.0);

}  // namespace codemark::sim
