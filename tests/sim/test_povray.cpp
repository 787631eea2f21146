// The POV-Ray renderer: the scene text (no povray needed), the edge
// placement and the camera mapping on the committed renders of
// tests/data/povray (regenerate.sh there), a live render when povray is
// installed, and the error of a missing program.
#include <codemark/landmark/codebook.h>
#include <codemark/sim/frames.h>
#include <codemark/sim/povray.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <opencv2/imgproc.hpp>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <unistd.h>

using namespace codemark;
using namespace codemark::sim;
namespace fs = std::filesystem;

namespace
{
const std::string kData = std::string(CODEMARK_TEST_DATA_DIR) + "/povray";

bool havePovray()
{
	const char* path = std::getenv("PATH");
	std::istringstream dirs(path ? path : "");
	for (std::string d; std::getline(dirs, d, ':');)
		if (!d.empty() && ::access((d + "/povray").c_str(), X_OK) == 0) return true;
	return false;
}

/** A fresh, empty directory under the system's temporary directory. */
std::string freshDir(const std::string& name)
{
	const fs::path p = fs::temp_directory_path() /
					   ("codemark-test-povray-" + name + "-" + std::to_string(::getpid()));
	fs::remove_all(p);
	fs::create_directories(p);
	return p.string();
}

/** The scene of a committed edge render: map, camera and pose of
 * tests/data/povray. */
Scene edgeScene()
{
	Scene s;
	s.map = LandmarkMap::load(kData + "/map.txt");
	s.camera = CameraModel::load(kData + "/camera-edge.ini");
	s.world_T_camera = loadCameraPoses(kData + "/edge-pose.txt").at(0);
	return s;
}

/** Projection of face point (s, t) of the scene's first landmark [px]. */
Eigen::Vector2d projectFace(const Scene& scene, double s, double t)
{
	const auto& lm = scene.map.landmarks[0];
	const mrpt::poses::CPose3D cam_T_lm = lm.world_T_landmark() - scene.world_T_camera;
	const Eigen::Vector3d pl = LandmarkGeometry::faceToLandmark(s, t);
	double x, y, z;
	cam_T_lm.composePoint(pl.x(), pl.y(), pl.z(), x, y, z);
	return {
		scene.camera.fx() * x / z + scene.camera.cx(),
		scene.camera.fy() * y / z + scene.camera.cy()};
}

/** Area and area-weighted centroid of a polygon (shoelace). */
std::pair<double, Eigen::Vector2d> areaCentroid(const std::vector<Eigen::Vector2d>& p)
{
	double a = 0;
	Eigen::Vector2d c(0, 0);
	for (size_t i = 0; i < p.size(); ++i)
	{
		const auto& p0 = p[i];
		const auto& p1 = p[(i + 1) % p.size()];
		const double cr = p0.x() * p1.y() - p1.x() * p0.y();
		a += cr;
		c += (p0 + p1) * cr;
	}
	return {0.5 * a, c / (3 * a)};
}

/** The projected centroid of the green fill (the reference square less
 * the black code cells). */
Eigen::Vector2d greenCentroidTruth(const Scene& scene)
{
	const auto& lm = scene.map.landmarks[0];
	const LandmarkGeometry g = lm.geometry();
	const auto rect = [&](double s0, double t0, double s1, double t1)
	{
		return areaCentroid(
			{projectFace(scene, s0, t0), projectFace(scene, s1, t0), projectFace(scene, s1, t1),
			 projectFace(scene, s0, t1)});
	};
	const double h = g.innerHalf(), c = g.cell_size_m;
	auto [a, m] = rect(-h, -h, h, h);
	Eigen::Vector2d moment = m * a;
	const CodeCells cells = encodeId(lm.id);
	for (int r = 0; r < 3; ++r)
		for (int q = 0; q < 3; ++q)
			if (cells[r][q])
			{
				const double s = (q - 1) * c, t = (1 - r) * c;
				auto [ac, mc] = rect(s - c / 2, t - c / 2, s + c / 2, t + c / 2);
				moment -= mc * ac;
				a -= ac;
			}
	return moment / a;
}

/** The green fill's centroid measured from the image: each pixel weighted
 * by its green coverage (G - black) / (green - black), over the pixels
 * whose centre lies 1.5 px or more inside the projected outer frame (so
 * that only the black frame, the fill and the cells are in it). */
Eigen::Vector2d greenCentroidMeasured(
	const cv::Mat& green_channel, const Scene& scene, double black, double green)
{
	const double h = scene.map.landmarks[0].geometry().outerHalf();
	std::vector<cv::Point2f> outline;
	for (const auto& st :
		 {Eigen::Vector2d(-h, h), Eigen::Vector2d(h, h), Eigen::Vector2d(h, -h),
		  Eigen::Vector2d(-h, -h)})
	{
		const Eigen::Vector2d p = projectFace(scene, st.x(), st.y());
		outline.emplace_back(float(p.x()), float(p.y()));
	}
	double sw = 0;
	Eigen::Vector2d m(0, 0);
	for (int v = 0; v < green_channel.rows; ++v)
		for (int u = 0; u < green_channel.cols; ++u)
		{
			if (cv::pointPolygonTest(outline, cv::Point2f(float(u), float(v)), true) < 1.5)
				continue;
			const double w = (green_channel.at<float>(v, u) - black) / (green - black);
			sw += w;
			m += w * Eigen::Vector2d(u, v);
		}
	return m / sw;
}

/** The edge from p0 to p1 found by the area of its profile, line by line
 * (rows for a steep edge, columns for a flat one): over a window of
 * 2 half + 1 pixels across the edge, the dark side's area gives the edge's
 * position on that line. For a straight edge and exact area coverage this
 * is the truth's position at the line's centre. Errors [px] per line,
 * \a trim_px clear of the ends. */
std::vector<double> edgeErrors(
	const cv::Mat& img, Eigen::Vector2d p0, Eigen::Vector2d p1, double dark, double bright,
	bool dark_first, int half = 3, double trim_px = 5)
{
	const bool steep = std::abs(p1.y() - p0.y()) > std::abs(p1.x() - p0.x());
	const auto along = [&](const Eigen::Vector2d& p) { return steep ? p.y() : p.x(); };
	const auto across = [&](const Eigen::Vector2d& p) { return steep ? p.x() : p.y(); };
	if (along(p0) > along(p1)) std::swap(p0, p1);
	std::vector<double> errs;
	for (int k = int(std::ceil(along(p0) + trim_px)); k <= int(std::floor(along(p1) - trim_px));
		 ++k)
	{
		const double f = (k - along(p0)) / (along(p1) - along(p0));
		const double e = across(p0) + f * (across(p1) - across(p0));
		const int c = int(std::lround(e));
		double area = 0;  // of the first side along the line
		for (int i = c - half; i <= c + half; ++i)
		{
			const double v = steep ? img.at<float>(k, i) : img.at<float>(i, k);
			const double dark_fraction = (bright - v) / (bright - dark);
			area += dark_first ? dark_fraction : 1 - dark_fraction;
		}
		errs.push_back(c - half - 0.5 + area - e);
	}
	return errs;
}

struct EdgeCheck
{
	double worst_bias = 0;	//!< largest |mean error| over the four edges [px]
	double worst_rms = 0;  //!< largest RMS error per line over the four edges [px]
};

/** The four inner frame edges of a committed edge render, in its G
 * channel (black frame outside, green fill inside). */
EdgeCheck checkEdges(const std::string& dir, double level, double green_g, double black_g)
{
	const Scene scene = edgeScene();
	const LandmarkTruth tr = groundTruth(scene).at(0);
	const cv::Mat lin = readLinearPng(dir + "/linear_000.png");
	EXPECT_EQ(lin.cols, scene.camera.width());
	cv::Mat ch[3];
	cv::split(lin, ch);
	const double dark = black_g * level, bright = green_g * level;
	const auto& c = tr.corners_px;	// TL TR BR BL
	// Left and top: the black frame comes first along rows / columns; right
	// and bottom: the green fill does.
	const std::array<std::vector<double>, 4> e{
		edgeErrors(ch[1], c[0], c[3], dark, bright, true),
		edgeErrors(ch[1], c[1], c[2], dark, bright, false),
		edgeErrors(ch[1], c[0], c[1], dark, bright, true),
		edgeErrors(ch[1], c[3], c[2], dark, bright, false)};
	EdgeCheck out;
	const char* names[4] = {"left", "right", "top", "bottom"};
	for (int i = 0; i < 4; ++i)
	{
		EXPECT_GT(e[i].size(), 80u) << names[i];
		double mean = 0, ss = 0;
		for (double x : e[i]) mean += x, ss += x * x;
		mean /= e[i].size();
		const double rms = std::sqrt(ss / e[i].size());
		std::printf(
			"[ edge ] %s %-6s: bias %+.4f px, rms per line %.4f px over %zu lines\n",
			dir.substr(dir.rfind('/') + 1).c_str(), names[i], mean, rms, e[i].size());
		out.worst_bias = std::max(out.worst_bias, std::abs(mean));
		out.worst_rms = std::max(out.worst_rms, rms);
	}
	return out;
}

/** Numbers of "key <x, y, z>" in the scene text. */
Eigen::Vector3d vectorAfter(const std::string& text, const std::string& key)
{
	const std::regex re(key + " <([^,]+), ([^,]+), ([^>]+)>");
	std::smatch m;
	EXPECT_TRUE(std::regex_search(text, m, re)) << key;
	return {std::stod(m[1]), std::stod(m[2]), std::stod(m[3])};
}

size_t count(const std::string& text, const std::string& what)
{
	size_t n = 0;
	for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
	return n;
}
}  // namespace

