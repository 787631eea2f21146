#include <codemark/filters/mrpt_landmarks.h>
#include <codemark/landmark/text.h>
#include <mrpt/slam/CRangeBearingKFSLAM2D.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace codemark::filters
{
namespace
{
constexpr std::size_t kColumns = 7;

// The tokens of one line with comments ('%' or '#' to the end) removed.
std::vector<std::string> tokens(std::string text)
{
	if (const auto c = text.find_first_of("%#"); c != std::string::npos) text.erase(c);
	std::istringstream ss(text);
	std::vector<std::string> tok;
	for (std::string t; ss >> t;) tok.push_back(t);
	return tok;
}

// A whole-token finite number, else MapFileError naming the column.
double number(const std::string& tok, const char* field, const std::string& name, int line)
{
	if (const auto v = parseFiniteNumber(tok)) return *v;
	throw MapFileError(
		name, line, std::string("column '") + field + "' is not a finite number: '" + tok + "'");
}
}  // namespace

LandmarkMap parseMrptLandmarks(std::istream& in, const std::string& name)
{
	static const char* kFields[kColumns] = {"x", "y", "z", "type", "unused", "unused", "id"};
	LandmarkMap map;
	std::set<int> seen;
	std::string text;
	int line = 0;
	while (std::getline(in, text))
	{
		++line;
		const auto tok = tokens(text);
		if (tok.empty()) continue;
		if (tok.size() != kColumns)
			throw MapFileError(
				name, line,
				"expected 7 columns 'x y z type 0 0 id' (MRPT landmark ground truth), found " +
					std::to_string(tok.size()));
		double v[kColumns];
		for (std::size_t i = 0; i < kColumns; ++i) v[i] = number(tok[i], kFields[i], name, line);
		const double id = v[6];
		if (id != std::floor(id) || id < 0 || id > 2147483647.0)
			throw MapFileError(name, line, "ID '" + tok[6] + "' is not a non-negative integer");
		MapLandmark l;
		l.id = static_cast<int>(id);
		l.x_m = v[0];
		l.y_m = v[1];
		l.z_m = v[2];
		if (!seen.insert(l.id).second)
			throw MapFileError(name, line, "duplicate ID " + std::to_string(l.id));
		map.landmarks.push_back(l);
	}
	return map;
}

LandmarkMap loadMrptLandmarksFile(const std::string& path)
{
	std::ifstream f(path);
	if (!f) throw std::runtime_error("cannot open MRPT landmark file '" + path + "'");
	return parseMrptLandmarks(f, path);
}

bool isMrptLandmarksFile(const std::string& path)
{
	std::ifstream f(path);
	for (std::string text; std::getline(f, text);)
	{
		const auto tok = tokens(text);
		if (!tok.empty()) return tok.size() == kColumns;
	}
	return false;
}

std::map<int, Eigen::Vector2d> rangeBearingSlamLandmarks(
	const mrpt::slam::CRangeBearingKFSLAM2D& kf)
{
	mrpt::poses::CPosePDFGaussian pose;
	std::vector<mrpt::math::TPoint2D> pts;
	std::map<unsigned int, mrpt::maps::CLandmark::TLandmarkID> ids;
	mrpt::math::CVectorDouble x;
	mrpt::math::CMatrixDouble P;
	kf.getCurrentState(pose, pts, ids, x, P);
	std::map<int, Eigen::Vector2d> out;
	for (std::size_t i = 0; i < pts.size(); ++i)
		out[static_cast<int>(ids[static_cast<unsigned>(i)])] = Eigen::Vector2d(pts[i].x, pts[i].y);
	return out;
}

LandmarkMap loadAnyMap(const std::string& path)
{
	if (isMrptLandmarksFile(path)) return loadMrptLandmarksFile(path);
	return LandmarkMap::load(path);
}

}  // namespace codemark::filters
