#include <codemark/landmark/codebook.h>
#include <codemark/landmark/text.h>
#include <codemark/sim/povray.h>
#include <mrpt/config/CConfigFileBase.h>

#include <opencv2/imgcodecs.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "background.h"

namespace codemark::sim
{
namespace fs = std::filesystem;

namespace
{
/** Each layer of a landmark lies this far in front of the one below it [m]. */
constexpr double kLayerM = 2e-5;
/** The wall lies this far behind the landmark plane [m]. */
constexpr double kWallGapM = 5e-4;
/** Reflectance of the occluding bar (render()'s grey 100). */
constexpr double kOccluderReflectance = 100.0 / 255.0;

[[noreturn]] void bad(const std::string& key, const std::string& what)
{
	throw std::invalid_argument("povray option '" + key + "' " + what);
}

std::string lower(std::string s)
{
	std::transform(
		s.begin(), s.end(), s.begin(),
		[](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	return s;
}

template <typename E, size_t N>
E fromName(const std::string& name, const std::string& key, const std::array<const char*, N>& names)
{
	const std::string n = lower(name);
	for (size_t i = 0; i < N; ++i)
		if (n == names[i]) return static_cast<E>(i);
	std::string list;
	for (size_t i = 0; i < N; ++i) list += std::string(i ? ", " : "") + names[i];
	bad(key, "must be one of " + list + ", got '" + name + "'");
}

constexpr std::array<const char*, 3> kLightLevels{"dim", "normal", "bright"};
constexpr std::array<const char*, 3> kLightTypes{"point", "area", "ambient"};
constexpr std::array<const char*, 4> kWalls{"auto", "plain", "plaster", "brick"};
constexpr std::array<const char*, 3> kFloors{"plain", "tiles", "wood"};
}  // namespace

const char* lightLevelName(LightLevel l) { return kLightLevels[static_cast<size_t>(l)]; }
const char* lightTypeName(LightType t) { return kLightTypes[static_cast<size_t>(t)]; }
const char* wallTextureName(WallTexture t) { return kWalls[static_cast<size_t>(t)]; }
const char* floorTextureName(FloorTexture t) { return kFloors[static_cast<size_t>(t)]; }
LightLevel lightLevelFromName(const std::string& name, const std::string& key)
{
	return fromName<LightLevel>(name, key, kLightLevels);
}
LightType lightTypeFromName(const std::string& name, const std::string& key)
{
	return fromName<LightType>(name, key, kLightTypes);
}
WallTexture wallTextureFromName(const std::string& name, const std::string& key)
{
	return fromName<WallTexture>(name, key, kWalls);
}
FloorTexture floorTextureFromName(const std::string& name, const std::string& key)
{
	return fromName<FloorTexture>(name, key, kFloors);
}

// ---------------------------------------------------------------------------
// PovrayOptions

double PovrayOptions::level(double gain) const
{
	static constexpr std::array<double, 3> factor{0.35, 1.0, 1.6};
	return factor[static_cast<size_t>(light)] * light_scale * gain;
}

std::string PovrayOptions::cacheDirectory() const
{
	if (!cache_dir.empty()) return cache_dir;
	if (const char* e = std::getenv("CODEMARK_POVRAY_CACHE"); e && *e) return e;
	if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x)
		return std::string(x) + "/codemark/povray";
	if (const char* h = std::getenv("HOME"); h && *h)
		return std::string(h) + "/.cache/codemark/povray";
	return (fs::temp_directory_path() / "codemark-povray").string();
}

std::string PovrayOptions::renderSettings() const
{
	std::ostringstream s;
	s << "Antialias=on\nSampling_Method=" << aa_method << "\nAntialias_Depth=" << aa_depth
	  << "\nAntialias_Threshold=" << aa_threshold
	  << "\nAntialias_Gamma=1.0\nJitter=" << (aa_jitter > 0 ? "on" : "off")
	  << "\nJitter_Amount=" << aa_jitter
	  << "\nFile_Gamma=1.0\nOutput_File_Type=N\nBits_Per_Color=16\nOutput_Alpha=off\n";
	return s.str();
}

void PovrayOptions::validate() const
{
	const auto range = [](const char* key, double v, double lo, double hi)
	{
		if (!std::isfinite(v) || v < lo || v > hi)
		{
			std::ostringstream s;
			s << "must be in [" << lo << ", " << hi << "], got " << v;
			bad(key, s.str());
		}
	};
	range("light_scale", light_scale, 1e-6, 1e6);
	if (!(light_scale > 0)) bad("light_scale", "must be > 0");
	range("ambient_share", ambient_share, 0, 1);
	range("light_gradient", light_gradient, -0.45, 0.45);
	range("lamp_distance_m", lamp_distance_m, 0.2, 100);
	range("lamp_height_m", lamp_height_m, -10, 10);
	range("area_light_size_m", area_light_size_m, 0.01, 10);
	range("area_light_samples", area_light_samples, 2, 8);
	range("aa_threshold", aa_threshold, 0, 3);
	if (aa_method != 1 && aa_method != 2) bad("aa_method", "must be 1 or 2");
	range("aa_depth", aa_depth, 1, 9);
	range("aa_jitter", aa_jitter, 0, 1);
	range("threads", threads, 1, 512);
	if (executable.empty()) bad("executable", "must not be empty");
}

void PovrayOptions::loadFromConfigFile(
	const mrpt::config::CConfigFileBase& source, const std::string& section)
{
	const auto& c = source;
	const std::string& s = section;
	requireIniNumbers(
		c, s,
		{"light_scale", "ambient_share", "light_gradient", "lamp_distance_m", "lamp_height_m",
		 "area_light_size_m", "aa_threshold", "aa_jitter"});
	requireIniNumbers(
		c, s, {"area_light_samples", "aa_method", "aa_depth", "threads", "texture_seed"}, true);
	light = lightLevelFromName(c.read_string(s, "light", lightLevelName(light)), "light");
	MRPT_LOAD_CONFIG_VAR(light_scale, double, c, s);
	light_type =
		lightTypeFromName(c.read_string(s, "light_type", lightTypeName(light_type)), "light_type");
	MRPT_LOAD_CONFIG_VAR(ambient_share, double, c, s);
	MRPT_LOAD_CONFIG_VAR(light_gradient, double, c, s);
	MRPT_LOAD_CONFIG_VAR(lamp_distance_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(lamp_height_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(area_light_size_m, double, c, s);
	MRPT_LOAD_CONFIG_VAR(area_light_samples, int, c, s);
	wall = wallTextureFromName(c.read_string(s, "wall", wallTextureName(wall)), "wall");
	floor = floorTextureFromName(c.read_string(s, "floor", floorTextureName(floor)), "floor");
	texture_seed = c.read_uint64_t(s, "texture_seed", texture_seed);
	executable = c.read_string(s, "executable", executable);
	MRPT_LOAD_CONFIG_VAR(aa_threshold, double, c, s);
	MRPT_LOAD_CONFIG_VAR(aa_method, int, c, s);
	MRPT_LOAD_CONFIG_VAR(aa_depth, int, c, s);
	MRPT_LOAD_CONFIG_VAR(aa_jitter, double, c, s);
	cache_dir = c.read_string(s, "cache_dir", cache_dir);
	MRPT_LOAD_CONFIG_VAR(threads, int, c, s);
	validate();
}

void PovrayOptions::saveToConfigFile(
	mrpt::config::CConfigFileBase& target, const std::string& section) const
{
	auto& c = target;
	const std::string& s = section;
	c.write(s, "light", lightLevelName(light));
	c.write(s, "light_scale", light_scale);
	c.write(s, "light_type", lightTypeName(light_type));
	c.write(s, "ambient_share", ambient_share);
	c.write(s, "light_gradient", light_gradient);
	c.write(s, "lamp_distance_m", lamp_distance_m);
	c.write(s, "lamp_height_m", lamp_height_m);
	c.write(s, "area_light_size_m", area_light_size_m);
	c.write(s, "area_light_samples", area_light_samples);
	c.write(s, "wall", wallTextureName(wall));
	c.write(s, "floor", floorTextureName(floor));
	c.write(s, "texture_seed", texture_seed);
	c.write(s, "executable", executable);
	c.write(s, "aa_threshold", aa_threshold);
	c.write(s, "aa_method", aa_method);
	c.write(s, "aa_depth", aa_depth);
	c.write(s, "aa_jitter", aa_jitter);
	c.write(s, "cache_dir", cache_dir);
	c.write(s, "threads", threads);
}

// ---------------------------------------------------------------------------
// The scene text

namespace
{
using Vec3 = Eigen::Vector3d;

/** A number in POV-Ray's syntax, 12 significant digits (1e-11 m at 10 m). */
std::string num(double v)
{
	if (std::abs(v) < 1e-15) v = 0;	 // no "-0"
	char buf[40];
	std::snprintf(buf, sizeof(buf), "%.12g", v);
	return buf;
}

std::string vec(const Vec3& v)
{
	return "<" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + ">";
}

std::string rgb(double r, double g, double b)
{
	return "rgb <" + num(r) + ", " + num(g) + ", " + num(b) + ">";
}

/** BGR [0..255] as a linear reflectance in POV-Ray's rgb. */
std::string rgbOf(const cv::Scalar& bgr)
{
	return rgb(bgr[2] / 255.0, bgr[1] / 255.0, bgr[0] / 255.0);
}

/** A landmark's frame: centre, outward normal n (X_L), right (Y_L), up (Z_L). */
struct Frame
{
	Vec3 c, n, right, up;
	/** World point of face (s right, t up) at \a x_m in front of the plane. */
	Vec3 at(double s, double t, double x_m = 0) const { return c + n * x_m + right * s + up * t; }
};

Frame frameOf(const MapLandmark& lm)
{
	const mrpt::poses::CPose3D p = lm.world_T_landmark();
	const auto R = p.getRotationMatrix();
	Frame f;
	f.c = Vec3(p.x(), p.y(), p.z());
	f.n = Vec3(R(0, 0), R(1, 0), R(2, 0));
	f.right = Vec3(R(0, 1), R(1, 1), R(2, 1));
	f.up = Vec3(R(0, 2), R(1, 2), R(2, 2));
	return f;
}

/** The face rectangle [s0, s1] x [t0, t1] at \a x_m as a POV-Ray polygon. */
std::string facePolygon(
	const Frame& f, double s0, double t0, double s1, double t1, double x_m,
	const std::string& texture)
{
	const Vec3 a = f.at(s0, t0, x_m), b = f.at(s1, t0, x_m), c = f.at(s1, t1, x_m),
			   d = f.at(s0, t1, x_m);
	return "polygon { 5, " + vec(a) + ", " + vec(b) + ", " + vec(c) + ", " + vec(d) + ", " +
		   vec(a) + " " + texture + " no_shadow }\n";
}

std::string squarePolygon(const Frame& f, double half, double x_m, const std::string& texture)
{
	return facePolygon(f, -half, -half, half, half, x_m, texture);
}

/** A texture of flat reflectance \a colour with the scene's finish F. */
std::string paint(const std::string& colour)
{
	return "texture { pigment { " + colour + " } finish { F } }";
}

/** Irradiance at \a p (normal \a n) from a lamp of unit intensity at \a lamp:
 * cos(incidence) x POV-Ray's fading 2 / (1 + (d / fade_distance)^2) with
 * fade_distance 1 m; 0 from behind. */
double irradiance(const Vec3& lamp, const Vec3& p, const Vec3& n)
{
	const Vec3 d = lamp - p;
	const double r = d.norm();
	const double cosine = std::max(0.0, n.dot(d) / r);
	return cosine * 2.0 / (1.0 + r * r);
}

/** The lamp of landmark frame \a f: lamp_distance_m in front, lamp_height_m
 * above, moved sideways and closer (by bisection) until the irradiance
 * across the sheet changes by light_gradient from its left to its right
 * edge. */
Vec3 lampPosition(const Frame& f, double sheet_half, const PovrayOptions& pov)
{
	const double d0 = pov.lamp_distance_m, h = pov.lamp_height_m;
	const double side = pov.light_gradient >= 0 ? 1.0 : -1.0;
	// u = 0: straight in front; u = 1: 0.25 m in front, 0.5 m to the side,
	// 0.1 m above: a lamp close beside the sheet.
	const auto place = [&](double u)
	{ return f.at(side * 0.5 * u, h + (0.1 - h) * u, d0 + (0.25 - d0) * u); };
	const auto gradient = [&](double u)
	{
		const Vec3 L = place(u);
		const double e0 = irradiance(L, f.c, f.n);
		return side *
			   (irradiance(L, f.at(sheet_half, 0), f.n) -
				irradiance(L, f.at(-sheet_half, 0), f.n)) /
			   e0;
	};
	const double g = std::abs(pov.light_gradient);
	if (g == 0) return place(0);
	// The gradient grows with u from 0 up to its largest value.
	double lo = 0, hi = 1;
	double best = 0, best_g = 0;
	for (int i = 0; i <= 50; ++i)
	{
		const double u = i / 50.0, gu = gradient(u);
		if (gu > best_g) best_g = gu, best = u;
	}
	if (best_g < g)
	{
		std::ostringstream s;
		s << "is out of reach of the lamp (at most " << best_g << " here), got "
		  << pov.light_gradient;
		bad("light_gradient", s.str());
	}
	hi = best;
	for (int i = 0; i < 60; ++i)
	{
		const double m = 0.5 * (lo + hi);
		(gradient(m) < g ? lo : hi) = m;
	}
	return place(0.5 * (lo + hi));
}

/** Non-negative intensities I with A I = b (projected Gauss-Seidel; A is
 * dominated by its diagonal: each lamp lights its own landmark most). */
std::vector<double> nonNegativeSolve(const Eigen::MatrixXd& A, const Eigen::VectorXd& b)
{
	const int n = static_cast<int>(b.size());
	std::vector<double> x(n, 0.0);
	for (int it = 0; it < 500; ++it)
		for (int i = 0; i < n; ++i)
		{
			double r = b[i];
			for (int k = 0; k < n; ++k)
				if (k != i) r -= A(i, k) * x[k];
			x[i] = A(i, i) > 0 ? std::max(0.0, r / A(i, i)) : 0.0;
		}
	return x;
}

/** A wall: the plane n . p = d with landmarks on it. */
struct Wall
{
	Vec3 n;
	double d;
	std::vector<size_t> landmarks;
};

/** Uniform [0, 1) from a counter-based hash (stable across platforms). */
struct Hash01
{
	uint64_t state;
	double operator()()
	{
		state = detail::streamSeed(state, 7);
		return static_cast<double>(state >> 11) * (1.0 / 9007199254740992.0);
	}
};

/** The distractors around one landmark, on its wall, clear of every sheet
 * of the map that lies on the same wall: shapes a detector must reject. */
void writeDistractors(
	std::ostringstream& out, const Frame& f, const std::vector<Frame>& frames,
	const std::vector<double>& sheet_halves, size_t self, int count, uint64_t seed,
	const RenderOptions& o, double floor_z)
{
	Hash01 rnd{detail::streamSeed(seed, 1000 + self)};
	const std::string green = rgbOf(o.green_bgr), black = rgbOf(o.black_bgr),
					  white = rgbOf(o.white_bgr);
	const double x0 = -kWallGapM + kLayerM;
	for (int k = 0, tries = 0; k < count && tries < 50 * count; ++tries)
	{
		const double size = 0.05 + 0.25 * rnd();  // side [m]
		const double s = (rnd() * 2 - 1) * 1.2, t = (rnd() * 2 - 1) * 0.6;
		// Clear of every sheet on this wall (with a 2 cm margin).
		bool clear = true;
		for (size_t j = 0; j < frames.size() && clear; ++j)
		{
			const Vec3 q = f.at(s, t) - frames[j].c;
			if (std::abs(q.dot(frames[j].n)) > 0.01 || frames[j].n.dot(f.n) < 0.999) continue;
			const double lim = sheet_halves[j] + 0.5 * size * std::sqrt(2.0) + 0.02;
			clear = std::abs(q.dot(frames[j].right)) > lim || std::abs(q.dot(frames[j].up)) > lim;
		}
		// Above the floor (a poster reaches 1.4 x its half side).
		clear = clear && f.at(s, t).z() - 0.75 * size * 1.5 > floor_z + 0.05;
		if (!clear) continue;
		++k;
		const double h = 0.5 * size;
		const int kind = static_cast<int>(rnd() * 5);
		switch (kind)
		{
			case 0:	 // a green rectangle
				out << facePolygon(f, s - h, t - 0.6 * h, s + h, t + 0.6 * h, x0, paint(green));
				break;
			case 1:	 // a green disc
				out << "disc { " << vec(f.at(s, t, x0)) << ", " << vec(f.n) << ", " << num(h) << " "
					<< paint(green) << " no_shadow }\n";
				break;
			case 2:	 // a black frame filled with red, blue, white or grey
			{
				static const std::array<cv::Scalar, 4> fills{
					cv::Scalar(40, 40, 200), cv::Scalar(200, 60, 40), cv::Scalar(235, 235, 235),
					cv::Scalar(128, 128, 128)};
				out << facePolygon(f, s - h, t - h, s + h, t + h, x0, paint(black));
				const double i = 0.8 * h;
				out << facePolygon(
					f, s - i, t - i, s + i, t + i, x0 + kLayerM,
					paint(rgbOf(fills[static_cast<size_t>(rnd() * 4) % 4])));
				break;
			}
			case 3:	 // a poster: white with black and green print
			{
				out << facePolygon(f, s - h, t - 1.4 * h, s + h, t + 1.4 * h, x0, paint(white));
				for (int r = 0; r < 5; ++r)
				{
					const double tt = t + 1.4 * h * (0.8 - 0.35 * r);
					const double w = h * (0.4 + 0.5 * rnd());
					out << facePolygon(
						f, s - w, tt - 0.08 * h, s + w, tt + 0.08 * h, x0 + kLayerM,
						paint(r % 2 ? green : black));
				}
				break;
			}
			default:  // a marker-like grid: black frame, green fill, random cells, green centre
			{
				out << facePolygon(f, s - h, t - h, s + h, t + h, x0, paint(black));
				const double i = 0.8 * h, c = 0.9 * i / 3;
				out << facePolygon(f, s - i, t - i, s + i, t + i, x0 + kLayerM, paint(green));
				for (int r = 0; r < 3; ++r)
					for (int q = 0; q < 3; ++q)
						if ((r != 1 || q != 1) && rnd() < 0.5)
						{
							const double cs = s + (q - 1) * c, ct = t + (1 - r) * c;
							out << facePolygon(
								f, cs - 0.5 * c, ct - 0.5 * c, cs + 0.5 * c, ct + 0.5 * c,
								x0 + 2 * kLayerM, paint(black));
						}
				break;
			}
		}
	}
}

std::string wallPigment(WallTexture t, double grey, uint64_t seed)
{
	Hash01 rnd{detail::streamSeed(seed, 11)};
	const Vec3 offset(rnd() * 100, rnd() * 100, rnd() * 100);
	const double g = std::clamp(grey, 0.0, 1.0);
	std::ostringstream p;
	switch (t)
	{
		case WallTexture::Plaster:
			p << "pigment { bozo turbulence 0.3 octaves 3 color_map { [0 "
			  << rgb(0.85 * g, 0.85 * g, 0.83 * g) << "] [1 " << rgb(1.15 * g, 1.14 * g, 1.12 * g)
			  << "] } scale 0.25 translate " << vec(offset) << " }";
			break;
		case WallTexture::Brick:
			p << "pigment { brick "
			  << rgb(std::min(0.95, 1.35 * g), std::min(0.95, 1.3 * g), std::min(0.95, 1.25 * g))
			  << ", " << rgb(1.15 * g, 0.85 * g, 0.75 * g)
			  << " brick_size <0.25, 0.065, 0.125> mortar 0.012 translate " << vec(offset)
			  << " rotate 90*x }";	// POV-Ray's courses stack along y: ours along z
			break;
		default:
			p << "pigment { " << rgb(g, g, g) << " }";
			break;
	}
	return p.str();
}

std::string floorPigment(FloorTexture t, uint64_t seed)
{
	Hash01 rnd{detail::streamSeed(seed, 12)};
	const Vec3 offset(rnd() * 10, rnd() * 10, 0);
	std::ostringstream p;
	switch (t)
	{
		case FloorTexture::Tiles:
			p << "pigment { checker " << rgb(0.5, 0.5, 0.48) << ", " << rgb(0.22, 0.22, 0.24)
			  << " scale 0.3 translate " << vec(offset) << " }";
			break;
		case FloorTexture::Wood:
			p << "pigment { wood turbulence 0.08 color_map { [0 " << rgb(0.42, 0.27, 0.15)
			  << "] [1 " << rgb(0.26, 0.15, 0.08) << "] } scale 0.04 rotate 90*y translate "
			  << vec(offset) << " }";
			break;
		default:
			p << "pigment { " << rgb(0.35, 0.35, 0.35) << " }";
			break;
	}
	return p.str();
}
}  // namespace

std::string povrayScene(
	const Scene& scene, const RenderOptions& o, const PovrayOptions& pov, uint64_t seed)
{
	o.validate();
	pov.validate();
	const CameraModel& cam = scene.camera;
	if (cam.hasDistortion())
	{
		const std::string name = cam.params().cameraName;
		throw std::invalid_argument(
			"povray: camera '" + (name.empty() ? std::string("(unnamed)") : name) +
			"' has lens distortion; the POV-Ray renderer models the pinhole only (undistort, or "
			"use the project's renderer)");
	}
	const int W = cam.width(), H = cam.height();
	const auto& lms = scene.map.landmarks;
	const double level = pov.level(o.gain);
	const bool ambient_only = pov.light_type == LightType::Ambient;
	const double ambient = ambient_only ? level : level * pov.ambient_share;

	std::ostringstream out;
	out << "// codemark: POV-Ray 3.7 scene (libs/sim/src/povray.cpp), linear light\n"
		<< "#version 3.7;\n"
		<< "global_settings { assumed_gamma 1.0 ambient_light " << rgb(ambient, ambient, ambient)
		<< " max_trace_level 5 }\n"
		<< "background { rgb 0 }\n"
		<< "#declare F = finish { ambient 1 diffuse " << (ambient_only ? "0" : "1")
		<< " specular 0 phong 0 }\n";

	// The camera: the ray of pixel (i, j) (OpenCV: (0, 0) the centre of the
	// top-left pixel) is z + (i - cx) / fx x + (j - cy) / fy y in the optical
	// frame. POV-Ray traces pixel (i, j) along direction + u right + v up
	// with u = (i + 0.5) / W - 0.5, v = 0.5 - (j + 0.5) / H.
	const auto Rc = scene.world_T_camera.getRotationMatrix();
	const Vec3 cx_w(Rc(0, 0), Rc(1, 0), Rc(2, 0)), cy_w(Rc(0, 1), Rc(1, 1), Rc(2, 1)),
		cz_w(Rc(0, 2), Rc(1, 2), Rc(2, 2));
	const Vec3 eye(scene.world_T_camera.x(), scene.world_T_camera.y(), scene.world_T_camera.z());
	const Vec3 direction = cz_w + cx_w * ((0.5 * W - 0.5 - cam.cx()) / cam.fx()) +
						   cy_w * ((0.5 * H - 0.5 - cam.cy()) / cam.fy());
	out << "camera { perspective location " << vec(eye) << " direction " << vec(direction)
		<< " right " << vec(cx_w * (W / cam.fx())) << " up " << vec(-cy_w * (H / cam.fy()))
		<< " }\n";

	std::vector<Frame> frames;
	std::vector<double> sheet_half;
	for (const auto& lm : lms)
	{
		frames.push_back(frameOf(lm));
		const LandmarkGeometry g = lm.geometry();
		sheet_half.push_back(g.outerHalf() + g.margin_m);
	}

	// Lamps: one per landmark, intensities so that every landmark centre
	// receives (1 - ambient_share) x level from all lamps together.
	if (!ambient_only && !lms.empty())
	{
		const size_t n = lms.size();
		std::vector<Vec3> lamps;
		for (size_t i = 0; i < n; ++i) lamps.push_back(lampPosition(frames[i], sheet_half[i], pov));
		Eigen::MatrixXd A(n, n);
		const int m = pov.light_type == LightType::Area ? pov.area_light_samples : 1;
		const auto panel = [&](size_t k, int p, int q)
		{
			const double a = pov.area_light_size_m;
			const double u = m > 1 ? a * (p / (m - 1.0) - 0.5) : 0.0;
			const double v = m > 1 ? a * (q / (m - 1.0) - 0.5) : 0.0;
			return Vec3(lamps[k] + frames[k].right * u + frames[k].n * v);
		};	// an area lamp: a horizontal square panel of m x m points
		for (size_t j = 0; j < n; ++j)
			for (size_t k = 0; k < n; ++k)
			{
				double e = 0;
				for (int p = 0; p < m; ++p)
					for (int q = 0; q < m; ++q)
						e += irradiance(panel(k, p, q), frames[j].c, frames[j].n);
				A(j, k) = e / (m * m);
			}
		const Eigen::VectorXd b = Eigen::VectorXd::Constant(n, level * (1 - pov.ambient_share));
		const std::vector<double> I = nonNegativeSolve(A, b);
		// Shadowless: nothing in the scene stands between a lamp and what it
		// lights (the landmarks are flat prints, the walls bound the room).
		for (size_t k = 0; k < n; ++k)
		{
			if (!(I[k] > 0)) continue;
			const double w = I[k] / (m * m);
			for (int p = 0; p < m; ++p)
				for (int q = 0; q < m; ++q)
					out << "light_source { " << vec(panel(k, p, q)) << " " << rgb(w, w, w)
						<< " fade_distance 1 fade_power 2 shadowless }\n";
		}
	}

	// Walls: one plane per set of coplanar landmarks, solid behind. A wall
	// that would hide another landmark or the camera becomes a panel
	// behind each of its landmarks.
	std::vector<Wall> walls;
	for (size_t i = 0; i < lms.size(); ++i)
	{
		const Vec3 n = frames[i].n;
		const double d = n.dot(frames[i].c) - kWallGapM;
		auto it = std::find_if(
			walls.begin(), walls.end(),
			[&](const Wall& w) { return w.n.dot(n) > 1 - 1e-9 && std::abs(w.d - d) < 1e-4; });
		if (it == walls.end())
			walls.push_back({n, d, {i}});
		else
			it->landmarks.push_back(i);
	}
	const WallTexture wall_tex = pov.wall != WallTexture::Auto		? pov.wall
								 : o.background == Background::Flat ? WallTexture::Plain
																	: WallTexture::Plaster;
	const std::string wall_texture =
		"texture { " + wallPigment(wall_tex, o.background_grey / 255.0, pov.texture_seed) +
		" finish { F } }";
	for (const Wall& w : walls)
	{
		const double cam_side = w.n.dot(eye) - w.d;
		if (cam_side <= 0) continue;  // behind the wall: its landmarks face away
		bool hides = false;
		for (size_t j = 0; j < lms.size(); ++j) hides = hides || w.n.dot(frames[j].c) < w.d - 1e-3;
		if (!hides)
			out << "plane { " << vec(w.n) << ", " << num(w.d) << " " << wall_texture << " }\n";
		else
			for (size_t i : w.landmarks)
			{
				const Frame& f = frames[i];
				const double s = sheet_half[i] + 1.0;
				out << "box { <-0.01, " << num(-s) << ", " << num(-s) << ">, <0, " << num(s) << ", "
					<< num(s) << "> " << wall_texture << " matrix <" << num(f.n.x()) << ", "
					<< num(f.n.y()) << ", " << num(f.n.z()) << ", " << num(f.right.x()) << ", "
					<< num(f.right.y()) << ", " << num(f.right.z()) << ", " << num(f.up.x()) << ", "
					<< num(f.up.y()) << ", " << num(f.up.z()) << ", "
					<< num(f.c.x() - kWallGapM * f.n.x()) << ", "
					<< num(f.c.y() - kWallGapM * f.n.y()) << ", "
					<< num(f.c.z() - kWallGapM * f.n.z()) << "> }\n";
			}
	}

	// Floor and ceiling: below and above every landmark and the camera.
	double floor_z = std::min(0.0, eye.z() - 0.05), ceiling_z = std::max(2.6, eye.z() + 0.3);
	for (size_t i = 0; i < lms.size(); ++i)
	{
		floor_z = std::min(floor_z, frames[i].c.z() - 1.5 * sheet_half[i]);
		ceiling_z = std::max(ceiling_z, frames[i].c.z() + 1.5 * sheet_half[i] + 0.3);
	}
	out << "plane { z, " << num(floor_z) << " texture { "
		<< floorPigment(pov.floor, pov.texture_seed) << " finish { F } } }\n";
	out << "plane { -z, " << num(-ceiling_z) << " " << paint(rgb(0.8, 0.8, 0.8)) << " }\n";

	// Landmarks, and the occluders drawn far to near as render() does so
	// that the sides match its seed.
	std::vector<size_t> order(lms.size());
	std::iota(order.begin(), order.end(), size_t(0));
	const auto dist = [&](size_t i) { return (frames[i].c - eye).norm(); };
	std::stable_sort(
		order.begin(), order.end(), [&](size_t a, size_t b) { return dist(a) > dist(b); });
	cv::RNG occ_rng(detail::streamSeed(seed, 3));
	const std::string white = paint(rgbOf(o.white_bgr)), black = paint(rgbOf(o.black_bgr)),
					  green = paint(rgbOf(o.green_bgr));
	for (size_t i : order)
	{
		const int side = occ_rng.uniform(0, 4);
		const Frame& f = frames[i];
		// The back of a landmark is the wall it hangs on.
		if (f.n.dot(eye - f.c) <= 0) continue;
		const LandmarkGeometry g = lms[i].geometry();
		out << "// landmark " << lms[i].id << "\n";
		out << squarePolygon(f, sheet_half[i], -2 * kLayerM, white);
		out << squarePolygon(f, g.outerHalf(), -kLayerM, black);
		out << squarePolygon(f, g.innerHalf(), 0, green);  // its edge: the reference square
		const CodeCells cells = encodeId(lms[i].id);
		const double c = g.cell_size_m;
		for (int r = 0; r < 3; ++r)
			for (int q = 0; q < 3; ++q)
				if (cells[r][q])
				{
					const double s = (q - 1) * c, t = (1 - r) * c;
					out << facePolygon(
						f, s - 0.5 * c, t - 0.5 * c, s + 0.5 * c, t + 0.5 * c, kLayerM, black);
				}
		if (o.occlusion > 0)
		{
			const double far = 1.3 * sheet_half[i], h = g.innerHalf(),
						 edge = -h + 2 * h * o.occlusion;
			double s0 = -far, s1 = far, t0 = -far, t1 = far;
			switch (side)
			{
				case 0:
					s1 = edge;
					break;
				case 1:
					s0 = -edge;
					break;
				case 2:
					t1 = edge;
					break;
				default:
					t0 = -edge;
					break;
			}
			out << facePolygon(
				f, s0, t0, s1, t1, 3 * kLayerM,
				paint(rgb(kOccluderReflectance, kOccluderReflectance, kOccluderReflectance)));
		}
	}
	if (o.background == Background::Cluttered && o.distractors > 0)
		for (size_t i = 0; i < lms.size(); ++i)
			writeDistractors(
				out, frames[i], frames, sheet_half, i, o.distractors, pov.texture_seed, o, floor_z);
	return out.str();
}

// ---------------------------------------------------------------------------
// Running POV-Ray

namespace
{
/** FNV-1a, 64 bits, as 16 hex digits. */
std::string hashHex(const std::string& text)
{
	uint64_t h = 0xcbf29ce484222325ull;
	for (unsigned char ch : text) h = (h ^ ch) * 0x100000001b3ull;
	char buf[17];
	std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(h));
	return buf;
}

/** The program \a exe on PATH (or as given with a '/'), or "" when absent. */
std::string findProgram(const std::string& exe)
{
	if (exe.find('/') != std::string::npos)
		return ::access(exe.c_str(), X_OK) == 0 ? exe : std::string();
	const char* path = std::getenv("PATH");
	std::istringstream dirs(path ? path : "/usr/local/bin:/usr/bin:/bin");
	std::string dir;
	while (std::getline(dirs, dir, ':'))
	{
		std::string p = (dir.empty() ? std::string(".") : dir) + "/" + exe;
		if (::access(p.c_str(), X_OK) == 0) return p;
	}
	return {};
}

std::string lastLines(const std::string& file, size_t n)
{
	std::ifstream in(file);
	std::vector<std::string> lines;
	std::string l;
	while (std::getline(in, l))
		if (!l.empty()) lines.push_back(l);
	std::string out;
	for (size_t i = lines.size() > n ? lines.size() - n : 0; i < lines.size(); ++i)
		out += (out.empty() ? "" : " | ") + lines[i];
	return out;
}

/** Runs \a args in \a dir with stdout and stderr into \a log; the exit status. */
int runIn(const std::string& dir, const std::vector<std::string>& args, const std::string& log)
{
	std::vector<char*> argv;
	argv.reserve(args.size() + 1);
	for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
	argv.push_back(nullptr);
	const pid_t pid = ::fork();
	if (pid < 0)
		throw std::runtime_error(std::string("povray: cannot fork: ") + std::strerror(errno));
	if (pid == 0)
	{
		if (::chdir(dir.c_str()) != 0) ::_exit(126);
		const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
		if (fd >= 0)
		{
			::dup2(fd, 1);
			::dup2(fd, 2);
			::close(fd);
		}
		const int null = ::open("/dev/null", O_RDONLY);
		if (null >= 0) ::dup2(null, 0);
		::execv(argv[0], argv.data());
		::_exit(127);
	}
	int status = 0;
	while (::waitpid(pid, &status, 0) < 0)
		if (errno != EINTR) throw std::runtime_error("povray: waitpid failed");
	return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}
}  // namespace

std::string povrayCachedRender(
	const Scene& scene, const RenderOptions& options, const PovrayOptions& pov, uint64_t seed)
{
	const std::string text = povrayScene(scene, options, pov, seed);
	const int W = scene.camera.width(), H = scene.camera.height();
	const std::string settings = "Width=" + std::to_string(W) + "\nHeight=" + std::to_string(H) +
								 "\n" + pov.renderSettings();
	const std::string key = hashHex(text + "\n//settings\n" + settings);
	const fs::path dir = fs::absolute(pov.cacheDirectory());
	const fs::path png = dir / (key + ".png");
	if (fs::exists(png)) return png.string();

	const std::string exe = findProgram(pov.executable);
	if (exe.empty())
		throw std::runtime_error(
			"povray: program '" + pov.executable +
			"' not found (install POV-Ray 3.7: apt-get install povray)");
	createFolder(dir.string(), "the POV-Ray cache");
	std::error_code ec;

	// POV-Ray's I/O restrictions allow the working directory: render there
	// under a name of this process, then rename (atomic for readers).
	const std::string tag = key + "." + std::to_string(::getpid());
	const std::string pov_name = key + ".pov", tmp_png = tag + ".tmp.png", log = tag + ".log";
	{
		std::ofstream f(dir / (tag + ".pov"));
		f << text;
		if (!f) throw std::runtime_error((dir / pov_name).string() + ": cannot write");
	}
	fs::rename(dir / (tag + ".pov"), dir / pov_name, ec);
	std::vector<std::string> args{
		exe,
		"+I" + pov_name,
		"+O" + tmp_png,
		"+W" + std::to_string(W),
		"+H" + std::to_string(H),
		"+FN16",
		"-D",
		"-P",
		"-V",
		"+WT" + std::to_string(pov.threads)};
	std::istringstream lines(pov.renderSettings());
	for (std::string l; std::getline(lines, l);)
		if (!l.empty()) args.push_back(l);
	const int rc = runIn(dir.string(), args, (dir / log).string());
	if (rc != 0 || !fs::exists(dir / tmp_png))
	{
		const std::string msg = lastLines((dir / log).string(), 3);
		fs::remove(dir / tmp_png, ec);
		throw std::runtime_error(
			"povray: rendering " + (dir / pov_name).string() + " failed (exit " +
			std::to_string(rc) + "): " + msg);
	}
	fs::rename(dir / tmp_png, png, ec);
	if (ec) throw std::runtime_error(png.string() + ": cannot store the render: " + ec.message());
	fs::remove(dir / log, ec);
	return png.string();
}

cv::Mat readLinearPng(const std::string& path)
{
	const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
	if (raw.empty() || raw.depth() != CV_16U || raw.channels() != 3)
		throw std::runtime_error(path + ": not a 16-bit RGB PNG");
	cv::Mat linear;
	raw.convertTo(linear, CV_32FC3, 255.0 / 65535.0);
	return linear;
}

Render renderPovray(
	const Scene& scene, const RenderOptions& options, uint64_t seed, const PovrayOptions& pov)
{
	cv::Mat linear = readLinearPng(povrayCachedRender(scene, options, pov, seed));
	Render out;
	out.image =
		cameraImage(linear, options.drawn(seed), scene.camera.cx(), scene.camera.cy(), seed);
	out.truth = groundTruth(scene);
	for (auto& t : out.truth)
		if (t.facing) t.occluded_fraction = options.occlusion;
	return out;
}

Renderer povrayRenderer(const PovrayOptions& pov)
{
	return [pov](const Scene& scene, const RenderOptions& options, uint64_t seed)
	{ return renderPovray(scene, options, seed, pov); };
}

}  // namespace codemark::sim