// (c) The scene text: deterministic, balanced, and built from the spec.
TEST(PovrayScene, DeterministicAndWellFormed)
{
	const Scene scene = edgeScene();
	RenderOptions o;
	PovrayOptions pov;
	const std::string a = povrayScene(scene, o, pov, 7), b = povrayScene(scene, o, pov, 7);
	EXPECT_EQ(a, b);
	// Without occlusion the frame's seed changes nothing.
	EXPECT_EQ(a, povrayScene(scene, o, pov, 8));
	EXPECT_NE(a.find("#version 3.7;"), std::string::npos);
	EXPECT_NE(a.find("assumed_gamma 1.0"), std::string::npos);
	EXPECT_EQ(count(a, "{"), count(a, "}"));
	EXPECT_EQ(a.find("nan"), std::string::npos);
	EXPECT_EQ(a.find("inf"), std::string::npos);
	EXPECT_EQ(count(a, "camera {"), 1u);
	// Sheet, frame, fill and one polygon per black cell (ID 37: 3 + centre).
	const CodeCells cells = encodeId(37);
	size_t black = 0;
	for (const auto& r : cells)
		for (bool c : r) black += c;
	EXPECT_EQ(count(a, "polygon {"), 3 + black);
	EXPECT_EQ(count(a, "light_source {"), 1u);
	// One plane each: the wall, the floor, the ceiling.
	EXPECT_EQ(count(a, "plane {"), 3u);
	// Colours are linear reflectances: the white sheet's 235 / 255.
	EXPECT_NE(a.find("rgb <0.921568627451, 0.921568627451, 0.921568627451>"), std::string::npos);

	// Another print changes the fill's colour only.
	RenderOptions office = o;
	office.green_bgr = cv::Scalar(80, 170, 40);
	const std::string c = povrayScene(scene, office, pov, 7);
	EXPECT_NE(c.find("rgb <0.156862745098, 0.666666666667, 0.313725490196>"), std::string::npos);
	EXPECT_EQ(count(c, "polygon {"), count(a, "polygon {"));

	// Area lamps: area_light_samples^2 points; ambient light: no lamp.
	PovrayOptions area = pov;
	area.light_type = LightType::Area;
	EXPECT_EQ(count(povrayScene(scene, o, area, 7), "light_source {"), 9u);
	PovrayOptions flat = pov;
	flat.light_type = LightType::Ambient;
	EXPECT_EQ(count(povrayScene(scene, o, flat, 7), "light_source {"), 0u);
}

