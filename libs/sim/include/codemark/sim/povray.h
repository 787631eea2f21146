#pragma once
/** \file povray.h
 * An independent renderer: the scene (landmarks of a map on textured walls
 * above a textured floor, lit by point or area lights) as a POV-Ray 3.7
 * scene built from the landmark spec alone, ray traced by the `povray`
 * program in linear light, then the project's camera pipeline
 * (camera_pipeline.h). Ground truth is the geometry (groundTruth()), never
 * measured from an image. See docs/povray.md.
 */
#include <codemark/sim/render.h>
#include <mrpt/config/CLoadableOptions.h>

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace codemark::sim
{
/** Named light levels: the sheet's white at the landmark centre (with the
 * default white_bgr 235) lands at about 0.92 of full scale under Normal. */
enum class LightLevel
{
	Dim,  //!< 0.35 x normal
	Normal,	 //!< 1.0: the white sheet near the project renderer's level
	Bright	//!< 1.6 x normal: white and fluorescent green saturate
};

/** How the scene is lit. */
enum class LightType
{
	/** One shadowless point lamp per landmark, in front of it and above,
	 * its light fading with distance (POV-Ray's fade_power 2). */
	Point,
	/** The same lamps as horizontal square panels of
	 * area_light_samples^2 points: a broader, softer light. */
	Area,
	/** No lamps: every surface shows its reflectance times the level (no
	 * shading): flat regions are exactly uniform, for measurements. */
	Ambient
};

/** Paint of the walls. */
enum class WallTexture
{
	Auto,  //!< Plain for RenderOptions' Flat background, else Plaster
	Plain,	//!< uniform, reflectance background_grey / 255
	Plaster,  //!< smooth noise around background_grey (granular paint)
	Brick  //!< brick pattern with mortar, around background_grey
};

/** Cover of the floor. */
enum class FloorTexture
{
	Plain,	//!< uniform grey (reflectance 0.35)
	Tiles,	//!< 0.3 m light and dark square tiles
	Wood  //!< wood grain in brown
};

const char* lightLevelName(LightLevel l);  //!< "dim", "normal", "bright"
const char* lightTypeName(LightType t);	 //!< "point", "area", "ambient"
const char* wallTextureName(WallTexture t);	 //!< "auto", "plain", "plaster", "brick"
const char* floorTextureName(FloorTexture t);  //!< "plain", "tiles", "wood"
/** Parsers of the names above (case-insensitive); throw
 * std::invalid_argument naming \a key and the accepted names. */
LightLevel lightLevelFromName(const std::string& name, const std::string& key = "light");
LightType lightTypeFromName(const std::string& name, const std::string& key = "light_type");
WallTexture wallTextureFromName(const std::string& name, const std::string& key = "wall");
FloorTexture floorTextureFromName(const std::string& name, const std::string& key = "floor");

/** Settings of the POV-Ray renderer (section [povray] of an ini file). */
struct PovrayOptions : public mrpt::config::CLoadableOptions
{
	/** @name Light
	 * @{ */
	LightLevel light = LightLevel::Normal;	//!< named level
	/** Multiplies the named level (and RenderOptions::gain multiplies
	 * both) (> 0). */
	double light_scale = 1.0;
	LightType light_type = LightType::Point;  //!< lamps or flat light
	/** Share of the level at each landmark centre that comes from the
	 * ambient light (the rest from the lamps) [0..1]; 1 with
	 * LightType::Ambient. */
	double ambient_share = 0.3;
	/** Relative change of the lamps' irradiance across each landmark's
	 * sheet, from its left to its right edge as seen from the front,
	 * divided by the irradiance at its centre (0.3: +-15%); the lamp moves
	 * sideways and closer to make it. |light_gradient| <= 0.45. */
	double light_gradient = 0.0;
	double lamp_distance_m = 1.5;  //!< lamp in front of its landmark, at gradient 0 [m]
	double lamp_height_m = 0.8;	 //!< lamp above its landmark's centre [m]
	double area_light_size_m = 0.4;	 //!< side of an area lamp's square [m]
	int area_light_samples = 3;	 //!< area lamp: points per side (2..8)
	/** @} */

	/** @name Surroundings
	 * @{ */
	WallTexture wall = WallTexture::Auto;  //!< paint of the walls
	FloorTexture floor = FloorTexture::Tiles;  //!< cover of the floor
	/** Places the wall and floor patterns (and the distractors on the
	 * walls): the same seed gives the same room in every frame. */
	uint64_t texture_seed = 1;
	/** @} */

	/** @name POV-Ray
	 * @{ */
	std::string executable = "povray";	//!< program, found on PATH unless it holds a '/'
	/** Antialias_Threshold: a pixel is supersampled when it differs from
	 * a neighbour by at least this (sum of the channels' absolute
	 * differences, linear 0..1). */
	double aa_threshold = 0.01;
	/** Sampling_Method: 1 (non-recursive: depth x depth samples in the
	 * pixel, plus its centre) or 2 (recursive corners, 2^depth + 1 per
	 * side). */
	int aa_method = 1;
	int aa_depth = 9;  //!< Antialias_Depth (method 1: 1..9; method 2: 1..9)
	double aa_jitter = 1.0;	 //!< Jitter_Amount; 0 = no jitter (a regular grid)
	/** Directory of the cached renders; empty: $CODEMARK_POVRAY_CACHE, else
	 * $XDG_CACHE_HOME/codemark/povray, else ~/.cache/codemark/povray. */
	std::string cache_dir;
	int threads = 1;  //!< Work_Threads of one render (>= 1)
	/** @} */

	/** The level at the landmark centres: light's factor x light_scale x
	 * \a gain. */
	double level(double gain = 1.0) const;
	/** The cache directory in use (cache_dir or the environment's). */
	std::string cacheDirectory() const;
	/** The POV-Ray settings that change a render (resolution aside), as
	 * `Key=value` lines: part of the cache key. */
	std::string renderSettings() const;

	/** Throws std::invalid_argument naming the key of the first bad value. */
	void validate() const;
	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;
};

/** The POV-Ray 3.7 scene of \a scene: `global_settings { assumed_gamma 1.0 }`,
 * the camera (the pinhole of scene.camera exactly: POV-Ray's ray
 * direction + u right + v up, u, v in [-0.5, 0.5] over the image, with
 * the principal point in `direction`), each facing landmark of the map as
 * polygons in its plane (white sheet, black frame, green fill, black code
 * cells, each layer 0.02 mm proud of the one below it, the green fill in
 * the landmark plane itself, none casting shadows), a wall behind each
 * landmark (one plane per wall, several landmarks sharing it), the floor
 * and the ceiling, the lamps and the ambient light. Colours are
 * RenderOptions' black_bgr, white_bgr and green_bgr read as linear
 * reflectances (value / 255). With RenderOptions::occlusion > 0 each
 * landmark gets its occluding bar (grey 100 / 255, from the side drawn from
 * \a seed as render() does); with the Cluttered background,
 * RenderOptions::distractors shapes are placed on the wall around each
 * landmark (from texture_seed). Deterministic. Throws
 * std::invalid_argument naming the camera when it has lens distortion, and
 * on invalid options. */
std::string povrayScene(
	const Scene& scene, const RenderOptions& options, const PovrayOptions& pov, uint64_t seed);

/** Renders \a scene with POV-Ray into the cache (a 16-bit linear PNG named
 * by a hash of the scene text, the resolution and renderSettings(); reused
 * when present) and returns its path. Throws std::runtime_error with one
 * line naming the program when it is missing, or with POV-Ray's last
 * message when the render fails. */
std::string povrayCachedRender(
	const Scene& scene, const RenderOptions& options, const PovrayOptions& pov, uint64_t seed);

/** The linear image of a cached render: CV_32FC3 BGR, 0..255 = full
 * scale. Throws std::runtime_error when \a path is not a 16-bit PNG. */
cv::Mat readLinearPng(const std::string& path);

/** Renders \a scene with POV-Ray: povrayCachedRender(), its linear image,
 * then cameraImage() with options.drawn(seed). The truth is
 * groundTruth(scene) (occluded_fraction set as rendered). Honoured from
 * RenderOptions: the colours, gain (scales the light), background (Flat:
 * plain walls; Textured, Cluttered: textured walls), background_grey (the
 * walls' mean reflectance x 255), distractors (with Cluttered: on the
 * walls), occlusion, and every camera-stage key (blur, noise, JPEG and the
 * camera pipeline's). Not used: gradient and gradient_angle_rad (an image
 * plane gradient; here the lamps' falloff and
 * PovrayOptions::light_gradient make the light's gradients) and
 * supersampling (POV-Ray's antialiasing governs). */
Render renderPovray(
	const Scene& scene, const RenderOptions& options, uint64_t seed, const PovrayOptions& pov);

/** renderPovray() with \a pov bound, as a Renderer. */
Renderer povrayRenderer(const PovrayOptions& pov);

}  // namespace codemark::sim
