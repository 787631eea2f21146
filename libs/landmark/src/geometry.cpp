#include <codemark/landmark/geometry.h>
#include <codemark/landmark/text.h>
#include <mrpt/config/CConfigFileBase.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace codemark
{
LandmarkGeometry LandmarkGeometry::scaledBy(double scale) const
{
	if (!(scale > 0) || !std::isfinite(scale))
	{
		std::ostringstream s;
		s << "landmark scale must be finite and > 0, got " << scale;
		throw std::invalid_argument(s.str());
	}
	LandmarkGeometry g = *this;
	g.outer_size_m *= scale;
	g.inner_size_m *= scale;
	g.cell_size_m *= scale;
	g.margin_m *= scale;
	return g;
}

LandmarkGeometry LandmarkGeometry::scaled(double scale)
{
	return LandmarkGeometry().scaledBy(scale);
}

std::array<Eigen::Vector3d, 4> LandmarkGeometry::referencePoints() const
{
	const double h = innerHalf();
	// As seen from the front: right is +Y_L, up is +Z_L.
	return {
		faceToLandmark(-h, +h), faceToLandmark(+h, +h), faceToLandmark(+h, -h),
		faceToLandmark(-h, -h)};
}

Eigen::Vector2d LandmarkGeometry::cellCentreFace(int row, int col) const
{
	if (row < 0 || row > 2 || col < 0 || col > 2)
		throw std::out_of_range("code cell row/col must be in 0..2");
	return {(col - 1) * cell_size_m, (1 - row) * cell_size_m};
}

void LandmarkGeometry::validate() const
{
	const bool ok = std::isfinite(outer_size_m) && std::isfinite(inner_size_m) &&
					std::isfinite(cell_size_m) && std::isfinite(margin_m) && cell_size_m > 0 &&
					3 * cell_size_m < inner_size_m && inner_size_m < outer_size_m && margin_m >= 0;
	if (!ok)
	{
		std::ostringstream s;
		s << "invalid landmark geometry: need 0 < 3*cell_size_m (" << 3 * cell_size_m
		  << ") < inner_size_m (" << inner_size_m << ") < outer_size_m (" << outer_size_m
		  << ") and margin_m (" << margin_m << ") >= 0";
		throw std::invalid_argument(s.str());
	}
}

void LandmarkGeometry::loadFromConfigFile(
	const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	requireIniNumbers(c, s, {"outer_size_m", "inner_size_m", "cell_size_m", "margin_m", "scale"});
	MRPT_LOAD_CONFIG_VAR(outer_size_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(inner_size_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(cell_size_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(margin_m, double, c, s);
	// An optional overall scale, as in the map file's scale column.
	*this = scaledBy(c.read_double(s, "scale", 1.0));
	validate();
}

void LandmarkGeometry::saveToConfigFile(
	mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	c.write(s, "outer_size_m", outer_size_m, -1, -1, "outer edge of the black frame [m]");
	c.write(
		s, "inner_size_m", inner_size_m, -1, -1,
		"inner edge of the frame, the reference square [m]");
	c.write(s, "cell_size_m", cell_size_m, -1, -1, "one of the 3x3 code cells [m]");
	c.write(s, "margin_m", margin_m, -1, -1, "minimum white margin around the frame [m]");
}

}  // namespace codemark
