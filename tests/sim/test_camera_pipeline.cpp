// The camera pipeline's stages, each on its own, and its options: presets,
// per-frame draws, overrides and bad input.
#include <codemark/sim/camera_pipeline.h>
#include <codemark/sim/render.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <set>

using namespace codemark;
using namespace codemark::sim;

namespace
{
RenderOptions loadRender(const std::string& text)
{
	mrpt::config::CConfigFileMemory c;
	c.setContent("[render]\n" + text);
	RenderOptions o;
	o.loadFromConfigFile(c, "render");
	return o;
}

std::string loadError(const std::string& text)
{
	try
	{
		loadRender(text);
	}
	catch (const std::exception& e)
	{
		return e.what();
	}
	return "";
}

/** Intensity-weighted centroid of plane \a channel of \a img. */
cv::Point2d centroid(const cv::Mat& img, int channel)
{
	double s = 0, su = 0, sv = 0;
	for (int v = 0; v < img.rows; ++v)
		for (int u = 0; u < img.cols; ++u)
		{
			const double w = img.at<cv::Vec3f>(v, u)[channel];
			s += w;
			su += w * u;
			sv += w * v;
		}
	return {su / s, sv / s};
}
}  // namespace

TEST(CameraPipeline, TransferCurvesRoundTrip)
{
	// The sRGB curve's defining points (IEC 61966-2-1).
	EXPECT_NEAR(encodeTransfer(0.0031308, Transfer::SRGB), 0.04045, 1e-5);
	EXPECT_NEAR(encodeTransfer(0.5, Transfer::SRGB), 0.735357, 1e-5);
	EXPECT_NEAR(encodeTransfer(0.18, Transfer::Gamma, 2.0), std::sqrt(0.18), 1e-12);
	for (Transfer t : {Transfer::Linear, Transfer::SRGB, Transfer::Gamma, Transfer::Filmic})
	{
		double prev = -1;
		for (int i = 0; i <= 1000; ++i)
		{
			const double x = i / 1000.0;
			const double y = encodeTransfer(x, t, 2.4, 0.35);
			EXPECT_GT(y, prev) << transferName(t) << " is not monotone at " << x;
			prev = y;
			EXPECT_NEAR(decodeTransfer(y, t, 2.4, 0.35), x, 1e-9) << transferName(t) << " " << x;
		}
		EXPECT_NEAR(encodeTransfer(0, t, 2.4, 0.35), 0, 1e-12);
		EXPECT_NEAR(encodeTransfer(1, t, 2.4, 0.35), 1, 1e-12);
	}
	// The filmic S-curve darkens the shadows and lifts the highlights of sRGB.
	EXPECT_LT(
		encodeTransfer(0.03, Transfer::Filmic, 2.2, 0.25), encodeTransfer(0.03, Transfer::SRGB));
	EXPECT_GT(
		encodeTransfer(0.5, Transfer::Filmic, 2.2, 0.25), encodeTransfer(0.5, Transfer::SRGB));
	// The image stage applies the same curve.
	cv::Mat img(1, 3, CV_32FC3, cv::Scalar(0.2 * 255, 0.5 * 255, 0.9 * 255));
	applyTransfer(img, Transfer::SRGB, 2.2, 0.25);
	EXPECT_NEAR(img.at<cv::Vec3f>(0, 1)[1], 255 * encodeTransfer(0.5, Transfer::SRGB), 1e-3);
	EXPECT_NEAR(img.at<cv::Vec3f>(0, 1)[2], 255 * encodeTransfer(0.9, Transfer::SRGB), 1e-3);
}

