#pragma once
/** \file detector.h
 * The landmark detector of Baczyk, Kasinski and Skrzypczynski (2003),
 * section 2.2 (docs/design.md, "The detector"): colour segmentation,
 * components, edgels, segments, quadrangles, sub-pixel corners, code.
 */
#include <codemark/detect/options.h>
#include <codemark/landmark/camera.h>
#include <codemark/landmark/detection.h>
#include <codemark/landmark/geometry.h>

#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <string>
#include <vector>

namespace codemark::detect
{
/** Wall-clock time of each stage for one image [microseconds]. */
struct StageTimings
{
	double segmentation_us = 0;	 //!< smoothing + colour mask
	double components_us = 0;  //!< connected components, moments, ROIs
	double edgels_us = 0;  //!< gradients, edgels, edgel domains (all ROIs)
	double segments_us = 0;	 //!< side selection (all ROIs)
	double quads_us = 0;  //!< linking into quadrangles (all ROIs)
	double subpixel_us = 0;	 //!< edge profiles, line fits, corners (all ROIs)
	double code_us = 0;	 //!< frame check and code reading (all ROIs)
	double total_us = 0;  //!< the whole detect() call, debug images excluded
};

/** One detected landmark with its primary measurement. */
struct DetectedLandmark
{
	Detection detection;  //!< ID, raw-pixel corners TL, TR, BR, BL, quality
	/** P = [x1 y1 x2 y2] from the undistorted corners (primary.h) [px of
	 * lambda = fx, relative to the principal point]. */
	Eigen::Vector4d P = Eigen::Vector4d::Zero();
};

/** Counts of candidates surviving each stage (for tuning and debugging). */
struct StageCounts
{
	int components = 0;	 //!< connected components of the mask
	int rois = 0;  //!< components that passed area and shape tests
	int quads = 0;	//!< ROIs where four sides were linked
	int fitted = 0;	 //!< quadrangles with four good line fits
	int decoded = 0;  //!< landmarks reported
};

/** What detect() found in one image. */
struct DetectionResult
{
	std::vector<DetectedLandmark> landmarks;  //!< sorted by ID
	StageTimings timings;
	StageCounts counts;
};

/** Detects every fully visible landmark in \a bgr (CV_8UC3, BGR; an empty
 * or tiny image gives no detection; another type throws
 * std::invalid_argument). \a camera gives the distortion used for the line
 * fits and P; \a geometry the landmark's proportions. With \a debug_dir
 * non-empty, writes the mask, components, edgels, fitted lines and an
 * overlay there as PNG images (the directory must exist). */
DetectionResult detect(
	const cv::Mat& bgr, const CameraModel& camera, const LandmarkGeometry& geometry,
	const DetectorOptions& options, const std::string& debug_dir = {});

/** Draws the detections on \a bgr: the frame, the corners (TL marked), the
 * ID and the landmark's axes (Y_L red, Z_L blue) at the centre. */
void drawDetections(cv::Mat& bgr, const std::vector<DetectedLandmark>& landmarks);

}  // namespace codemark::detect