// (c) The camera statement is the pinhole: POV-Ray's ray of pixel (i, j),
// direction + ((i + 0.5) / W - 0.5) right + (0.5 - (j + 0.5) / H) up, is the
// ray through OpenCV's pixel centre (i, j).
TEST(PovrayScene, CameraIsThePinhole)
{
	const Scene scene = edgeScene();
	const std::string text = povrayScene(scene, RenderOptions(), PovrayOptions(), 1);
	const Eigen::Vector3d loc = vectorAfter(text, "location"), dir = vectorAfter(text, "direction"),
						  right = vectorAfter(text, "right"), up = vectorAfter(text, "up");
	const CameraModel& cam = scene.camera;
	const int W = cam.width(), H = cam.height();
	const mrpt::poses::CPose3D cam_T_world = -scene.world_T_camera;
	for (const auto& ij :
		 {Eigen::Vector2d(0, 0), Eigen::Vector2d(W - 1, H - 1), Eigen::Vector2d(17, 151),
		  Eigen::Vector2d(cam.cx(), cam.cy())})
	{
		const Eigen::Vector3d ray =
			dir + ((ij.x() + 0.5) / W - 0.5) * right + (0.5 - (ij.y() + 0.5) / H) * up;
		const Eigen::Vector3d p = loc + 2.0 * ray;
		double x, y, z;
		cam_T_world.composePoint(p.x(), p.y(), p.z(), x, y, z);
		EXPECT_NEAR(cam.fx() * x / z + cam.cx(), ij.x(), 1e-7);
		EXPECT_NEAR(cam.fy() * y / z + cam.cy(), ij.y(), 1e-7);
	}
}