TEST(CameraPipeline, MosaicPatternPerLayout)
{
	// B = 10, G = 20, R = 30 everywhere: each raw pixel holds its filter's colour.
	const cv::Mat flat(8, 8, CV_32FC3, cv::Scalar(10, 20, 30));
	for (BayerLayout l :
		 {BayerLayout::RGGB, BayerLayout::BGGR, BayerLayout::GRBG, BayerLayout::GBRG})
	{
		const std::string name = bayerName(l);
		const cv::Mat raw = mosaic(flat, l);
		for (int v = 0; v < 4; ++v)
			for (int u = 0; u < 4; ++u)
			{
				const char c = name[(v % 2) * 2 + (u % 2)];
				const float want = c == 'R' ? 30.f : (c == 'G' ? 20.f : 10.f);
				EXPECT_EQ(raw.at<float>(v, u), want) << name << " at " << u << "," << v;
			}
		// Every demosaicing gives the flat colour back away from the border.
		for (Demosaic d : {Demosaic::Bilinear, Demosaic::VNG, Demosaic::EdgeAware})
		{
			const cv::Mat rgb =
				demosaicRaw(mosaic(cv::Mat(16, 16, CV_32FC3, cv::Scalar(60, 120, 200)), l), l, d);
			const cv::Vec3f p = rgb.at<cv::Vec3f>(8, 7);
			EXPECT_NEAR(p[0], 60, 1.0) << name << " " << demosaicName(d);
			EXPECT_NEAR(p[1], 120, 1.0) << name << " " << demosaicName(d);
			EXPECT_NEAR(p[2], 200, 1.0) << name << " " << demosaicName(d);
		}
	}
}

// Demosaicing keeps the scene in place: a horizontal and a vertical edge
// cross G's half level where the full-colour image has them, within a
// tenth of a pixel, for every layout and method. (OpenCV's VNG moves its
// output by two rows up to 4.11; demosaicRaw() undoes that.)
TEST(CameraPipeline, EveryDemosaicingKeepsTheImageInPlace)
{
	// Where G crosses 120 along row or column 20 of \a img [px].
	const auto crossing = [](const cv::Mat& img, bool down)
	{
		for (int i = 1; i < 40; ++i)
		{
			const float a = down ? img.at<cv::Vec3f>(i - 1, 20)[1]
								 : img.at<cv::Vec3f>(20, i - 1)[1],
						b = down ? img.at<cv::Vec3f>(i, 20)[1] : img.at<cv::Vec3f>(20, i)[1];
			if (a < 120 && b >= 120) return i - 1 + (120 - a) / (b - a);
		}
		return -1.0f;
	};
	for (const bool down : {true, false})
	{
		cv::Mat scene(40, 40, CV_32FC3, cv::Scalar(40, 40, 40));
		(down ? scene.rowRange(20, 40) : scene.colRange(20, 40)).setTo(cv::Scalar(200, 200, 200));
		cv::GaussianBlur(scene, scene, cv::Size(0, 0), 1.0);
		const float truth = crossing(scene, down);
		ASSERT_NEAR(truth, 19.5, 0.05);
		for (BayerLayout l :
			 {BayerLayout::RGGB, BayerLayout::BGGR, BayerLayout::GRBG, BayerLayout::GBRG})
			for (Demosaic d : {Demosaic::Bilinear, Demosaic::VNG, Demosaic::EdgeAware})
			{
				const cv::Mat rgb = demosaicRaw(mosaic(scene, l), l, d);
				EXPECT_NEAR(crossing(rgb, down), truth, 0.1)
					<< bayerName(l) << " " << demosaicName(d) << (down ? " rows" : " columns");
			}
	}
}

