#pragma once
/** \file uncertainty_figure.h
 * The paper's Fig. 3 as a PNG: the predicted uncertainty of a sighting
 * (pose::predictUncertainty()) on a grid of robot positions in front of a
 * landmark, drawn for codemark-uncertainty; and that tool's text reports.
 */
#include <codemark/landmark/camera.h>
#include <codemark/pose/uncertainty.h>

#include <optional>
#include <string>

namespace codemark::eval
{
/** Magnifications used by drawUncertaintyFigure(). */
struct FigureScales
{
	double ellipse = 1;	 //!< position ellipses
	double heading = 1;	 //!< heading wedges
};

/** Options of the paper's Fig. 3. */
struct FigureOptions
{
	double sigma_px = pose::kDefaultSigmaPx;  //!< noise of each component of P [px]
	/** When set, C_P from this noise model (a calibration) in place of
	 * sigma_px, described in the figure as noise_label. */
	std::optional<pose::PoseOptions> noise;
	std::string noise_label;
	double scale = 1.0;	 //!< landmark scale (1 = A4)
	double x_min_m = 0.5, x_max_m = 3.0;  //!< robot distances along the normal X_L [m]
	double y_max_m = 2.0;  //!< robots at |Y_L| <= y_max_m [m]
	double step_m = 0.5;  //!< grid step [m]
	double max_view_angle_deg = 70;	 //!< positions beyond this angle are skipped [deg]
	/** Positions where the reference square is smaller [px] are marked "not
	 * detectable". */
	double min_size_px = 30;
	/** Magnification of the ellipses and heading wedges; 0 = automatic (the
	 * largest ellipse's semi-major axis is about 0.45 of a grid step,
	 * rounded down to 1-2-5). */
	double magnification = 0;
	/** Magnification of the heading wedges; 0 = automatic (the widest
	 * wedge's half-angle about 20 deg, rounded down to 1-2-5, at least 1). */
	double heading_magnification = 0;
	double pixels_per_m = 160;	//!< drawing scale [px/m]
};

/** Draws Fig. 3: the landmark seen from above, a robot (a level camera
 * looking at the landmark centre) at each grid position with its 95%
 * position ellipse (chi-square 2 dof, 5.991) and a +-1.96 sigma heading
 * wedge, and writes it as PNG to \a path. Returns the magnifications used.
 * Throws std::runtime_error when the file cannot be written. */
FigureScales drawUncertaintyFigure(
	const std::string& path, const CameraModel& camera, const FigureOptions& options);

/** A text report of \a advice: the scale, the printed sizes and the
 * predicted accuracy at that scale. */
std::string describeSizeAdvice(const pose::SizeAdvice& advice, double k_sigma);

/** The accuracy to expect from a landmark of \a scale across \a distances_m
 * at \a view_angle_rad (level camera, landmark centred), as a text table:
 * distance, size in px, sigma of l2, phi1, phi2, of the position (worst
 * direction) and heading, and whether the detector can use it (size >=
 * \a min_size_px and in the image). */
std::string accuracyTable(
	const CameraModel& camera, double scale, double sigma_px, double view_angle_rad,
	const std::vector<double>& distances_m, double min_size_px = 30.0);

/** accuracyTable() with C_P from \a noise's noise model, described in the
 * header line as \a noise_label. */
std::string accuracyTable(
	const CameraModel& camera, double scale, const pose::PoseOptions& noise,
	const std::string& noise_label, double view_angle_rad, const std::vector<double>& distances_m,
	double min_size_px = 30.0);

}  // namespace codemark::eval
