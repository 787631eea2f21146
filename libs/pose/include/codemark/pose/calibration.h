#pragma once
/** \file calibration.h
 * Calibration files: the noise model of P (C_P, PoseOptions'
 * noise-model keys) as an ini file, with its provenance in comments.
 * docs/calibration.md specifies the format.
 *
 *   # made by: codemark-bench-pose-calib --renders 1200 ... --out FILE
 *   # data: ...
 *   # date: 2026/12/04,06:31:42.655778
 *   [pose]
 *   sigma_px = 0.0238
 *   ...
 *
 * A calibration's [pose] section holds every key of calibrationKeys() and
 * nothing else; the same keys in any other [pose] section (an EKF config's,
 * a detector ini's) override it field by field.
 */
#include <codemark/pose/measurement.h>

#include <string>
#include <vector>

namespace codemark::pose
{
/** The noise-model keys of PoseOptions, in the order a calibration file
 * lists them. */
const std::vector<std::string>& calibrationKeys();

/** \a base with the noise model of the calibration file \a path. Throws
 * std::invalid_argument "FILE:LINE: ..." on an unknown key in its [pose]
 * section, a missing key, a value that is not a finite number (or a table of
 * size:value pairs), a negative sigma, size or ratio, or a correlation
 * outside (-1, 1) (clipped_side_correlation: [0, 1)); std::runtime_error
 * when the file cannot be read or has no [pose] section. */
PoseOptions loadCalibration(const std::string& path, const PoseOptions& base = PoseOptions());

/** Writes \a o's noise model as a calibration file: \a provenance as "# "
 * comment lines (the command, the data, the date), then [pose] with every
 * key of calibrationKeys(), values that read back exactly. Throws
 * std::runtime_error when the file cannot be written. */
void saveCalibration(
	const std::string& path, const PoseOptions& o, const std::vector<std::string>& provenance);

/** \a o with every standard deviation of its noise model multiplied by \a
 * factor (C_P by factor^2): sigma_px, sigma_y_px, the growth terms, the
 * sigma and noise tables, clipped_side_sigma_px. Ratios and correlations
 * stay. */
PoseOptions scaledNoiseModel(const PoseOptions& o, double factor);

/** The path of the shipped calibration \a name
 * (share/codemark/calibration/<name>.ini, found as findShareFile() finds
 * files). Throws std::runtime_error naming the folders it looked in when it
 * is not there. */
std::string shippedCalibrationPath(const std::string& name);

/** The names of the shipped calibrations (the files' stems), sorted. */
std::vector<std::string> shippedCalibrationNames();

/** A calibration given as a file path, or as the name of a shipped one
 * (a word without '/' or ".ini" that is not an existing file). */
std::string resolveCalibration(const std::string& path_or_name);

}  // namespace codemark::pose