// The 1-D camera profile: in linear light without sharpening each pixel is
// the blurred print averaged over the pixel (here against a numeric
// average), a level above full scale clips, and the curve encodes.
TEST(CameraPipeline, CameraProfileIsThePixelAveragedBlurredPrint)
{
	PrintProfile print;
	print.edges = {6.3, 11.8};
	print.levels = {{0.6, 0.6, 0.6}, {0.02, 0.02, 0.02}, {0.1, 1.4, 0.2}};
	const double sigma = 0.7;
	const auto linear = cameraProfile(print, 20, sigma, 0, Transfer::Linear);
	const auto srgb = cameraProfile(print, 20, sigma, 0, Transfer::SRGB);
	for (int i = 0; i < 20; ++i)
		for (int c = 0; c < 3; ++c)
		{
			double sum = 0;
			constexpr int kSub = 2000;
			for (int k = 0; k < kSub; ++k)
			{
				const double x = i - 0.5 + (k + 0.5) / kSub;
				double v = print.levels[0][c];
				for (size_t e = 0; e < 2; ++e)
					v += (print.levels[e + 1][c] - print.levels[e][c]) * 0.5 *
						 std::erfc(-(x - print.edges[e]) / (std::sqrt(2.0) * sigma));
				sum += v;
			}
			const double expected = std::min(1.0, sum / kSub);
			// Within the 8-bit rounding.
			EXPECT_NEAR(linear[i][c], 255 * expected, 0.5 + 1e-6) << i << " " << c;
			EXPECT_NEAR(srgb[i][c], 255 * encodeTransfer(expected, Transfer::SRGB), 0.5 + 1e-6)
				<< i << " " << c;
		}
	EXPECT_EQ(linear[19][1], 255);	// G at 1.4 clips
	EXPECT_THROW(cameraProfile(print, 0, sigma, 0, Transfer::Linear), std::invalid_argument);
}

TEST(CameraPipeline, DefocusKernelIsADiscSummingToOne)
{
	for (double r : {0.3, 0.8, 1.5, 3.0})
	{
		const cv::Mat k = defocusKernel(r);
		EXPECT_NEAR(cv::sum(k)[0], 1.0, 1e-6) << r;
		const int c = k.rows / 2;
		for (int y = 0; y < k.rows; ++y)
			for (int x = 0; x < k.cols; ++x)
			{
				EXPECT_NEAR(k.at<float>(y, x), k.at<float>(k.rows - 1 - y, x), 1e-7);
				EXPECT_NEAR(k.at<float>(y, x), k.at<float>(x, y), 1e-7);
			}
		// A pixel wholly inside the disc weighs 1 / (pi r^2).
		if (r >= 0.8)
		{
			EXPECT_NEAR(k.at<float>(c, c) * M_PI * r * r, 1.0, 0.02) << r;
		}
		EXPECT_EQ(k.at<float>(0, 0), 0.f) << r;	 // the kernel's corners lie outside
	}
	EXPECT_EQ(defocusKernel(0).total(), 1u);
}

TEST(CameraPipeline, ChromaticAberrationShiftsADotByTheSetAmount)
{
	// A Gaussian dot (sigma 2 px) at 90% of the corner radius, towards the
	// bottom-right corner; R moves outwards by 0.7 * 0.9 px, B inwards by
	// 0.4 * 0.9 px, G stays.
	const int W = 640, H = 480;
	const double cx = 319.5, cy = 239.5;
	const double rc = std::hypot(W - 0.5 - cx, H - 0.5 - cy);
	const cv::Point2d dir((W - 0.5 - cx) / rc, (H - 0.5 - cy) / rc);
	const cv::Point2d dot(cx + 0.9 * rc * dir.x, cy + 0.9 * rc * dir.y);
	cv::Mat img(H, W, CV_32FC3, cv::Scalar(0, 0, 0));
	for (int v = 0; v < H; ++v)
		for (int u = 0; u < W; ++u)
		{
			const double d2 = std::pow(u - dot.x, 2) + std::pow(v - dot.y, 2);
			if (d2 < 144) img.at<cv::Vec3f>(v, u) = cv::Vec3f::all(float(200 * std::exp(-d2 / 8)));
		}
	applyChromaticAberration(img, 0.7, -0.4, cx, cy);
	const cv::Point2d g = centroid(img, 1), r = centroid(img, 2), b = centroid(img, 0);
	EXPECT_NEAR(g.x, dot.x, 1e-3);
	EXPECT_NEAR(g.y, dot.y, 1e-3);
	EXPECT_NEAR((r - g).dot(dir), 0.7 * 0.9, 0.01);
	EXPECT_NEAR((b - g).dot(dir), -0.4 * 0.9, 0.01);
	EXPECT_NEAR((r - g).cross(dir), 0, 0.01);
}

