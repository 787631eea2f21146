#pragma once
/** \file pipeline.h
 * One camera image to one landmark observation: detect (libs/detect), then
 * measure each landmark (libs/pose), then wrap the result as the MRPT
 * observation of the plugin (libs/mrpt). The flow of an image of docs/design.md.
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
/** The shipped calibration of C_P that the tools measure with unless told
 * otherwise (share/codemark/calibration/<name>.ini; docs/calibration.md). */
constexpr const char* kDefaultCalibration = "family";

/** The pose options the tools measure with: the closed form refined on P,
 * C_R to second order in C_L, and the noise model of C_P from the
 * calibration \a path_or_name (a file, or the name of a shipped calibration,
 * pose::resolveCalibration()). Throws as pose::loadCalibration(), and
 * std::runtime_error naming the folders searched when a shipped calibration
 * is missing. */
pose::PoseOptions calibratedPoseOptions(const std::string& path_or_name = kDefaultCalibration);

/** Everything that turns an image into measurements. */
struct PipelineOptions
{
	detect::DetectorOptions detector;
	/** The pose library's options; the noise model from the default
	 * calibration (calibratedPoseOptions()). */
	pose::PoseOptions pose = calibratedPoseOptions();
	/** The landmark's proportions and default size (share/codemark/landmark.ini). */
	LandmarkGeometry geometry;
	/** When set, a landmark's size comes from its map entry's scale, and
	 * IDs not in the map are still reported (with the default size). */
	std::optional<LandmarkMap> map;
	/** When set, replaces the camera stored in each image observation. */
	std::optional<CameraModel> camera_override;
	/** Folder of externally stored images with relative file names (a
	 * rawlog's `<name>_Images`, imagesDirectoryOf()). Empty: MRPT's
	 * process-wide CImage::getImagesPathBase(), which two rawlogs read in
	 * parallel (codemark-bench's jobs) would share. */
	std::string images_dir;
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
	/** Detections whose corners gave no measurement (degenerate). */
	std::vector<detect::DetectedLandmark> unmeasured;
	detect::StageTimings timings;  //!< the detector's own time
	double pose_us = 0;	 //!< time spent in the pose library [us]
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

/** \a c with each sighting measured again from its stored corners, quality
 * and camera (\a o's camera_override when set) under \a o's pose options
 * and landmark sizes: a landmark observation annotated with one calibration,
 * measured with another. Throws as pose::measure(). */
CObservationCodedLandmarks::Ptr remeasure(
	const CObservationCodedLandmarks& c, const PipelineOptions& o);

/** The BGR cv::Mat of an image observation (loading external storage, a
 * relative file name from \a images_dir, or MRPT's
 * CImage::getImagesPathBase() when it is empty); grey images are
 * converted. Throws std::runtime_error naming the file when
 * it cannot be loaded. */
cv::Mat imageAsBgr(const mrpt::obs::CObservationImage& img, const std::string& images_dir = {});

/** `<dir>/<name without extension>_Images` for a rawlog path: MRPT's
 * external-image folder. Computed here because MRPT 2.5.8's
 * CRawlog::detectImagesDirectory drops the slash for paths with a
 * directory part. */
std::string imagesDirectoryOf(const std::string& rawlog_path);

}  // namespace codemark::pipeline
