#pragma once
/** \file uncertainty_figure.h
 * The paper's Fig. 3 as a PNG: the predicted uncertainty of a sighting
 * (pose::predictUncertainty()) on a grid of robot positions in front of a
 * landmark, drawn for codemark-uncertainty.
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

}  // namespace codemark::eval