TEST(CameraPipeline, VignettingFollowsTheSquaredRadius)
{
	cv::Mat img(101, 201, CV_32FC3, cv::Scalar(100, 100, 100));
	applyVignetting(img, 0.3, 100, 50);
	EXPECT_NEAR(img.at<cv::Vec3f>(50, 100)[1], 100, 1e-4);
	const double rc = std::hypot(100.5, 50.5);
	EXPECT_NEAR(
		img.at<cv::Vec3f>(0, 0)[1], 100 * (1 - 0.3 * std::pow(std::hypot(100, 50) / rc, 2)), 1e-3);
	EXPECT_NEAR(img.at<cv::Vec3f>(50, 0)[1], 100 * (1 - 0.3 * std::pow(100 / rc, 2)), 1e-3);
}

TEST(CameraPipeline, SensorNoiseVarianceFollowsTheModel)
{
	// Var in grey levels^2 = (e + read^2) / (e per level)^2, e = x * FW / 255.
	for (double level : {20.0, 128.0})
		for (double fw : {5000.0, 20000.0})
		{
			const double read = 8;
			cv::Mat img(256, 256, CV_32FC3, cv::Scalar::all(level));
			addSensorNoise(img, fw, read, 11);
			cv::Scalar mean, sd;
			cv::meanStdDev(img.reshape(1), mean, sd);
			const double epl = fw / 255, e = level * epl;
			const double want = std::sqrt(e + read * read) / epl;
			EXPECT_NEAR(sd[0], want, 0.02 * want) << level << " " << fw;
			EXPECT_NEAR(mean[0], level, 0.02) << level << " " << fw;
		}
	// Saturation: nothing beyond full scale.
	cv::Mat bright(64, 64, CV_32FC3, cv::Scalar::all(300));
	addSensorNoise(bright, 10000, 5, 1);
	double lo, hi;
	cv::minMaxLoc(bright.reshape(1), &lo, &hi);
	EXPECT_LE(hi, 255);
}

TEST(CameraPipeline, UnsharpMaskSharpensAnEdgeAndKeepsFlatAreas)
{
	cv::Mat img(20, 40, CV_32FC3, cv::Scalar::all(50));
	img(cv::Rect(20, 0, 20, 20)).setTo(cv::Scalar::all(150));
	unsharpMask(img, 1.0, 0.8);
	EXPECT_NEAR(img.at<cv::Vec3f>(10, 5)[1], 50, 1e-3);
	EXPECT_NEAR(img.at<cv::Vec3f>(10, 35)[1], 150, 1e-3);
	EXPECT_LT(img.at<cv::Vec3f>(10, 19)[1], 45);  // undershoot before the edge
	EXPECT_GT(img.at<cv::Vec3f>(10, 20)[1], 155);  // overshoot after it
}

TEST(CameraPipeline, JpegIsFourTwoZero)
{
	cv::Mat img(32, 32, CV_8UC3);
	cv::randu(img, 0, 255);
	std::vector<uchar> buf;
	// The same call as jpegRoundTrip(): read the sampling factors from SOF0.
	cv::imencode(".jpg", img, buf, {cv::IMWRITE_JPEG_QUALITY, 85});
	size_t i = 0;
	while (i + 1 < buf.size() && !(buf[i] == 0xFF && (buf[i + 1] == 0xC0 || buf[i + 1] == 0xC2)))
		++i;
	ASSERT_LT(i + 17, buf.size());
	ASSERT_EQ(buf[i + 9], 3);  // three components
	EXPECT_EQ(buf[i + 11], 0x22);  // Y: 2 x 2
	EXPECT_EQ(buf[i + 14], 0x11);  // Cb: 1 x 1
	EXPECT_EQ(buf[i + 17], 0x11);  // Cr: 1 x 1
	const cv::Mat back = jpegRoundTrip(img, 85);
	EXPECT_EQ(back.size(), img.size());
	EXPECT_EQ(back.type(), CV_8UC3);
}

