#pragma once
/** \file map.h
 * The landmark map file (docs/spec.md section 3): one landmark per line,
 * `id x[m] y[m] z[m] yaw[deg] [scale]`, `#` starts a comment. yaw is the
 * direction of X_L (the outward normal) in the world frame.
 */
#include <codemark/landmark/geometry.h>
#include <mrpt/poses/CPose3D.h>

#include <iosfwd>
#include <stdexcept>
#include <string>
#include <vector>

namespace codemark
{
/** One landmark of a map. */
struct MapLandmark
{
	int id = 0;	 //!< 0..255
	double x_m = 0, y_m = 0, z_m = 0;  //!< centre of the green square, world frame [m]
	double yaw_rad = 0;	 //!< direction of the outward normal X_L in the world [rad]
	double scale = 1.0;	 //!< multiplies every size of the A4 landmark

	/** Pose of frame L in the world: CPose3D(x, y, z, yaw, 0, 0). */
	mrpt::poses::CPose3D world_T_landmark() const;
	LandmarkGeometry geometry() const { return LandmarkGeometry::scaled(scale); }
};

/** A parse error that names the file and the line. */
class MapFileError : public std::runtime_error
{
   public:
	MapFileError(const std::string& file, int line, const std::string& what);
	const std::string& file() const { return file_; }
	int line() const { return line_; }

   private:
	std::string file_;
	int line_;
};

/** The landmarks of a map, unique by ID. */
class LandmarkMap
{
   public:
	std::vector<MapLandmark> landmarks;

	/** The landmark with \a id, or nullptr. */
	const MapLandmark* find(int id) const;

	/** Reads a map file; throws MapFileError naming the line on a bad number
	 * of fields, non-numeric values, NaN/inf, a scale <= 0, a duplicate ID or
	 * an ID outside 0..255, and std::runtime_error when the file cannot be
	 * opened. */
	static LandmarkMap load(const std::string& path);
	/** As load(), from a stream; \a name is used in error messages. */
	static LandmarkMap parse(std::istream& in, const std::string& name);

	/** Writes the map in the same format (yaw in degrees, the scale column
	 * only where it is not 1). Throws std::runtime_error on I/O failure. */
	void save(const std::string& path) const;
	void write(std::ostream& out) const;
};

}  // namespace codemark
