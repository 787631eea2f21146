#pragma once
/** \file pipeline.h
 * One camera image to one landmark observation: detect (libs/detect), then
 * measure each landmark (libs/pose), then wrap the result as the MRPT
 * observation of the plugin (libs/mrpt). ARCHITECTURE.md's flow of an image.
 */
#include <codemark/detect/detector.h>
#include <codemark/landmark/camera.h>
#include <codemark/landmark/geometry.h>
#include <codemark/landmark/map.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <codemark/pose/measurement.h>
#include <mrpt/obs/CObservationImage.h>

#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <vector>

namespace codemark::pipeline
{
/** Noise of P's components for codemark's own detector [px], calibrated
 * from its measured error (landmark-spec.md section 4 asks for this
 * instead of the paper's 1 px): codemark-annotate on simulated loops
 * (textured wall, gain gradient 0.3, noise sigma 2, blur 0.8, landmarks at
 * 1-5 m and up to 60 deg), error of L against the renderer's exact truth
 * divided by the sigma that the closed form propagates, per component, so
 * that the RMS of the normalised errors of l2 (set by y1, y2) and phi1 (set
 * by x1, x2) is about 1 (tests/pipeline prints these figures). x1, x2 come
 * from whole-edge line fits and are good to a few hundredths of a pixel; y1,
 * y2 depend on where the top and bottom lines cut the sides, and at range on
 * the thin frame, and are a few times worse. */
constexpr double kDetectorSigmaXPx = 0.03;
constexpr double kDetectorSigmaYPx = 0.10;

/** The pose options codemark's detector is calibrated for. */
inline pose::PoseOptions detectorCalibratedPoseOptions()
{
	pose::PoseOptions o;
	o.sigma_px = kDetectorSigmaXPx;
	o.sigma_y_px = kDetectorSigmaYPx;
	return o;
}

/** Everything that turns an image into measurements. */
struct PipelineOptions
{
	detect::DetectorOptions detector;
	pose::PoseOptions pose = detectorCalibratedPoseOptions();
	/** The landmark's proportions and default size (share/codemark/landmark.ini). */
	LandmarkGeometry geometry;
	/** When set, a landmark's size comes from its map entry's scale, and
	 * IDs not in the map are still reported (with the default size). */
	std::optional<LandmarkMap> map;
	/** When set, replaces the camera stored in each image observation. */
	std::optional<CameraModel> camera_override;
};

/** One measured landmark: the detection and its measurement. */
struct MeasuredLandmark
{
	detect::DetectedLandmark detected;
	pose::Measurement measurement;
};

/** The result of one image. */
struct ImageResult
{
	std::vector<MeasuredLandmark> landmarks;
	detect::StageTimings timings;  //!< the detector's own time
	double pose_us = 0;  //!< time spent in the pose library [us]
};

/** The geometry of landmark \a id under \a o (its map scale, else the default). */
LandmarkGeometry geometryFor(int id, const PipelineOptions& o);

/** Detects and measures the landmarks of one BGR image. */
ImageResult processImage(
	const cv::Mat& bgr, const CameraModel& camera, const PipelineOptions& o,
	const std::string& debug_dir = {});

/** The landmark observation of an image observation: label
 * `<label>_LANDMARKS`, the image's timestamp and cameraPose, the camera used
 * (override or the image's). Throws std::runtime_error if the image cannot
 * be loaded (e.g. a missing external file). */
CObservationCodedLandmarks::Ptr observeImage(
	const mrpt::obs::CObservationImage& img, const PipelineOptions& o,
	ImageResult* result_out = nullptr);

/** The BGR cv::Mat of an image observation (loading external storage);
 * grey images are converted. Throws std::runtime_error naming the file when
 * it cannot be loaded. */
cv::Mat imageAsBgr(const mrpt::obs::CObservationImage& img);

/** `<dir>/<name without extension>_Images` for a rawlog path: MRPT's
 * external-image folder. Computed here because MRPT 2.5.8's
 * CRawlog::detectImagesDirectory drops the slash for paths with a
 * directory part (mrpt-notes.md). */
std::string imagesDirectoryOf(const std::string& rawlog_path);

}  // namespace codemark::pipeline
