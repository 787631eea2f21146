#pragma once
/** \file camera.h
 * A pinhole camera with optional plumb_bob lens distortion, over MRPT's
 * mrpt::img::TCamera (docs/spec.md section 2). Loaded from MRPT's
 * `[CAMERA_PARAMS]` ini (the output of camera-calib) or from ROS/OpenCV
 * calibration YAML.
 *
 * Pixel convention: (0,0) is the centre of the top-left pixel; u right, v
 * down. Camera (optical) frame: z along the optical axis, x right, y down.
 */
#include <mrpt/img/TCamera.h>

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace codemark
{
class CameraModel
{
   public:
	/** The camera of the paper: 640x480, fx = fy = 800, cx = 319.5,
	 * cy = 239.5, no distortion. */
	CameraModel();
	explicit CameraModel(const mrpt::img::TCamera& params);

	/** Loads a camera file: `.ini`/`.cfg`/`.txt` as MRPT's `[CAMERA_PARAMS]`
	 * section (or \a section), `.yaml`/`.yml` as ROS camera_info or OpenCV
	 * calibration YAML. Throws std::runtime_error naming the file and what is
	 * wrong. Non-fatal problems (e.g. `dist` given without
	 * `distortion_model`, which MRPT then silently drops) are appended to
	 * \a warnings, or printed to stderr when \a warnings is null. */
	static CameraModel load(
		const std::string& path, std::vector<std::string>* warnings = nullptr,
		const std::string& section = "CAMERA_PARAMS");

	/** The camera used wherever a tool needs one and none is given:
	 * `share/codemark/camera-paper.ini`, or the built-in equal default when
	 * that file cannot be found. */
	static CameraModel paperDefault();

	const mrpt::img::TCamera& params() const { return params_; }
	int width() const { return static_cast<int>(params_.ncols); }
	int height() const { return static_cast<int>(params_.nrows); }
	double fx() const { return params_.fx(); }
	double fy() const { return params_.fy(); }
	double cx() const { return params_.cx(); }
	double cy() const { return params_.cy(); }
	/** True when a distortion model with a non-zero coefficient is set. */
	bool hasDistortion() const;

	/** Raw (distorted) pixel of a point given in the camera optical frame
	 * [m]; nullopt when the point is not in front of the camera (z <= 0). */
	std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_cam) const;

	/** Raw pixel of an undistorted normalised image point (x/z, y/z). */
	Eigen::Vector2d distortNormalized(const Eigen::Vector2d& xn) const;

	/** Undistorted normalised coordinates (x/z, y/z) of a raw pixel
	 * (iterative inversion of the plumb_bob model, as OpenCV's
	 * undistortPoints). */
	Eigen::Vector2d undistortToNormalized(const Eigen::Vector2d& raw_px) const;

	/** Ideal (undistorted) pixel of a raw pixel, with the same fx, fy, cx,
	 * cy. Identity when there is no distortion. */
	Eigen::Vector2d undistortPixel(const Eigen::Vector2d& raw_px) const;

	/** Writes the camera as MRPT's `[CAMERA_PARAMS]` ini text. */
	std::string toIniText(const std::string& section = "CAMERA_PARAMS") const;

   private:
	mrpt::img::TCamera params_;
};

/** Finds a file shipped under share/codemark/ (\a relative, e.g.
 * "camera-paper.ini"): $CODEMARK_SHARE_DIR, then the source tree, then the
 * install prefix. Empty when not found. */
std::string findShareFile(const std::string& relative);

/** The folders findShareFile() looks in, in its order. */
std::vector<std::string> shareSearchDirs();

}  // namespace codemark
