#include <codemark/landmark/map.h>
#include <codemark/landmark/text.h>

#include <cstdlib>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

namespace codemark
{
mrpt::poses::CPose3D MapLandmark::world_T_landmark() const
{
	return mrpt::poses::CPose3D(x_m, y_m, z_m, yaw_rad, 0.0, 0.0);
}

MapFileError::MapFileError(const std::string& file, int line, const std::string& what)
	: std::runtime_error(file + ":" + std::to_string(line) + ": " + what), file_(file), line_(line)
{
}

const MapLandmark* LandmarkMap::find(int id) const
{
	for (const auto& l : landmarks)
		if (l.id == id) return &l;
	return nullptr;
}

namespace
{
// Parses one numeric field strictly: the whole token must be a finite number.
double parseNumber(const std::string& tok, const char* field, const std::string& name, int line)
{
	if (const auto v = parseFiniteNumber(tok)) return *v;
	const bool number = std::isnan(std::strtod(tok.c_str(), nullptr)) ||
						std::isinf(std::strtod(tok.c_str(), nullptr));
	throw MapFileError(
		name, line,
		std::string("field '") + field + (number ? "' is not finite: '" : "' is not a number: '") +
			tok + "'");
}
}  // namespace

LandmarkMap LandmarkMap::parse(std::istream& in, const std::string& name)
{
	static const char* kFields[] = {"id", "x", "y", "z", "yaw", "scale"};
	LandmarkMap map;
	std::set<int> seen;
	std::string text;
	int line = 0;
	while (std::getline(in, text))
	{
		++line;
		if (const auto hash = text.find('#'); hash != std::string::npos) text.erase(hash);
		std::istringstream ss(text);
		std::vector<std::string> tok;
		for (std::string t; ss >> t;) tok.push_back(t);
		if (tok.empty()) continue;
		if (tok.size() != 5 && tok.size() != 6)
			throw MapFileError(
				name, line,
				"expected 5 or 6 fields 'id x y z yaw_deg [scale]', found " +
					std::to_string(tok.size()));
		double v[6] = {0, 0, 0, 0, 0, 1.0};
		for (std::size_t i = 0; i < tok.size(); ++i)
			v[i] = parseNumber(tok[i], kFields[i], name, line);
		if (v[0] != std::floor(v[0]) || v[0] < 0 || v[0] > 255)
			throw MapFileError(name, line, "ID '" + tok[0] + "' is not an integer in 0..255");
		if (v[5] <= 0) throw MapFileError(name, line, "scale must be > 0, got '" + tok[5] + "'");
		MapLandmark l;
		l.id = static_cast<int>(v[0]);
		l.x_m = v[1];
		l.y_m = v[2];
		l.z_m = v[3];
		l.yaw_rad = v[4] * M_PI / 180.0;
		l.scale = v[5];
		if (!seen.insert(l.id).second)
			throw MapFileError(name, line, "duplicate ID " + std::to_string(l.id));
		map.landmarks.push_back(l);
	}
	if (in.bad()) throw MapFileError(name, line, "read error");
	return map;
}

LandmarkMap LandmarkMap::load(const std::string& path)
{
	std::ifstream f(path);
	if (!f) throw std::runtime_error(path + ": cannot open map file");
	return parse(f, path);
}

void LandmarkMap::write(std::ostream& out) const
{
	out << "# codemark landmark map (docs/spec.md section 3)\n"
		<< "# id  x[m]  y[m]  z[m]  yaw[deg]  [scale]\n";
	out << std::setprecision(10);
	for (const auto& l : landmarks)
	{
		out << l.id << ' ' << l.x_m << ' ' << l.y_m << ' ' << l.z_m << ' '
			<< l.yaw_rad * 180.0 / M_PI;
		if (l.scale != 1.0) out << ' ' << l.scale;
		out << '\n';
	}
}

void LandmarkMap::save(const std::string& path) const
{
	std::ofstream f(path);
	if (!f) throw std::runtime_error(path + ": cannot write map file");
	write(f);
	if (!f) throw std::runtime_error(path + ": error while writing map file");
}

}  // namespace codemark
