#pragma once
/** \file detection.h
 * Plain data that crosses libraries (docs/design.md, "Libraries"): what the detector
 * reports for one landmark. Defined here so the MRPT plugin can carry it
 * without depending on the detector.
 */
#include <Eigen/Core>
#include <array>
#include <cstdint>

namespace codemark
{
/** How trustworthy one detection is. */
struct DetectionQuality
{
	/** RMS distance of the edge points to the fitted line, per side in the
	 * order top, right, bottom, left [px]. */
	std::array<double, 4> line_rms_px{{0, 0, 0, 0}};
	/** Number of edge points that supported each side's line fit. */
	std::array<int, 4> line_support{{0, 0, 0, 0}};
	/** Smallest margin between a code cell's mean intensity and the
	 * black/green decision threshold, over the nine cells [grey levels,
	 * 0..255]; for cells read through the blur (docs/design.md, "Cells
	 * through the blur"), the cells' smallest distance to the boundary with
	 * another code. Larger is safer. */
	double code_margin = 0;
	/** Area of the reference square in the image [px^2]. */
	double area_px = 0;
	/** Standard deviation of each corner coordinate estimated from the line
	 * fits [px]; 0 when not estimated. */
	double corner_sigma_px = 0;
	/** Per side (top, right, bottom, left): the green fill clipped at the
	 * sensor's top along all of it, so the edge rests on the dark half of
	 * its transition only (restored from an edge model where it fits): it
	 * is less certain (pose::PoseOptions::clipped_side_sigma_px). */
	std::array<bool, 4> fill_clipped{{false, false, false, false}};
	/** The image's noise at the landmark: the standard deviation of G
	 * [grey levels] in its black centre cell (detect::centreCellNoiseRms(),
	 * where at least 5 x 5 px of the cell lie 3.5 px clear of its sides:
	 * nearer than about 1.5-2 m with the paper's camera), else in the flat
	 * unclipped 8 x 8 px blocks of a window three times the landmark's size
	 * around it (detect::surroundNoiseRms()); 0 when not measured (fewer
	 * than 8 such blocks). pose::PoseOptions::reference_noise_grey scales
	 * the noise-driven part of C_P with it. */
	double image_noise_grey = 0;
	/** How far the camera moves the edges towards their dark sides [px]:
	 * half the median excess of the green bands' measured width (between
	 * the frame and a black code cell) over the printed one. A transfer
	 * curve, sharpening or a clipped fill make it positive, printers' dot
	 * gain negative; about 0 in linear light. 0 when not measured. */
	double edge_bend_px = 0;
	/** The standard error of edge_bend_px [px], from the bands' scatter
	 * over the landmark and its correlation between neighbouring profiles
	 * (what a camera's denoising, demosaicing and compression spread along
	 * an edge averages out less). */
	double edge_bend_se_px = 0;
};

/** One detected landmark. */
struct Detection
{
	int id = -1;  //!< 0..255
	/** The four reference points (inner frame corners) in raw (distorted)
	 * pixel coordinates of the image, sub-pixel, pixel (0,0) at the centre of
	 * the top-left pixel; order top-left, top-right, bottom-right, bottom-left
	 * as they appear in the image. */
	std::array<Eigen::Vector2d, 4> corners;
	DetectionQuality quality;
};

}  // namespace codemark