TEST(PovrayScene, OcclusionDistractorsAndErrors)
{
	const Scene scene = edgeScene();
	RenderOptions o;
	const PovrayOptions pov;
	const size_t plain = count(povrayScene(scene, o, pov, 1), "polygon {");
	o.occlusion = 0.3;
	EXPECT_EQ(count(povrayScene(scene, o, pov, 1), "polygon {"), plain + 1);
	o.occlusion = 0;
	o.background = Background::Cluttered;
	o.distractors = 6;
	const std::string cluttered = povrayScene(scene, o, pov, 1);
	EXPECT_GT(count(cluttered, "polygon {") + count(cluttered, "disc {"), plain + 5);

	// A camera with distortion: refused, naming the camera.
	Scene distorted = scene;
	mrpt::img::TCamera p = scene.camera.params();
	p.cameraName = "lens-cam";
	p.distortion = mrpt::img::DistortionModel::plumb_bob;
	p.dist[0] = -0.2;
	distorted.camera = CameraModel(p);
	try
	{
		povrayScene(distorted, RenderOptions(), pov, 1);
		FAIL() << "no exception";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("lens-cam"), std::string::npos) << e.what();
	}

	// Bad options name their key.
	PovrayOptions bad = pov;
	bad.aa_depth = 12;
	try
	{
		bad.validate();
		FAIL() << "no exception";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("aa_depth"), std::string::npos) << e.what();
	}
	EXPECT_THROW(lightLevelFromName("dusk"), std::invalid_argument);
	EXPECT_EQ(lightLevelFromName("Bright"), LightLevel::Bright);
}

TEST(PovrayOptions, IniRoundTrip)
{
	PovrayOptions a;
	a.light = LightLevel::Dim;
	a.light_type = LightType::Area;
	a.light_gradient = -0.2;
	a.wall = WallTexture::Brick;
	a.floor = FloorTexture::Wood;
	a.texture_seed = 42;
	a.aa_threshold = 0.02;
	mrpt::config::CConfigFileMemory mem;
	a.saveToConfigFile(mem, "povray");
	PovrayOptions b;
	b.loadFromConfigFile(mem, "povray");
	EXPECT_EQ(b.light, a.light);
	EXPECT_EQ(b.light_type, a.light_type);
	EXPECT_EQ(b.light_gradient, a.light_gradient);
	EXPECT_EQ(b.wall, a.wall);
	EXPECT_EQ(b.floor, a.floor);
	EXPECT_EQ(b.texture_seed, a.texture_seed);
	EXPECT_EQ(b.renderSettings(), a.renderSettings());
	mem.write("povray", "light", "dusk");
	EXPECT_THROW(b.loadFromConfigFile(mem, "povray"), std::invalid_argument);
}

// (d) A missing program: one line naming it and how to install POV-Ray.
TEST(PovrayRender, MissingProgramIsOneLine)
{
	PovrayOptions pov;
	pov.executable = "codemark-no-such-povray";
	pov.cache_dir = freshDir("missing");
	try
	{
		renderPovray(edgeScene(), RenderOptions(), 1, pov);
		FAIL() << "no exception";
	}
	catch (const std::runtime_error& e)
	{
		const std::string msg = e.what();
		EXPECT_NE(msg.find("codemark-no-such-povray"), std::string::npos) << msg;
		EXPECT_NE(msg.find("apt-get install povray"), std::string::npos) << msg;
		EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
	}
	fs::remove_all(pov.cache_dir);
}

// (a) Edge placement on the committed renders: each inner frame edge,
// located by its profile's area line by line, lies where the projected
// truth puts it, within 0.02 px on average along the edge, at high
// contrast (fluorescent green against black, normal light) and low
// contrast (7 grey levels: a dark green print in dim light).
TEST(PovrayRender, EdgePlacementHighContrast)
{
	const EdgeCheck e = checkEdges(kData + "/edge-high", 255.0 * 1.0, 1.0, 25.0 / 255.0);
	EXPECT_LT(e.worst_bias, 0.02);
	EXPECT_LT(e.worst_rms, 0.05);
}

TEST(PovrayRender, EdgePlacementLowContrast)
{
	const EdgeCheck e = checkEdges(kData + "/edge-low", 255.0 * 0.35, 45.0 / 255.0, 25.0 / 255.0);
	EXPECT_LT(e.worst_bias, 0.02);
	EXPECT_LT(e.worst_rms, 0.05);
}

