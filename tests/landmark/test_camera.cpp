#include <codemark/landmark/camera.h>
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include <cstdio>
#include <fstream>
#include <random>

using namespace codemark;

namespace
{
std::string writeTemp(const std::string& name, const std::string& text)
{
	const std::string p = ::testing::TempDir() + name;
	std::ofstream(p) << text;
	return p;
}

CameraModel distortedCamera()
{
	mrpt::img::TCamera c;
	c.ncols = 1280;
	c.nrows = 960;
	c.setIntrinsicParamsFromValues(1000.0, 990.0, 640.3, 478.9);
	c.setDistortionPlumbBob(-0.28, 0.09, 0.0012, -0.0007, -0.012);
	return CameraModel(c);
}
}  // namespace

TEST(Camera, PaperDefault)
{
	const CameraModel c = CameraModel::paperDefault();
	EXPECT_EQ(c.width(), 640);
	EXPECT_EQ(c.height(), 480);
	EXPECT_DOUBLE_EQ(c.fx(), 800);
	EXPECT_DOUBLE_EQ(c.cx(), 319.5);
	EXPECT_FALSE(c.hasDistortion());
	const auto px = c.project({0, 0, 2});
	ASSERT_TRUE(px.has_value());
	EXPECT_DOUBLE_EQ(px->x(), 319.5);
	EXPECT_FALSE(c.project({0, 0, -1}).has_value());
}

TEST(Camera, ProjectionMatchesOpenCv)
{
	const CameraModel cam = distortedCamera();
	std::mt19937 rng(3);
	std::uniform_real_distribution<double> u(-0.6, 0.6), z(0.5, 5);
	std::vector<cv::Point3d> pts;
	for (int i = 0; i < 200; ++i)
	{
		const double zz = z(rng);
		pts.emplace_back(u(rng) * zz, u(rng) * zz * 0.75, zz);
	}
	const auto& P = cam.params();
	cv::Mat K = (cv::Mat_<double>(3, 3) << P.fx(), 0, P.cx(), 0, P.fy(), P.cy(), 0, 0, 1);
	cv::Mat D(1, 8, CV_64F);
	for (int i = 0; i < 8; ++i) D.at<double>(i) = P.dist[i];
	std::vector<cv::Point2d> ref;
	cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, ref);
	for (std::size_t i = 0; i < pts.size(); ++i)
	{
		const auto px = cam.project({pts[i].x, pts[i].y, pts[i].z});
		ASSERT_TRUE(px);
		EXPECT_NEAR(px->x(), ref[i].x, 1e-9);
		EXPECT_NEAR(px->y(), ref[i].y, 1e-9);
	}
}

TEST(Camera, UndistortRoundTrip)
{
	const CameraModel cam = distortedCamera();
	std::mt19937 rng(5);
	std::uniform_real_distribution<double> u(-0.55, 0.55), v(-0.42, 0.42);
	for (int i = 0; i < 500; ++i)
	{
		const Eigen::Vector2d xn(u(rng), v(rng));
		const Eigen::Vector2d raw = cam.distortNormalized(xn);
		const Eigen::Vector2d back = cam.undistortToNormalized(raw);
		EXPECT_NEAR((back - xn).norm() * cam.fx(), 0.0, 1e-6) << xn.transpose();
		const Eigen::Vector2d ideal = cam.undistortPixel(raw);
		EXPECT_NEAR(ideal.x(), cam.fx() * xn.x() + cam.cx(), 1e-6);
	}
}

TEST(Camera, LoadsMrptIni)
{
	const auto p = writeTemp(
		"cam.ini",
		"[CAMERA_PARAMS]\nresolution = [800 600]\ncx = 400.5\ncy = 300.25\nfx = 700\nfy = "
		"710\ndistortion_model = plumb_bob\ndist = [-0.1 0.01 0 0 0]\n");
	std::vector<std::string> warnings;
	const CameraModel c = CameraModel::load(p, &warnings);
	EXPECT_TRUE(warnings.empty());
	EXPECT_EQ(c.width(), 800);
	EXPECT_DOUBLE_EQ(c.fy(), 710);
	EXPECT_TRUE(c.hasDistortion());
	EXPECT_DOUBLE_EQ(c.params().dist[0], -0.1);
}

