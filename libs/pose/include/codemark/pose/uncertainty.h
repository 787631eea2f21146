#pragma once
/** \file uncertainty.h
 * Uncertainty before printing (paper section 3, Fig. 3): the predicted
 * covariance of a sighting by a level camera at a given distance and angle,
 * the landmark scale needed for a wanted accuracy, the accuracy of a given
 * scale across distances, and the paper's Fig. 3 (95% ellipses on a grid)
 * as a PNG. The logic of the codemark-uncertainty tool.
 */
#include <codemark/landmark/camera.h>
#include <codemark/landmark/geometry.h>
#include <codemark/pose/measurement.h>

#include <optional>
#include <string>
#include <vector>

namespace codemark::pose
{
/** The predicted uncertainty of one sighting (closed form, level camera
 * with its optical centre at the landmark centre's height unless given). */
struct SightingUncertainty
{
	/** The landmark's outer frame is in front of the camera and inside the
	 * image; the other fields are meaningful only then. */
	bool in_image = false;
	double size_px = 0;	 //!< vertical size of the reference square, min(2 y1, 2 y2) [px]
	Measurement measurement;  //!< predicted P, L, C_L, pose_in_landmark, C_R
	double sigma_l2_m = 0;	//!< standard deviation of the range l2 [m]
	double sigma_phi1_rad = 0;	//!< of the bearing phi1 [rad]
	double sigma_phi2_rad = 0;	//!< of phi2 [rad]
	/** Position standard deviation along its worst direction: sqrt of the
	 * largest eigenvalue of C_R's position block [m]. */
	double sigma_position_m = 0;
	double sigma_heading_rad = 0;  //!< of the heading theta [rad]
};

/** Predicts the sighting of a landmark \a geometry by a level camera at
 * horizontal distance \a distance_m from its centre, on the line of sight at
 * \a view_angle_rad from the outward normal (CCW seen from above), the
 * centre appearing \a bearing_rad left of the optical axis, the optical
 * centre \a height_m above the landmark centre; \a sigma_px the noise of each
 * component of P. */
SightingUncertainty predictUncertainty(
	const CameraModel& camera, const LandmarkGeometry& geometry, double sigma_px, double distance_m,
	double view_angle_rad, double bearing_rad = 0, double height_m = 0);

/** The same with C_P from \a noise's noise model (a calibration,
 * calibration.h: size-dependent, correlated). */
SightingUncertainty predictUncertainty(
	const CameraModel& camera, const LandmarkGeometry& geometry, const PoseOptions& noise,
	double distance_m, double view_angle_rad, double bearing_rad = 0, double height_m = 0);

/** Pose options whose C_P is the spec's constant diagonal, \a sigma_px on
 * each component of P [px]. */
PoseOptions constantNoise(double sigma_px);

/** The answer of sizeFor(). */
struct SizeAdvice
{
	bool found = false;	 //!< false: no printable scale meets the request in this image
	double scale = 0;  //!< multiply the A4 landmark by this (outer frame 0.2 m * scale)
	SightingUncertainty at;	 //!< the prediction at that scale
	std::string reason;	 //!< why not found, or which requirement set the scale
};

/** The smallest landmark scale (relative to the A4 landmark) that gives
 * k_sigma * sigma_position <= \a position_m and k_sigma * sigma_heading <=
 * \a heading_rad at the given distance and angle (level camera, landmark
 * centred in the image), and a reference square at least \a min_size_px
 * tall; not found when the landmark would no longer fit in the image.
 * Bisection on the scale (the sigmas fall monotonically with it). */
SizeAdvice sizeFor(
	const CameraModel& camera, double sigma_px, double position_m, double heading_rad,
	double distance_m, double view_angle_rad, double k_sigma = 2.0, double min_size_px = 30.0);

/** sizeFor() with C_P from \a noise's noise model. */
SizeAdvice sizeFor(
	const CameraModel& camera, const PoseOptions& noise, double position_m, double heading_rad,
	double distance_m, double view_angle_rad, double k_sigma = 2.0, double min_size_px = 30.0);

}  // namespace codemark::pose
