#pragma once
/** \file mrpt_landmarks.h
 * MRPT's landmark ground-truth files, as shipped beside its range-bearing
 * datasets (e.g. /usr/share/mrpt/datasets/kf-slam_demo_ground_truth.txt):
 * one point landmark per line, 7 whitespace-separated columns
 *     x[m] y[m] z[m] type 0 0 id
 * (written by MRPT's landmark simulators: `type` is the landmark class, the
 * two zeros are unused, `id` is the landmark ID that the dataset's
 * CObservationBearingRange readings carry). Lines starting with `%` or `#`
 * and blank lines are comments.
 */
#include <codemark/landmark/map.h>

#include <Eigen/Core>
#include <map>

#include <iosfwd>
#include <string>

namespace mrpt::slam
{
class CRangeBearingKFSLAM2D;
}

namespace codemark::filters
{
/** Reads an MRPT landmark ground-truth file as point landmarks: id, x, y, z
 * [m] from the file, yaw 0, scale 1. IDs are any non-negative integers (MRPT
 * datasets are not limited to the coded landmarks' 0..255). Throws
 * codemark::MapFileError naming the file and line on a wrong number of
 * columns, a non-numeric or non-finite value, a non-integer or negative ID,
 * or a duplicate ID; std::runtime_error when the file cannot be opened. */
LandmarkMap loadMrptLandmarksFile(const std::string& path);

/** As loadMrptLandmarksFile(), from a stream; \a name is used in errors. */
LandmarkMap parseMrptLandmarks(std::istream& in, const std::string& name);

/** True when \a path looks like an MRPT landmark file rather than a codemark
 * map (spec section 3): its first non-comment line has 7 columns. Lets tools
 * accept both with one --map option. False when the file cannot be read. */
bool isMrptLandmarksFile(const std::string& path);

/** The point landmarks of MRPT's CRangeBearingKFSLAM2D (stock kf-slam's
 * filter) by landmark ID: (x, y) [m] in its map frame. */
std::map<int, Eigen::Vector2d> rangeBearingSlamLandmarks(
	const mrpt::slam::CRangeBearingKFSLAM2D& kf);

/** A landmark map from \a path: the spec's format or MRPT's landmark file
 * (isMrptLandmarksFile()). Throws as LandmarkMap::load(). */
LandmarkMap loadAnyMap(const std::string& path);

}  // namespace codemark::filters
