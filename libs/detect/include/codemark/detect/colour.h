#pragma once
/** \file colour.h
 * The colours of a detected landmark as the detector's segmentation sees
 * them (codemark-detect --colour-report): the fill's and the frame's mean
 * colour, their HSI hue, saturation and intensity, and how far each lies
 * from the thresholds that decide whether a print is found. A user checks
 * a print under their own light with it before recording.
 */
#include <codemark/detect/detector.h>
#include <codemark/detect/options.h>
#include <codemark/landmark/camera.h>
#include <codemark/landmark/geometry.h>

#include <opencv2/core.hpp>

#include <string>

namespace codemark::detect
{
/** One surface's mean colour and its HSI coordinates, as the segmentation
 * predicate defines them (SegmentationParams). */
struct MeasuredColour
{
	double r = 0, g = 0, b = 0;	 //!< mean channels [grey levels 0..255]
	double hue_deg = 0;	 //!< HSI hue, hexcone form, green = 120 [deg, 0..360)
	double saturation = 0;	//!< 1 - min(R, G, B) / I [0..1]
	double intensity = 0;  //!< I = (R + G + B) / 3 [grey levels]
	int samples = 0;  //!< pixels averaged
};

/** The fill and frame colours of one detection and their margins to the
 * detector's thresholds: positive is inside the accepted range, negative
 * outside (that test refuses the print). */
struct ColourReport
{
	MeasuredColour fill;  //!< the green band between the frame and the code board
	MeasuredColour frame;  //!< the black frame, its middle half across
	double margin_intensity = 0;  //!< fill I - segmentation.min_intensity [grey levels]
	double margin_saturation = 0;  //!< fill S - segmentation.min_saturation [-]
	double margin_hue_min_deg = 0;	//!< fill hue - segmentation.hue_min_deg [deg]
	double margin_hue_max_deg = 0;	//!< segmentation.hue_max_deg - fill hue [deg]
	/** code.max_black_ratio - frame ink / fill G [-] (the ink: the two darkest
	 * sides with the blur's share of fill and sheet removed, as the check
	 * compares it). */
	double margin_black_ratio = 0;
	/** code.min_contrast subtracted from fill G - frame G [grey levels]. */
	double margin_contrast = 0;
};

/** HSI of one colour [grey levels], as MeasuredColour defines it. */
MeasuredColour hsiOf(double r, double g, double b);

/** Measures the fill and the frame of detection \a d in \a bgr (CV_8UC3)
 * through its corners' homography, and their margins to \a opt. */
ColourReport colourReport(
	const cv::Mat& bgr, const codemark::Detection& d, const CameraModel& camera,
	const LandmarkGeometry& geometry, const DetectorOptions& opt);

/** The report as a JSON object: {"fill": {"rgb", "hue_deg", "saturation",
 * "intensity"}, "frame": {...}, "margins": {"intensity", "saturation",
 * "hue_min_deg", "hue_max_deg", "black_ratio", "contrast"}}. */
std::string colourReportJson(const ColourReport& r);

}  // namespace codemark::detect