// (b) The camera mapping on the committed render (principal point off the
// centre, fx != fy, a rolled and pitched camera): the centroid of the green
// fill, measured model-free from the pixels' coverage, is the projected
// truth's within 0.05 px.
TEST(PovrayRender, CameraMappingCommitted)
{
	const Scene scene = edgeScene();
	const cv::Mat lin = readLinearPng(kData + "/edge-high/linear_000.png");
	cv::Mat ch[3];
	cv::split(lin, ch);
	const Eigen::Vector2d m = greenCentroidMeasured(ch[1], scene, 25.0, 255.0);
	const Eigen::Vector2d t = greenCentroidTruth(scene);
	std::printf(
		"[ mapping ] committed: measured - truth = (%+.4f, %+.4f) px\n", m.x() - t.x(),
		m.y() - t.y());
	EXPECT_LT((m - t).norm(), 0.05);
}

// (b) The same, rendered now (needs the povray program): the paper's
// camera with its principal point moved off the centre.
TEST(PovrayRender, CameraMappingLive)
{
	if (!havePovray()) GTEST_SKIP() << "povray not installed";
	mrpt::img::TCamera p = CameraModel::paperDefault().params();
	p.ncols = 320;
	p.nrows = 240;
	p.intrinsicParams(0, 0) = 420;	// fx
	p.intrinsicParams(1, 1) = 400;	// fy
	p.intrinsicParams(0, 2) = 171.2;  // cx
	p.intrinsicParams(1, 2) = 110.6;  // cy
	Scene scene = singleLandmarkScene(CameraModel(p), 37, 0.5);
	scene.world_T_camera =
		levelCameraLookingAt(scene.map.landmarks[0], 0.7, 35 * M_PI / 180, -0.03, 0.05);
	RenderOptions o;
	PovrayOptions pov;
	pov.light_type = LightType::Ambient;
	pov.wall = WallTexture::Plain;
	pov.cache_dir = freshDir("live");
	const cv::Mat lin = readLinearPng(povrayCachedRender(scene, o, pov, 1));
	ASSERT_EQ(lin.cols, 320);
	ASSERT_EQ(lin.rows, 240);
	cv::Mat ch[3];
	cv::split(lin, ch);
	const Eigen::Vector2d m = greenCentroidMeasured(ch[1], scene, 25.0, 255.0);
	const Eigen::Vector2d t = greenCentroidTruth(scene);
	std::printf(
		"[ mapping ] live: measured - truth = (%+.4f, %+.4f) px\n", m.x() - t.x(), m.y() - t.y());
	EXPECT_LT((m - t).norm(), 0.05);

	// The cache: a second call reuses the render.
	const std::string path = povrayCachedRender(scene, o, pov, 1);
	EXPECT_TRUE(fs::exists(path));
	const Render r = renderPovray(scene, o, 1, pov);
	EXPECT_EQ(r.image.type(), CV_8UC3);
	EXPECT_EQ(r.truth.size(), 1u);
	fs::remove_all(pov.cache_dir);
}

// The light levels: the white sheet near 0.92 of full scale at normal
// light, 0.35 x and 1.6 x (clipped) at dim and bright, on the committed set
// renders (the sheet's centre-left margin, away from the frame).
TEST(PovrayRender, LightLevelsOfTheSet)
{
	const auto fill = [&](const std::string& group)
	{
		const std::string dir = kData + "/set/" + group;
		Scene s;
		s.map = LandmarkMap::load(kData + "/set/map.txt");
		s.camera = CameraModel::paperDefault();	 // the set's camera
		s.world_T_camera = loadCameraPoses(dir + "/poses.txt").at(0);
		const LandmarkTruth tr = groundTruth(s).at(0);
		const cv::Mat lin = readLinearPng(dir + "/linear_000.png");
		// The fill's G at the reference square's centre region, away from the cells.
		Eigen::Vector2d c(0, 0);
		for (const auto& q : tr.corners_px) c += q / 4;
		const Eigen::Vector2d mid_left = 0.5 * (tr.corners_px[0] + tr.corners_px[3]);
		const Eigen::Vector2d p = mid_left + 0.15 * (c - mid_left);
		return lin.at<cv::Vec3f>(int(std::lround(p.y())), int(std::lround(p.x())))[1];
	};
	const double normal = fill("normal-fluorescent");
	EXPECT_NEAR(normal / 255.0, 1.0, 0.12);
	EXPECT_NEAR(fill("dim-fluorescent") / normal, 0.35, 0.06);
	EXPECT_GE(fill("bright-fluorescent"), 254.0);  // saturated
}