TEST(Camera, WarnsWhenDistWithoutModel)
{
	const auto p = writeTemp(
		"cam_nomodel.ini",
		"[CAMERA_PARAMS]\nresolution = [640 480]\ncx = 319.5\ncy = 239.5\nfx = 800\nfy = "
		"800\ndist = [-0.2 0.05 0 0 0]\n");
	std::vector<std::string> warnings;
	const CameraModel c = CameraModel::load(p, &warnings);
	ASSERT_EQ(warnings.size(), 1u);
	EXPECT_NE(warnings[0].find("distortion_model"), std::string::npos);
	EXPECT_FALSE(c.hasDistortion());  // as MRPT does
}

TEST(Camera, LoadsRosYaml)
{
	const auto p = writeTemp(
		"cam_ros.yaml",
		"image_width: 1280\nimage_height: 720\ncamera_name: cam0\ncamera_matrix:\n  rows: 3\n  "
		"cols: 3\n  data: [900.5, 0, 640.1, 0, 901.5, 360.2, 0, 0, 1]\ndistortion_model: "
		"plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [-0.3, 0.1, 0.001, "
		"-0.002, 0]\n");
	const CameraModel c = CameraModel::load(p);
	EXPECT_EQ(c.width(), 1280);
	EXPECT_DOUBLE_EQ(c.fx(), 900.5);
	EXPECT_DOUBLE_EQ(c.cy(), 360.2);
	EXPECT_DOUBLE_EQ(c.params().dist[3], -0.002);
}

TEST(Camera, LoadsOpenCvYaml)
{
	const auto p = writeTemp(
		"cam_cv.yaml",
		"%YAML:1.0\n---\ncalibration_time: \"Sat 05 Dec 2026\"\nimage_points: !!opencv-nd-matrix\n"
		"  sizes: [ 2, 1 ]\n  dt: \"2f\"\n  data: [ 1., 2., 3., 4. ]\n"
		"image_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n  "
		"rows: 3\n  cols: 3\n  dt: d\n  data: [ 810., 0., 320.,\n        0., 805., 240.,\n     0., "
		"0., 1. ]\n# a comment\ndistortion_coefficients: !!opencv-matrix\n  rows: 1\n  cols: 5\n  "
		"dt: d\n  data: [ -0.2, 0.03, 0., 0., 0. ]\n");
	// The data's continuation lines sit at any indentation inside '[ ]';
	// the other keys OpenCV's calibration sample writes are ignored.
	const CameraModel c = CameraModel::load(p);
	EXPECT_DOUBLE_EQ(c.fx(), 810);
	EXPECT_DOUBLE_EQ(c.fy(), 805);
	EXPECT_DOUBLE_EQ(c.cy(), 240);
	EXPECT_EQ(c.width(), 640);
	EXPECT_TRUE(c.hasDistortion());
	EXPECT_DOUBLE_EQ(c.params().dist[0], -0.2);
}

TEST(Camera, BadFilesGiveClearErrors)
{
	EXPECT_THROW(CameraModel::load("/nonexistent/cam.ini"), std::runtime_error);
	const auto nosec = writeTemp("cam_nosec.ini", "[OTHER]\nfx = 1\n");
	try
	{
		CameraModel::load(nosec);
		FAIL();
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("CAMERA_PARAMS"), std::string::npos);
	}
	const auto nofx = writeTemp(
		"cam_nofx.ini", "[CAMERA_PARAMS]\nresolution = [640 480]\ncx = 1\ncy = 1\nfy = 800\n");
	EXPECT_THROW(CameraModel::load(nofx), std::runtime_error);
	const auto negf = writeTemp(
		"cam_negf.ini",
		"[CAMERA_PARAMS]\nresolution = [640 480]\ncx = 319\ncy = 239\nfx = -800\nfy = 800\n");
	EXPECT_THROW(CameraModel::load(negf), std::runtime_error);
	const auto yamlmissing = writeTemp("cam_bad.yaml", "image_width: 640\n");
	EXPECT_THROW(CameraModel::load(yamlmissing), std::runtime_error);
}

TEST(Camera, IniTextRoundTrip)
{
	const CameraModel cam = distortedCamera();
	const auto p = writeTemp("cam_rt.ini", cam.toIniText());
	const CameraModel back = CameraModel::load(p);
	EXPECT_NEAR(back.fx(), cam.fx(), 1e-4);
	EXPECT_NEAR(back.params().dist[0], cam.params().dist[0], 1e-9);
	EXPECT_TRUE(back.hasDistortion());
	// A camera without distortion (codemark-render's camera.ini) too.
	const CameraModel plain = CameraModel::paperDefault();
	const CameraModel plain_back = CameraModel::load(writeTemp("cam_rt0.ini", plain.toIniText()));
	EXPECT_NEAR(plain_back.cx(), plain.cx(), 1e-9);
	EXPECT_FALSE(plain_back.hasDistortion());
}