TEST(CameraPipeline, ChromaSubsamplingKeepsLumaAndAveragesColour)
{
	// Stripes of two colours one pixel wide, along columns (vertical
	// stripes) and along rows (horizontal ones); saturations low enough that
	// no averaged colour leaves the gamut.
	const cv::Vec3b a(100, 120, 160), b(150, 140, 95);
	cv::Mat cols(16, 16, CV_8UC3), rows(16, 16, CV_8UC3);
	for (int v = 0; v < 16; ++v)
		for (int u = 0; u < 16; ++u)
		{
			cols.at<cv::Vec3b>(v, u) = u % 2 ? b : a;
			rows.at<cv::Vec3b>(v, u) = v % 2 ? b : a;
		}
	const auto ycc = [](const cv::Mat& bgr)
	{
		cv::Mat f, out;
		bgr.convertTo(f, CV_32FC3);
		cv::cvtColor(f, out, cv::COLOR_BGR2YCrCb);
		return out;
	};
	const cv::Mat cols_ycc = ycc(cols);
	const cv::Vec3f mean = 0.5f * (cols_ycc.at<cv::Vec3f>(0, 0) + cols_ycc.at<cv::Vec3f>(0, 1));
	// Interior pixels: luma kept, chroma the stripes' mean where the
	// subsampling spans them, kept where it does not.
	const auto check = [&](const cv::Mat& in, ChromaSubsampling s, bool averaged)
	{
		const cv::Mat x = ycc(in), y = ycc(subsampleChroma(in, s));
		for (int v = 2; v < 14; ++v)
			for (int u = 2; u < 14; ++u)
			{
				const cv::Vec3f p = x.at<cv::Vec3f>(v, u), q = y.at<cv::Vec3f>(v, u);
				EXPECT_NEAR(q[0], p[0], 1.5) << chromaName(s) << " at " << u << "," << v;
				for (int c = 1; c < 3; ++c)
					EXPECT_NEAR(q[c], averaged ? mean[c] : p[c], 2.0)
						<< chromaName(s) << " plane " << c << " at " << u << "," << v;
			}
	};
	check(cols, ChromaSubsampling::S422, true);
	check(rows, ChromaSubsampling::S422, false);
	check(cols, ChromaSubsampling::S420, true);
	check(rows, ChromaSubsampling::S420, true);
	EXPECT_EQ(cv::norm(subsampleChroma(cols, ChromaSubsampling::None), cols, cv::NORM_INF), 0);
	// The stripes' colours differ by far more than the tolerance.
	EXPECT_GT(std::abs(cols_ycc.at<cv::Vec3f>(0, 0)[1] - mean[1]), 10);
}

TEST(CameraPipeline, ChromaSubsamplingKey)
{
	const RenderOptions o = loadRender("chroma_subsampling = 420\n");
	EXPECT_EQ(o.chroma_subsampling, ChromaSubsampling::S420);
	EXPECT_TRUE(o.hasCameraStages());
	EXPECT_EQ(loadRender("preset = webcam\n").chroma_subsampling, ChromaSubsampling::None);
	const RenderOptions any = loadRender("chroma_subsampling = any\n");
	mrpt::config::CConfigFileMemory c;
	any.saveToConfigFile(c, "render");
	RenderOptions back;
	back.loadFromConfigFile(c, "render");
	std::set<ChromaSubsampling> seen;
	for (uint64_t s = 0; s < 30; ++s)
	{
		seen.insert(any.drawn(s).chroma_subsampling);
		EXPECT_EQ(any.drawn(s).chroma_subsampling, back.drawn(s).chroma_subsampling);
	}
	EXPECT_EQ(seen.size(), 3u);
	EXPECT_NE(
		loadError("chroma_subsampling = 411\n").find("chroma_subsampling"), std::string::npos);
}

