#pragma once
/** \file json.h
 * The detector's JSON Lines output (docs/spec.md section 5): one object
 * per image, `{"image", "width", "height", "time_ms", "detections": [{"id",
 * "corners", "P", ...}]}` or `{"image", "error"}`.
 */
#include <codemark/detect/detector.h>

#include <string>
#include <utility>
#include <vector>

namespace codemark::detect
{
/** Extra members of one detection object, already encoded as JSON values
 * (e.g. {"L", "[1.2, 0.1, 0.0]"}), appended after "P" in the given order:
 * where the pose library adds L, C_L, pose_in_landmark and C_R. */
using JsonFields = std::vector<std::pair<std::string, std::string>>;

/** \a s as a JSON string literal, quotes included. */
std::string jsonString(const std::string& s);

/** A number with up to 10 significant digits (corners to 1e-4 px and
 * better); non-finite values become null. */
std::string jsonNumber(double v);

/** One line (without the newline) for an image. \a extra, when not empty,
 * holds one JsonFields per detection. */
std::string imageToJson(
	const std::string& image, int width, int height, double time_ms,
	const std::vector<DetectedLandmark>& detections, const std::vector<JsonFields>& extra = {});

/** One line (without the newline) for an input that could not be read. */
std::string errorToJson(const std::string& image, const std::string& error);

}  // namespace codemark::detect
