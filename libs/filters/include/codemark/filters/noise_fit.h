#pragma once
/** \file noise_fit.h
 * The logic of codemark-calibrate-noise: identify the sighting noise model
 * (C_P's constant and size-dependent parts, for x and for y) from a recorded
 * run with odometry and a landmark map, without ground truth, by maximising
 * the likelihood of the EKF's innovations over the run.
 *
 * The model fitted is C_P's parametric form (PoseOptions): sigma_x(w)^2 =
 * a_x^2 + (b_x (size_reference_px / w)^e_x)^2 with w the apparent width,
 * the same for y with the apparent height. The four scales a_x, b_x, a_y,
 * b_y are free; the exponents, the correlations and every other key stay the
 * starting calibration's. A tabulated start is first turned into that form
 * (a least-squares fit of its table with exponent 1, its table's
 * correlation for both parts). The motion noise stays the config's: with
 * it held fixed, the innovations' spread beyond the prediction's is the
 * sightings' own. The components the sightings barely inform (the bearing)
 * test that motion noise, and a warning says when they contradict it.
 */
#include <codemark/filters/localizer.h>
#include <codemark/pose/measurement.h>

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

namespace codemark::filters
{
/** What to fit from. */
struct NoiseFitRequest
{
	std::string rawlog;	 //!< a run with odometry (either rawlog format; images or annotated)
	std::string map_file;  //!< the landmark map (spec) or MRPT landmark file
	std::string config_file;  //!< the EKF's ini ([ekf], [stepper], [detector], [pose], [localize])
	/** The starting calibration (file or shipped name): images are detected
	 * and every sighting measured with it, then with the fitted scales. */
	std::string calibration;
	std::string camera_file;  //!< when set, replaces the camera stored in the rawlog
	int max_evaluations = 400;	//!< of the likelihood, by the simplex search
};

/** The four scales of the model, their names and units [px]. */
struct NoiseScales
{
	double sigma_x_px = 0;	//!< constant part of x1, x2 (PoseOptions::sigma_px)
	double growth_x_px = 0;	 //!< size-dependent part of x1, x2 (growth_x_px)
	double sigma_y_px = 0;	//!< constant part of y1, y2 (sigma_y_px)
	double growth_y_px = 0;	 //!< size-dependent part of y1, y2 (growth_y_px)
};

/** What the fit found. */
struct NoiseFitResult
{
	pose::PoseOptions start;  //!< the starting model in parametric form
	pose::PoseOptions fitted;  //!< the identified model
	NoiseScales start_scales, fitted_scales;
	/** One standard deviation of each fitted scale, relative (of its log),
	 * from the likelihood's curvature at the optimum, in NoiseScales' order;
	 * optimistic, since consecutive innovations are correlated. */
	Eigen::Vector4d relative_std = Eigen::Vector4d::Zero();
	InnovationSummary before, after;  //!< under the start and the fitted model
	long steps = 0;	 //!< camera frames of the run
	long sightings = 0;	 //!< coded sightings of mapped landmarks
	double width_min_px = 0, width_max_px = 0;	//!< the sightings' apparent widths
	int evaluations = 0;  //!< likelihood evaluations
	/** Why the run may not identify the model (few sightings, one distance
	 * only, a scale without curvature); empty when it does. */
	std::vector<std::string> warnings;
};

/** \a o's noise model in parametric form (see the file comment). */
pose::PoseOptions parametricNoiseModel(const pose::PoseOptions& o);

/** The scales of a parametric model, and the model with other scales. */
NoiseScales noiseScales(const pose::PoseOptions& o);
pose::PoseOptions withNoiseScales(const pose::PoseOptions& o, const NoiseScales& s);

/** Fits the model. \a progress(fraction) while reading the rawlog and while
 * fitting. Throws std::runtime_error / std::invalid_argument naming the
 * file on bad input, and when the run holds no sighting of a mapped
 * landmark. */
NoiseFitResult fitSightingNoise(
	const NoiseFitRequest& request, const std::function<void(double)>& progress = {});

}  // namespace codemark::filters
