#pragma once
/** \file geometry.h
 * The printed landmark of the spec (docs/spec.md section 1) and its
 * frame L (section 2): origin at the centre of the green square, X_L the
 * outward normal, Z_L up, Y_L = Z_L x X_L (to the right of an observer who
 * faces the landmark).
 */
#include <mrpt/config/CLoadableOptions.h>

#include <Eigen/Core>
#include <array>

namespace codemark
{
/** Sizes of one landmark, metres. Defaults are the A4 landmark of the spec;
 * scaled() multiplies every size and keeps the proportions. */
struct LandmarkGeometry : public mrpt::config::CLoadableOptions
{
	double outer_size_m = 0.200;  //!< outer edge of the black frame [m]
	double inner_size_m = 0.160;  //!< inner edge of the frame: the reference square [m]
	double cell_size_m = 0.030;	 //!< one code-board cell (3x3 board, centred) [m]
	double margin_m = 0.005;  //!< minimum white quiet margin around the frame [m]

	/** The A4 landmark with every size multiplied by \a scale (> 0). */
	static LandmarkGeometry scaled(double scale);
	/** This geometry with every size multiplied by \a scale (finite, > 0;
	 * else std::invalid_argument). */
	LandmarkGeometry scaledBy(double scale) const;

	/** h: half-length of the vertical inner edge [m] (0.08 m by default). */
	double innerHalf() const { return 0.5 * inner_size_m; }
	double outerHalf() const { return 0.5 * outer_size_m; }

	/** The four reference points (inner frame corners) in frame L [m], in
	 * the order top-left, top-right, bottom-right, bottom-left as seen from
	 * the front. */
	std::array<Eigen::Vector3d, 4> referencePoints() const;

	/** A point of the landmark's face given as (s right, t up) as seen from
	 * the front [m], expressed in frame L: (0, s, t). */
	static Eigen::Vector3d faceToLandmark(double s_right_m, double t_up_m)
	{
		return {0.0, s_right_m, t_up_m};
	}

	/** Centre of code cell (row, col), rows from the top and columns from the
	 * left as seen from the front, as face coordinates (s right, t up) [m]. */
	Eigen::Vector2d cellCentreFace(int row, int col) const;

	/** Throws std::invalid_argument unless 0 < cell board < inner < outer. */
	void validate() const;

	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;
};

}  // namespace codemark
