#include <codemark/landmark/camera.h>
#include <codemark/landmark/text.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/containers/yaml.h>

#include <Eigen/Dense>
#include <opencv2/core.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <stdexcept>

namespace codemark
{
namespace
{
mrpt::img::TCamera paperCamera()
{
	mrpt::img::TCamera c;
	c.ncols = 640;
	c.nrows = 480;
	c.setIntrinsicParamsFromValues(800.0, 800.0, 319.5, 239.5);
	c.distortion = mrpt::img::DistortionModel::none;
	c.cameraName = "paper";
	return c;
}

void validateCamera(const mrpt::img::TCamera& c, const std::string& path)
{
	const bool finite =
		std::isfinite(c.fx()) && std::isfinite(c.fy()) && std::isfinite(c.cx()) &&
		std::isfinite(c.cy()) &&
		std::all_of(c.dist.begin(), c.dist.end(), [](double d) { return std::isfinite(d); });
	if (!finite) throw std::runtime_error(path + ": camera parameters must be finite numbers");
	if (c.ncols == 0 || c.nrows == 0)
		throw std::runtime_error(path + ": camera resolution must be positive");
	if (!(c.fx() > 0) || !(c.fy() > 0))
		throw std::runtime_error(path + ": camera focal lengths fx, fy must be > 0");
	if (c.distortion == mrpt::img::DistortionModel::kannala_brandt)
		throw std::runtime_error(
			path + ": the kannala_brandt (fisheye) model is not supported; use plumb_bob");
}

void addWarning(std::vector<std::string>* warnings, const std::string& w)
{
	if (warnings)
		warnings->push_back(w);
	else
		std::cerr << "warning: " << w << "\n";
}

/** OpenCV's YAML (cv::FileStorage's "%YAML:" first line, or its matrix
 * tag below it) rather than ROS's, from the file's \a text. */
bool isOpenCvYaml(const std::string& text)
{
	const auto first_end = text.find('\n');
	return text.rfind("%YAML:", 0) == 0 ||
		   (first_end != std::string::npos &&
			text.find("!!opencv-matrix", first_end + 1) != std::string::npos);
}

/** Runs \a f with the process' stderr (file descriptor 2) sent to a
 * temporary file and returns what was written there. MRPT's YAML parser
 * (libfyaml inside mrpt::containers::yaml) prints its syntax errors to
 * stderr and then returns a partial document; we want them in the error
 * message instead, as one line naming the file and line. */
template <typename F>
std::string capturingStderr(F&& f)
{
	std::fflush(stderr);
	std::FILE* tmp = std::tmpfile();
	const int saved = tmp ? dup(2) : -1;
	if (saved < 0)
	{
		if (tmp) std::fclose(tmp);
		f();
		return {};
	}
	dup2(fileno(tmp), 2);
	std::string captured;
	auto restore = [&]()
	{
		std::fflush(stderr);
		dup2(saved, 2);
		close(saved);
		std::rewind(tmp);
		char buf[512];
		for (size_t n; (n = std::fread(buf, 1, sizeof(buf), tmp)) > 0;) captured.append(buf, n);
		std::fclose(tmp);
	};
	try
	{
		f();
	}
	catch (...)
	{
		restore();
		throw;
	}
	restore();
	return captured;
}

/** The finite numbers of the YAML number field \a node (a scalar or a
 * list of scalars); throws naming \a what where it holds anything else. */
std::vector<double> yamlNumbers(
	const mrpt::containers::yaml& node, const std::string& what, const std::string& path)
{
	std::vector<double> values;
	auto add = [&](const auto& scalar)
	{
		std::string text;
		try
		{
			text = scalar.template as<std::string>();
		}
		catch (const std::exception&)
		{
			return;	 // not stored as text (cannot happen for a parsed file): MRPT checks it
		}
		const auto v = parseFiniteNumber(text);
		if (!v)
			throw std::runtime_error(
				path + ": '" + what + "' holds '" + text + "', not a finite number");
		values.push_back(*v);
	};
	if (node.isSequence())
		for (const auto& v : node.asSequence())
		{
			if (!v.isScalar())
				throw std::runtime_error(path + ": '" + what + "' must be a list of numbers");
			add(v);
		}
	else if (node.isScalar())
		add(node);
	else
		throw std::runtime_error(path + ": '" + what + "' must be a number or a list of numbers");
	return values;
}

/** Refuses what no camera YAML holds but makes libfyaml (0.8, Debian
 * bookworm, inside MRPT's YAML reader) loop forever or crash, found by
 * fuzzing: a '%' directive line with non-ASCII bytes (a hang), tabs in a
 * malformed plain scalar (a segfault in its own error report). Camera files
 * are plain ASCII text without directives, indented with spaces; say so
 * instead of hanging or crashing. */
void requirePlainYamlText(const std::string& path, const std::string& text)
{
	int line = 1;
	bool line_start = true;	 // YAML breaks lines at '\n', '\r' and "\r\n"
	for (std::size_t i = 0; i < text.size(); ++i)
	{
		const auto u = static_cast<unsigned char>(text[i]);
		if (u == '\n' || u == '\r')
		{
			if (!(u == '\n' && i > 0 && text[i - 1] == '\r')) ++line;
			line_start = true;
			continue;
		}
		if (line_start && u == '%')
			throw std::runtime_error(
				path + ":" + std::to_string(line) +
				": YAML directives ('%...') are not supported here");
		if (u == '\t')
			throw std::runtime_error(
				path + ":" + std::to_string(line) +
				": tab character (camera YAML files take spaces only)");
		if (u < 0x20 || u == 0x7f)
			throw std::runtime_error(
				path + ":" + std::to_string(line) + ": control character in a YAML text file");
		line_start = false;
	}
}

std::string fileText(const std::string& path)
{
	std::ifstream in(path, std::ios::binary);
	return {(std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()};
}

/** \a text (the file \a path holds) parsed by MRPT's YAML reader, its
 * syntax errors thrown as "PATH:LINE:COL: error: MESSAGE". */
mrpt::containers::yaml parseYaml(const std::string& path, const std::string& text)
{
	requirePlainYamlText(path, text);
	mrpt::containers::yaml y;
	std::string diagnostics;
	try
	{
		diagnostics = capturingStderr([&]() { y = mrpt::containers::yaml::FromText(text); });
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error(path + ": cannot parse YAML: " + oneLineMessage(e.what()));
	}
	// libfyaml's "<memory-@0x...>:LINE:COL: error: MESSAGE" -> "PATH:LINE:COL: error: MESSAGE".
	if (const auto err = diagnostics.find(": error: "); err != std::string::npos)
	{
		const auto begin = diagnostics.rfind('\n', err);
		std::string line = diagnostics.substr(begin == std::string::npos ? 0 : begin + 1);
		line = line.substr(0, line.find('\n'));
		const auto close = line.find(">:");
		throw std::runtime_error(
			path + ":" + (close == std::string::npos ? " " + line : line.substr(close + 2)));
	}
	return y;
}

/** OpenCV's camera YAML (cv::FileStorage, as OpenCV's calibration sample
 * writes it): image_width, image_height, camera_matrix and
 * distortion_coefficients as !!opencv-matrix maps (rows, cols, dt, data).
 * Read by the same YAML reader as the ROS format, not by cv::FileStorage:
 * OpenCV 4.6's reader loops forever on some malformed files (found by
 * fuzzing), and one reader guarded against its failures serves both
 * formats. Its "%YAML:1.0" first line is OpenCV's own spelling of a
 * directive; it is blanked, keeping the line numbers. */
mrpt::img::TCamera loadOpenCvYaml(const std::string& path, std::string text)
{
	if (text.rfind("%YAML:", 0) == 0) text.erase(0, text.find_first_of("\r\n"));
	const mrpt::containers::yaml y = parseYaml(path, text);
	if (!y.isMap()) throw std::runtime_error(path + ": expected a YAML map of camera keys");
	auto matrix = [&](const char* key, size_t max_entries)
	{
		const auto& m = y[key];
		if (!m.isMap() || !m.has("data"))
			throw std::runtime_error(
				path + ": '" + key + "' is not an !!opencv-matrix with 'data'");
		std::vector<double> data = yamlNumbers(m["data"], std::string(key) + ".data", path);
		if (m.has("rows") && m.has("cols"))
		{
			const auto r = yamlNumbers(m["rows"], std::string(key) + ".rows", path);
			const auto c = yamlNumbers(m["cols"], std::string(key) + ".cols", path);
			if (r.size() != 1 || c.size() != 1 || r[0] * c[0] != double(data.size()))
				throw std::runtime_error(
					path + ": '" + key + "' has rows x cols unlike its " +
					std::to_string(data.size()) + " data entries");
		}
		if (data.size() > max_entries)
			throw std::runtime_error(
				path + ": '" + key + "' has " + std::to_string(data.size()) + " entries");
		return data;
	};
	for (const char* key : {"image_width", "image_height", "camera_matrix"})
		if (!y.has(key))
			throw std::runtime_error(path + ": missing required key '" + std::string(key) + "'");
	const auto w = yamlNumbers(y["image_width"], "image_width", path);
	const auto h = yamlNumbers(y["image_height"], "image_height", path);
	if (w.size() != 1 || h.size() != 1 || !(w[0] >= 1 && w[0] <= 1e6) ||
		!(h[0] >= 1 && h[0] <= 1e6) || w[0] != std::floor(w[0]) || h[0] != std::floor(h[0]))
		throw std::runtime_error(
			path + ": expected positive integer 'image_width' and 'image_height'");
	const std::vector<double> K = matrix("camera_matrix", 9);
	if (K.size() != 9) throw std::runtime_error(path + ": expected a 3x3 'camera_matrix'");
	mrpt::img::TCamera c;
	c.ncols = static_cast<uint32_t>(w[0]);
	c.nrows = static_cast<uint32_t>(h[0]);
	c.setIntrinsicParamsFromValues(K[0], K[4], K[2], K[5]);
	c.distortion = mrpt::img::DistortionModel::none;
	if (y.has("distortion_coefficients") && !y["distortion_coefficients"].isNullNode())
	{
		const std::vector<double> D = matrix("distortion_coefficients", 8);
		if (D.size() != 4 && D.size() != 5 && D.size() != 8)
			throw std::runtime_error(
				path + ": 'distortion_coefficients' must have 4, 5 or 8 entries");
		c.distortion = mrpt::img::DistortionModel::plumb_bob;
		for (size_t i = 0; i < D.size(); ++i) c.dist[i] = D[i];
	}
	return c;
}

mrpt::img::TCamera loadRosYaml(const std::string& path, const std::string& text)
{
	mrpt::containers::yaml y = parseYaml(path, text);
	for (const char* key : {"image_width", "image_height", "camera_matrix"})
		if (!y.has(key))
			throw std::runtime_error(path + ": missing required key '" + std::string(key) + "'");
	yamlNumbers(y["image_width"], "image_width", path);
	yamlNumbers(y["image_height"], "image_height", path);
	if (!y["camera_matrix"].isMap() || !y["camera_matrix"].has("data"))
		throw std::runtime_error(path + ": 'camera_matrix' needs 'data: [9 numbers]'");
	yamlNumbers(y["camera_matrix"]["data"], "camera_matrix.data", path);
	if (y["camera_matrix"]["data"].asSequence().size() != 9)
		throw std::runtime_error(path + ": 'camera_matrix.data' must hold 9 numbers");
	if (y.has("distortion_coefficients") && y["distortion_coefficients"].isMap() &&
		y["distortion_coefficients"].has("data"))
		yamlNumbers(y["distortion_coefficients"]["data"], "distortion_coefficients.data", path);
	if (!y.has("camera_name")) y["camera_name"] = std::string("camera");
	if (!y.has("distortion_coefficients"))
	{
		y["distortion_model"] = std::string("none");
	}
	try
	{
		return mrpt::img::TCamera::FromYAML(y);
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error(path + ": bad camera YAML: " + oneLineMessage(e.what()));
	}
}

mrpt::img::TCamera loadIni(
	const std::string& path, const std::string& section, std::vector<std::string>* warnings)
{
	mrpt::config::CConfigFile cfg(path);
	if (!cfg.sectionExists(section))
		throw std::runtime_error(path + ": no [" + section + "] section");
	// MRPT 2.5.8 silently drops 'dist' unless 'distortion_model' is given.
	const std::string dist = cfg.read_string(section, "dist", "");
	const std::string model = cfg.read_string(section, "distortion_model", "");
	if (model.empty() && !dist.empty())
	{
		std::string digits = dist;
		const bool nonzero = std::any_of(
			digits.begin(), digits.end(), [](char ch) { return ch >= '1' && ch <= '9'; });
		if (nonzero)
			addWarning(
				warnings, path + ": [" + section +
							  "] has non-zero 'dist' but no 'distortion_model'; "
							  "MRPT ignores the distortion in that case, and so does codemark. "
							  "Add 'distortion_model = plumb_bob' to use it.");
	}
	// MRPT reads "8o0" as 8 and "abc" as 0: check the numbers first.
	requireIniNumbers(cfg, section, {"cx", "cy", "fx", "fy", "focal_length"}, false, false, path);
	requireIniNumbers(cfg, section, {"resolution"}, true, true, path);
	// A camera without distortion writes "dist = []" (toIniText()).
	std::string dist_compact = dist;
	dist_compact.erase(
		std::remove_if(dist_compact.begin(), dist_compact.end(), ::isspace), dist_compact.end());
	if (dist_compact != "[]") requireIniNumbers(cfg, section, {"dist"}, false, true, path);
	for (const char* key : {"resolution", "cx", "cy", "fx", "fy"})
		if (!cfg.keyExists(section, key))
			throw std::runtime_error(
				path + ": [" + section + "] misses the required key '" + key + "'");
	mrpt::img::TCamera c;
	try
	{
		c.loadFromConfigFile(section, cfg);
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error(
			path + ": [" + section + "]: " + oneLineMessage(mrpt::exception_to_str(e)));
	}
	return c;
}

std::string lowerExtension(const std::string& path)
{
	const auto dot = path.find_last_of('.');
	if (dot == std::string::npos) return {};
	std::string ext = path.substr(dot + 1);
	std::transform(
		ext.begin(), ext.end(), ext.begin(),
		[](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
	return ext;
}

}  // namespace

CameraModel::CameraModel() : params_(paperCamera()) {}

CameraModel::CameraModel(const mrpt::img::TCamera& params) : params_(params)
{
	validateCamera(params_, "camera");
}

CameraModel CameraModel::load(
	const std::string& path, std::vector<std::string>* warnings, const std::string& section)
{
	{
		std::ifstream probe(path);
		if (!probe) throw std::runtime_error(path + ": cannot open camera file");
	}
	const std::string ext = lowerExtension(path);
	mrpt::img::TCamera c;
	if (ext == "yaml" || ext == "yml")
	{
		std::string text = fileText(path);
		c = isOpenCvYaml(text) ? loadOpenCvYaml(path, std::move(text)) : loadRosYaml(path, text);
	}
	else
		c = loadIni(path, section, warnings);
	validateCamera(c, path);
	return CameraModel(c);
}

std::vector<std::string> shareSearchDirs()
{
	std::vector<std::string> dirs;
	if (const char* env = std::getenv("CODEMARK_SHARE_DIR")) dirs.emplace_back(env);
	dirs.emplace_back(CODEMARK_SOURCE_SHARE_DIR);
	dirs.emplace_back(CODEMARK_INSTALL_SHARE_DIR);
	return dirs;
}

std::string findShareFile(const std::string& relative)
{
	for (const auto& d : shareSearchDirs())
	{
		std::string p = d + "/" + relative;
		if (std::ifstream(p).good()) return p;
	}
	return {};
}

CameraModel CameraModel::paperDefault()
{
	const std::string p = findShareFile("camera-paper.ini");
	if (p.empty()) return CameraModel();
	return load(p);
}

bool CameraModel::hasDistortion() const
{
	if (params_.distortion != mrpt::img::DistortionModel::plumb_bob) return false;
	return std::any_of(params_.dist.begin(), params_.dist.end(), [](double d) { return d != 0; });
}

Eigen::Vector2d CameraModel::distortNormalized(const Eigen::Vector2d& xn) const
{
	double x = xn.x(), y = xn.y();
	if (hasDistortion())
	{
		// OpenCV's rational plumb_bob model (k1 k2 p1 p2 k3 k4 k5 k6), written
		// out because it is called per sample by the renderer, where
		// cv::projectPoints would allocate per call.
		const auto& d = params_.dist;
		const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
		const double radial =
			(1 + d[0] * r2 + d[1] * r4 + d[4] * r6) / (1 + d[5] * r2 + d[6] * r4 + d[7] * r6);
		const double xd = x * radial + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x);
		const double yd = y * radial + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y;
		x = xd;
		y = yd;
	}
	return {fx() * x + cx(), fy() * y + cy()};
}

std::optional<Eigen::Vector2d> CameraModel::project(const Eigen::Vector3d& p) const
{
	if (!(p.z() > 0)) return std::nullopt;
	return distortNormalized({p.x() / p.z(), p.y() / p.z()});
}

Eigen::Vector2d CameraModel::undistortToNormalized(const Eigen::Vector2d& raw) const
{
	Eigen::Vector2d xd((raw.x() - cx()) / fx(), (raw.y() - cy()) / fy());
	if (!hasDistortion()) return xd;
	// Fixed-point iteration followed by Gauss-Newton polishing on the forward
	// model: OpenCV's undistortPoints stops at a fixed iteration count, which
	// leaves up to 1e-3 px at the image corners for strong distortion.
	Eigen::Vector2d x = xd;
	const auto& d = params_.dist;
	for (int it = 0; it < 20; ++it)
	{
		const double r2 = x.squaredNorm(), r4 = r2 * r2, r6 = r4 * r2;
		const double icdist =
			(1 + d[5] * r2 + d[6] * r4 + d[7] * r6) / (1 + d[0] * r2 + d[1] * r4 + d[4] * r6);
		const double dx = 2 * d[2] * x.x() * x.y() + d[3] * (r2 + 2 * x.x() * x.x());
		const double dy = d[2] * (r2 + 2 * x.y() * x.y()) + 2 * d[3] * x.x() * x.y();
		x = {(xd.x() - dx) * icdist, (xd.y() - dy) * icdist};
	}
	for (int it = 0; it < 5; ++it)
	{
		const auto f = [&](const Eigen::Vector2d& q)
		{
			const Eigen::Vector2d px = distortNormalized(q);
			return Eigen::Vector2d((px.x() - cx()) / fx(), (px.y() - cy()) / fy());
		};
		const Eigen::Vector2d r = f(x) - xd;
		if (r.norm() < 1e-14) break;
		const double h = 1e-7;
		Eigen::Matrix2d J;
		J.col(0) = (f(x + Eigen::Vector2d(h, 0)) - f(x - Eigen::Vector2d(h, 0))) / (2 * h);
		J.col(1) = (f(x + Eigen::Vector2d(0, h)) - f(x - Eigen::Vector2d(0, h))) / (2 * h);
		x -= J.fullPivLu().solve(r);
	}
	return x;
}

Eigen::Vector2d CameraModel::undistortPixel(const Eigen::Vector2d& raw) const
{
	if (!hasDistortion()) return raw;
	const Eigen::Vector2d xn = undistortToNormalized(raw);
	return {fx() * xn.x() + cx(), fy() * xn.y() + cy()};
}

std::string CameraModel::toIniText(const std::string& section) const
{
	mrpt::config::CConfigFileMemory cfg;
	params_.saveToConfigFile(section, cfg);
	return cfg.getContent();
}

}  // namespace codemark