TEST(CameraPipeline, DefaultsLeaveTheLinearImageAsItIs)
{
	cv::Mat img(10, 10, CV_32FC3);
	cv::randu(img, 0, 255);
	const cv::Mat copy = img.clone();
	const cv::Mat out = cameraImage(img, RenderOptions(), 4.5, 4.5, 1);
	cv::Mat want;
	copy.convertTo(want, CV_8UC3);
	EXPECT_EQ(cv::norm(out, want, cv::NORM_INF), 0);
	EXPECT_FALSE(RenderOptions().hasCameraStages());
}

TEST(CameraPipeline, PresetsLoadAndDrawPerFrame)
{
	for (const auto& name : RenderOptions::presetNames())
	{
		const RenderOptions o = loadRender("preset = " + name + "\n");
		EXPECT_EQ(o.preset, name);
		EXPECT_TRUE(o.hasCameraStages()) << name;
		EXPECT_NO_THROW(o.drawn(3).validate()) << name;
	}
	const RenderOptions web = loadRender("preset = webcam\n");
	EXPECT_EQ(web.bayer, BayerLayout::RGGB);
	EXPECT_EQ(web.transfer, Transfer::SRGB);
	EXPECT_EQ(web.jpeg_quality, 85);
	EXPECT_DOUBLE_EQ(web.blur_sigma_px, 0.6);
	EXPECT_DOUBLE_EQ(web.unsharp_amount, 0.5);
	// A stage key in the section overrides the preset, whatever the order.
	const RenderOptions over = loadRender("jpeg_quality = 95\npreset = webcam\ntransfer = gamma\n");
	EXPECT_EQ(over.jpeg_quality, 95);
	EXPECT_EQ(over.transfer, Transfer::Gamma);
	EXPECT_EQ(over.bayer, BayerLayout::RGGB);

	// family: deterministic per seed, different across seeds, inside its ranges.
	const RenderOptions fam = loadRender("preset = family\n");
	EXPECT_FALSE(fam.range_draws.empty());
	const RenderOptions a = fam.drawn(5), b = fam.drawn(5);
	EXPECT_TRUE(a.range_draws.empty() && a.choice_draws.empty());
	EXPECT_EQ(a.blur_sigma_px, b.blur_sigma_px);
	EXPECT_EQ(a.jpeg_quality, b.jpeg_quality);
	int differ = 0, jpeg_min = 100, jpeg_max = 0;
	std::set<int> layouts;
	for (uint64_t s = 0; s < 200; ++s)
	{
		const RenderOptions d = fam.drawn(s);
		differ += d.blur_sigma_px != a.blur_sigma_px;
		EXPECT_GE(d.blur_sigma_px, 0);
		EXPECT_LE(d.blur_sigma_px, 1.2);
		EXPECT_GE(d.wb_red, 0.75);
		EXPECT_LE(d.wb_red, 1.3);
		jpeg_min = std::min(jpeg_min, d.jpeg_quality);
		jpeg_max = std::max(jpeg_max, d.jpeg_quality);
		layouts.insert(static_cast<int>(d.bayer));
		EXPECT_NE(d.bayer, BayerLayout::None);
	}
	EXPECT_GT(differ, 190);
	EXPECT_GE(jpeg_min, 60);
	EXPECT_LE(jpeg_max, 95);
	EXPECT_LT(jpeg_min, 65);
	EXPECT_GT(jpeg_max, 90);
	EXPECT_EQ(layouts.size(), 4u);
	// One value for a drawn key ends its draw.
	const RenderOptions fixed = loadRender("preset = family\nblur_sigma_px = 0.4\nbayer = GBRG\n");
	for (uint64_t s = 0; s < 20; ++s)
	{
		EXPECT_EQ(fixed.drawn(s).blur_sigma_px, 0.4);
		EXPECT_EQ(fixed.drawn(s).bayer, BayerLayout::GBRG);
	}
}

