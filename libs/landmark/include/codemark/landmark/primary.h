#pragma once
/** \file primary.h
 * The primary measurement P = [x1 y1 x2 y2] (docs/spec.md section 4):
 * x1, x2 the image x-coordinates of the midpoints of the left and right
 * inner vertical frame edges, y1, y2 the half-lengths of those edges, from
 * the undistorted corners, in pixels of the single focal length
 * lambda = fx relative to the principal point (y scaled by fx/fy).
 * Defined here, below the detector and the pose library, because both the
 * detector's output and the renderer's ground truth carry it.
 */
#include <codemark/landmark/camera.h>

#include <Eigen/Core>
#include <array>

namespace codemark
{
/** P from the four corners in raw (distorted) pixels, order TL, TR, BR, BL.
 * \a lambda_px_out, when given, receives lambda = fx [px]. */
Eigen::Vector4d primaryMeasurement(
	const std::array<Eigen::Vector2d, 4>& corners_raw_px, const CameraModel& camera,
	double* lambda_px_out = nullptr);

/** As primaryMeasurement(), from corners already undistorted (ideal pixels
 * with the camera's fx, fy, cx, cy). */
Eigen::Vector4d primaryMeasurementFromIdeal(
	const std::array<Eigen::Vector2d, 4>& corners_ideal_px, const CameraModel& camera);

}  // namespace codemark