TEST(CameraPipeline, RangesAndChoicesRoundTripThroughAnIni)
{
	const RenderOptions o =
		loadRender("preset = phone\nexposure = 0.8 1.2\nbayer = RGGB GRBG\nnoise_sigma = 1 3\n");
	mrpt::config::CConfigFileMemory c;
	o.saveToConfigFile(c, "render");
	RenderOptions back;
	back.loadFromConfigFile(c, "render");
	EXPECT_EQ(back.preset, "phone");
	ASSERT_EQ(back.range_draws.size(), o.range_draws.size());
	ASSERT_EQ(back.choice_draws.size(), o.choice_draws.size());
	for (uint64_t s = 0; s < 10; ++s)
	{
		const RenderOptions x = o.drawn(s), y = back.drawn(s);
		EXPECT_DOUBLE_EQ(x.exposure, y.exposure);
		EXPECT_DOUBLE_EQ(x.noise_sigma, y.noise_sigma);
		EXPECT_EQ(x.bayer, y.bayer);
		EXPECT_EQ(x.transfer, Transfer::Filmic);
		EXPECT_EQ(x.demosaic, Demosaic::EdgeAware);
	}
}

TEST(CameraPipeline, BadKeysNameTheKey)
{
	EXPECT_NE(loadError("preset = dslr\n").find("preset"), std::string::npos);
	EXPECT_NE(loadError("preset = dslr\n").find("webcam"), std::string::npos);
	EXPECT_NE(loadError("bayer = RGBG\n").find("bayer"), std::string::npos);
	EXPECT_NE(loadError("demosaic = ahd\n").find("demosaic"), std::string::npos);
	EXPECT_NE(loadError("transfer = log\n").find("transfer"), std::string::npos);
	EXPECT_NE(loadError("vignetting = 0.95\n").find("vignetting"), std::string::npos);
	EXPECT_NE(loadError("vignetting = 0.95\n").find("out of range"), std::string::npos);
	EXPECT_NE(loadError("gamma = 0.5\n").find("gamma"), std::string::npos);
	EXPECT_NE(loadError("jpeg_quality = 60 101\n").find("jpeg_quality"), std::string::npos);
	EXPECT_NE(loadError("jpeg_quality = 80.5\n").find("whole"), std::string::npos);
	EXPECT_NE(loadError("exposure = 1.5 0.5\n").find("lo <= hi"), std::string::npos);
	EXPECT_NE(loadError("blur_sigma_px = 0.5px\n").find("blur_sigma_px"), std::string::npos);
	EXPECT_NE(loadError("wb_red = 1 1.1 1.2\n").find("wb_red"), std::string::npos);
	EXPECT_EQ(loadError("preset = family\nwb_red = 1.1 ; a comment\n"), "");
}

TEST(CameraPipeline, RenderedFramesThroughAPreset)
{
	// The renderer applies the pipeline: sRGB lifts the printed black (25 in
	// linear light) to about 89 and keeps the landmark detectable in shape.
	Scene scene = singleLandmarkScene();
	scene.world_T_camera = levelCameraLookingAt(scene.map.landmarks[0], 1.0, 0.0);
	RenderOptions lin;
	RenderOptions srgb;
	srgb.transfer = Transfer::SRGB;
	const Render a = render(scene, lin, 1), b = render(scene, srgb, 1);
	const auto& c = a.truth[0].corners_px;
	// A pixel on the frame, halfway between the inner and outer edge, left side.
	const int u = static_cast<int>(std::lround(c[0].x() - 0.5 * (c[1].x() - c[0].x()) / 8.0));
	const int v = static_cast<int>(std::lround(0.5 * (c[0].y() + c[3].y())));
	EXPECT_NEAR(a.image.at<cv::Vec3b>(v, u)[1], 25, 1);
	EXPECT_NEAR(
		b.image.at<cv::Vec3b>(v, u)[1], 255 * encodeTransfer(25 / 255.0, Transfer::SRGB), 1);
	// family draws differ from frame to frame.
	RenderOptions fam;
	fam.applyPreset("family");
	EXPECT_GT(cv::norm(render(scene, fam, 1).image, render(scene, fam, 2).image, cv::NORM_L1), 0);
	EXPECT_EQ(cv::norm(render(scene, fam, 3).image, render(scene, fam, 3).image, cv::NORM_L1), 0);
}
