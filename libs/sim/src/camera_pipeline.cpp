#include <codemark/sim/camera_pipeline.h>
#include <codemark/sim/render.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "background.h"

namespace codemark::sim
{
namespace
{
std::string lower(std::string s)
{
	std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
	return s;
}

template <typename E, size_t N>
E fromName(
	const std::string& name, const std::string& key, const std::array<E, N>& values,
	const char* (*nameOf)(E))
{
	std::string accepted;
	for (E v : values)
	{
		if (lower(name) == lower(nameOf(v))) return v;
		accepted += (accepted.empty() ? "" : ", ") + std::string(nameOf(v));
	}
	throw std::invalid_argument(
		"render option '" + key + "' must be one of " + accepted + ", got '" + name + "'");
}

/** The farthest distance from (cx, cy) to an image corner [px]. */
double cornerRadius(const cv::Mat& img, double cx, double cy)
{
	double r = 0;
	for (double u : {-0.5, img.cols - 0.5})
		for (double v : {-0.5, img.rows - 0.5}) r = std::max(r, std::hypot(u - cx, v - cy));
	return r;
}

/** Channel (0 B, 1 G, 2 R) that the filter at pixel (u, v) passes. */
int filterChannel(BayerLayout layout, int u, int v)
{
	// The 2 x 2 block row by row; 'R' = 2, 'G' = 1, 'B' = 0.
	const char* block = bayerName(layout);
	const char c = block[(v & 1) * 2 + (u & 1)];
	return c == 'R' ? 2 : (c == 'G' ? 1 : 0);
}

/** OpenCV's conversion code for \a layout. OpenCV names a pattern by the
 * second row's second and third pixels: RGGB is its "BG". */
int bayerCode(BayerLayout layout, Demosaic method)
{
	static const int bilinear[] = {
		cv::COLOR_BayerBG2BGR, cv::COLOR_BayerRG2BGR, cv::COLOR_BayerGB2BGR, cv::COLOR_BayerGR2BGR};
	static const int vng[] = {
		cv::COLOR_BayerBG2BGR_VNG, cv::COLOR_BayerRG2BGR_VNG, cv::COLOR_BayerGB2BGR_VNG,
		cv::COLOR_BayerGR2BGR_VNG};
	static const int ea[] = {
		cv::COLOR_BayerBG2BGR_EA, cv::COLOR_BayerRG2BGR_EA, cv::COLOR_BayerGB2BGR_EA,
		cv::COLOR_BayerGR2BGR_EA};
	const int i = static_cast<int>(layout) - 1;
	switch (method)
	{
		case Demosaic::VNG:
			return vng[i];
		case Demosaic::EdgeAware:
			return ea[i];
		case Demosaic::Bilinear:
			break;
	}
	return bilinear[i];
}

constexpr double kTwoPi = 2 * M_PI;

double srgbEncode(double x)
{
	return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055;
}
double srgbDecode(double y)
{
	return y <= 0.04045 ? y / 12.92 : std::pow((y + 0.055) / 1.055, 2.4);
}
double sCurve(double y, double k) { return y - k * std::sin(kTwoPi * y) / kTwoPi; }
double sCurveInverse(double z, double k)
{
	// s' = 1 - k cos(2 pi y) >= 1 - k > 0: Newton converges from y = z.
	double y = z;
	for (int i = 0; i < 30; ++i)
	{
		const double step = (sCurve(y, k) - z) / (1 - k * std::cos(kTwoPi * y));
		y -= step;
		if (std::abs(step) < 1e-14) break;
	}
	return std::clamp(y, 0.0, 1.0);
}
}  // namespace

const char* bayerName(BayerLayout b)
{
	switch (b)
	{
		case BayerLayout::RGGB:
			return "RGGB";
		case BayerLayout::BGGR:
			return "BGGR";
		case BayerLayout::GRBG:
			return "GRBG";
		case BayerLayout::GBRG:
			return "GBRG";
		case BayerLayout::None:
			break;
	}
	return "none";
}

const char* demosaicName(Demosaic d)
{
	switch (d)
	{
		case Demosaic::VNG:
			return "vng";
		case Demosaic::EdgeAware:
			return "edge-aware";
		case Demosaic::Bilinear:
			break;
	}
	return "bilinear";
}

const char* transferName(Transfer t)
{
	switch (t)
	{
		case Transfer::SRGB:
			return "srgb";
		case Transfer::Gamma:
			return "gamma";
		case Transfer::Filmic:
			return "filmic";
		case Transfer::Linear:
			break;
	}
	return "linear";
}

const char* chromaName(ChromaSubsampling c)
{
	switch (c)
	{
		case ChromaSubsampling::S422:
			return "422";
		case ChromaSubsampling::S420:
			return "420";
		case ChromaSubsampling::None:
			break;
	}
	return "none";
}

BayerLayout bayerFromName(const std::string& name, const std::string& key)
{
	return fromName<BayerLayout, 5>(
		name, key,
		{BayerLayout::None, BayerLayout::RGGB, BayerLayout::BGGR, BayerLayout::GRBG,
		 BayerLayout::GBRG},
		bayerName);
}

Demosaic demosaicFromName(const std::string& name, const std::string& key)
{
	return fromName<Demosaic, 3>(
		name, key, {Demosaic::Bilinear, Demosaic::VNG, Demosaic::EdgeAware}, demosaicName);
}

Transfer transferFromName(const std::string& name, const std::string& key)
{
	return fromName<Transfer, 4>(
		name, key, {Transfer::Linear, Transfer::SRGB, Transfer::Gamma, Transfer::Filmic},
		transferName);
}

ChromaSubsampling chromaFromName(const std::string& name, const std::string& key)
{
	return fromName<ChromaSubsampling, 3>(
		name, key, {ChromaSubsampling::None, ChromaSubsampling::S422, ChromaSubsampling::S420},
		chromaName);
}

double encodeTransfer(double x, Transfer t, double gamma, double filmic_strength)
{
	x = std::clamp(x, 0.0, 1.0);
	switch (t)
	{
		case Transfer::SRGB:
			return srgbEncode(x);
		case Transfer::Gamma:
			return std::pow(x, 1 / gamma);
		case Transfer::Filmic:
			return sCurve(srgbEncode(x), filmic_strength);
		case Transfer::Linear:
			break;
	}
	return x;
}

double decodeTransfer(double y, Transfer t, double gamma, double filmic_strength)
{
	y = std::clamp(y, 0.0, 1.0);
	switch (t)
	{
		case Transfer::SRGB:
			return srgbDecode(y);
		case Transfer::Gamma:
			return std::pow(y, gamma);
		case Transfer::Filmic:
			return srgbDecode(sCurveInverse(y, filmic_strength));
		case Transfer::Linear:
			break;
	}
	return y;
}

void applyMotionBlur(cv::Mat& img, double length_px, double angle_rad)
{
	if (!(length_px > 0)) return;
	const int half = static_cast<int>(std::ceil(0.5 * length_px)) + 1;
	cv::Mat k = cv::Mat::zeros(2 * half + 1, 2 * half + 1, CV_32F);
	const int steps = std::max(16, static_cast<int>(std::ceil(8 * length_px)));
	const double ca = std::cos(angle_rad), sa = std::sin(angle_rad);
	for (int i = 0; i < steps; ++i)
	{
		const double t = length_px * ((i + 0.5) / steps - 0.5);
		const double x = half + t * ca, y = half - t * sa;
		const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
		const double fx = x - x0, fy = y - y0;
		k.at<float>(y0, x0) += float((1 - fx) * (1 - fy));
		k.at<float>(y0, x0 + 1) += float(fx * (1 - fy));
		k.at<float>(y0 + 1, x0) += float((1 - fx) * fy);
		k.at<float>(y0 + 1, x0 + 1) += float(fx * fy);
	}
	k /= cv::sum(k)[0];
	cv::filter2D(img, img, -1, k, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
}

cv::Mat defocusKernel(double radius_px)
{
	if (!(radius_px > 0)) return cv::Mat::ones(1, 1, CV_32F);
	const int half = static_cast<int>(std::ceil(radius_px + 0.5));
	const int n = 2 * half + 1;
	constexpr int kSub = 16;
	cv::Mat k(n, n, CV_32F);
	const double r2 = radius_px * radius_px;
	for (int y = 0; y < n; ++y)
		for (int x = 0; x < n; ++x)
		{
			int inside = 0;
			for (int i = 0; i < kSub; ++i)
				for (int j = 0; j < kSub; ++j)
				{
					const double dx = x - half - 0.5 + (j + 0.5) / kSub;
					const double dy = y - half - 0.5 + (i + 0.5) / kSub;
					inside += dx * dx + dy * dy <= r2;
				}
			k.at<float>(y, x) = static_cast<float>(inside);
		}
	// A disc smaller than a sub-sample still covers the centre sample.
	const double sum = cv::sum(k)[0];
	if (sum <= 0) return cv::Mat::ones(1, 1, CV_32F);
	k /= sum;
	return k;
}

void applyChromaticAberration(cv::Mat& img, double red_px, double blue_px, double cx, double cy)
{
	CV_Assert(img.type() == CV_32FC3);
	if (red_px == 0 && blue_px == 0) return;
	const double rc = cornerRadius(img, cx, cy);
	std::vector<cv::Mat> planes;
	cv::split(img, planes);
	const std::pair<int, double> shifts[] = {{2, red_px}, {0, blue_px}};
	for (const auto& [channel, shift] : shifts)
	{
		if (shift == 0) continue;
		// Content at radius r moves to r (1 + m): sample the source at r / (1 + m).
		const double inv = 1 / (1 + shift / rc);
		cv::Mat mx(img.size(), CV_32F), my(img.size(), CV_32F);
		for (int v = 0; v < img.rows; ++v)
		{
			float* px = mx.ptr<float>(v);
			float* py = my.ptr<float>(v);
			for (int u = 0; u < img.cols; ++u)
			{
				px[u] = static_cast<float>(cx + (u - cx) * inv);
				py[u] = static_cast<float>(cy + (v - cy) * inv);
			}
		}
		cv::Mat out;
		cv::remap(planes[channel], out, mx, my, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
		planes[channel] = out;
	}
	cv::merge(planes, img);
}

void applyVignetting(cv::Mat& img, double amount, double cx, double cy)
{
	CV_Assert(img.type() == CV_32FC3);
	if (amount == 0) return;
	const double rc2 = std::pow(cornerRadius(img, cx, cy), 2);
	for (int v = 0; v < img.rows; ++v)
	{
		cv::Vec3f* p = img.ptr<cv::Vec3f>(v);
		for (int u = 0; u < img.cols; ++u)
		{
			const double r2 = (u - cx) * (u - cx) + (v - cy) * (v - cy);
			p[u] *= static_cast<float>(1 - amount * r2 / rc2);
		}
	}
}

void addSensorNoise(cv::Mat& img, double full_well_e, double read_noise_e, uint64_t seed)
{
	CV_Assert(img.depth() == CV_32F);
	if (!(full_well_e > 0)) return;
	cv::Mat z(img.size(), img.type());
	cv::RNG rng(detail::streamSeed(seed, 6));
	rng.fill(z, cv::RNG::NORMAL, 0.0, 1.0);
	const double e_per_level = full_well_e / 255.0;
	const double read2 = read_noise_e * read_noise_e;
	const int n = img.rows * img.cols * img.channels();
	CV_Assert(img.isContinuous() && z.isContinuous());
	float* p = img.ptr<float>();
	const float* q = z.ptr<float>();
	for (int i = 0; i < n; ++i)
	{
		const double e = std::max(0.0, static_cast<double>(p[i])) * e_per_level;
		const double noisy = e + std::sqrt(e + read2) * q[i];
		p[i] = static_cast<float>(std::clamp(noisy / e_per_level, 0.0, 255.0));
	}
}

cv::Mat mosaic(const cv::Mat& img, BayerLayout layout)
{
	CV_Assert(img.type() == CV_32FC3 && layout != BayerLayout::None);
	cv::Mat raw(img.size(), CV_32F);
	for (int v = 0; v < img.rows; ++v)
	{
		const cv::Vec3f* p = img.ptr<cv::Vec3f>(v);
		float* r = raw.ptr<float>(v);
		for (int u = 0; u < img.cols; ++u) r[u] = p[u][filterChannel(layout, u, v)];
	}
	return raw;
}

namespace
{
/** The rows by which OpenCV's VNG demosaicing moves the image down (its
 * output row v holds the scene's row v + 2 in OpenCV up to 4.11, opencv
 * issue #27225; none once fixed), measured once on a horizontal edge
 * against bilinear demosaicing, so that demosaicRaw() undoes it on any
 * OpenCV. */
int vngRowShift()
{
	static const int shift = []
	{
		cv::Mat raw(32, 16, CV_8U, cv::Scalar(40));
		raw.rowRange(16, 32).setTo(200);
		cv::Mat vng, bilinear;
		cv::demosaicing(raw, vng, cv::COLOR_BayerBG2BGR_VNG);
		cv::demosaicing(raw, bilinear, cv::COLOR_BayerBG2BGR);
		// The edge's row: where G's column 8 first reaches halfway.
		const auto edgeRow = [](const cv::Mat& img)
		{
			for (int v = 0; v < img.rows; ++v)
				if (img.at<cv::Vec3b>(v, 8)[1] >= 120) return v;
			return img.rows;
		};
		return edgeRow(bilinear) - edgeRow(vng);
	}();
	return shift;
}
}  // namespace

cv::Mat demosaicRaw(const cv::Mat& raw, BayerLayout layout, Demosaic method)
{
	CV_Assert(raw.type() == CV_32F && layout != BayerLayout::None);
	// VNG runs on 8-bit raw only (OpenCV); the others on 16 bits, as a raw file holds.
	const bool eight = method == Demosaic::VNG;
	const double scale = eight ? 1.0 : 65535.0 / 255.0;
	cv::Mat q, rgb;
	raw.convertTo(q, eight ? CV_8U : CV_16U, scale);
	cv::demosaicing(q, rgb, bayerCode(layout, method));
	if (const int shift = eight ? vngRowShift() : 0; shift != 0 && rgb.rows > std::abs(shift))
	{
		// Rows back in place; the ones it left uncovered repeat the border.
		const int n = rgb.rows - std::abs(shift);
		cv::Mat moved;
		cv::copyMakeBorder(
			rgb.rowRange(shift > 0 ? 0 : -shift, shift > 0 ? n : rgb.rows), moved,
			shift > 0 ? shift : 0, shift > 0 ? 0 : -shift, 0, 0, cv::BORDER_REPLICATE);
		rgb = moved;
	}
	cv::Mat out;
	rgb.convertTo(out, CV_32FC3, 1 / scale);
	return out;
}

std::vector<std::array<int, 3>> cameraProfile(
	const PrintProfile& print, int n, double sigma, double unsharp_amount, Transfer curve,
	double gamma, double filmic_strength)
{
	if (print.levels.size() != print.edges.size() + 1 || n < 1 || !(sigma > 0))
		throw std::invalid_argument(
			"cameraProfile: levels must outnumber edges by one, n >= 1 and sigma > 0");
	// The blurred print averaged over pixel i: each step's pixel-integrated
	// normal CDF, sum over [i - 1/2, i + 1/2] of Phi((x - e) / sigma).
	const auto integral = [&](double x)
	{
		// Integral of Phi(t / sigma) dt from -inf to x.
		const double z = x / sigma;
		return sigma * (z * 0.5 * std::erfc(-z / std::sqrt(2.0)) +
						std::exp(-0.5 * z * z) / std::sqrt(2 * M_PI));
	};
	cv::Mat lin(1, n, CV_64FC3);
	for (int i = 0; i < n; ++i)
		for (int c = 0; c < 3; ++c)
		{
			double v = print.levels[0][c];
			for (size_t k = 0; k < print.edges.size(); ++k)
				v += (print.levels[k + 1][c] - print.levels[k][c]) *
					 (integral(i + 0.5 - print.edges[k]) - integral(i - 0.5 - print.edges[k]));
			lin.at<cv::Vec3d>(0, i)[c] = std::min(1.0, v);
		}
	if (unsharp_amount > 0)
	{
		cv::Mat blurred;
		cv::GaussianBlur(lin, blurred, cv::Size(0, 0), 1.0, 0, cv::BORDER_REPLICATE);
		lin += unsharp_amount * (lin - blurred);
	}
	std::vector<std::array<int, 3>> out(n);
	for (int i = 0; i < n; ++i)
		for (int c = 0; c < 3; ++c)
			out[i][c] = static_cast<int>(std::lround(
				255 * encodeTransfer(
						  std::clamp(lin.at<cv::Vec3d>(0, i)[c], 0.0, 1.0), curve, gamma,
						  filmic_strength)));
	return out;
}

void applyTransfer(cv::Mat& img, Transfer t, double gamma, double filmic_strength)
{
	CV_Assert(img.depth() == CV_32F);
	if (t == Transfer::Linear) return;
	// A lookup table fine enough that its interpolation error (< 1e-4
	// levels) is far below 8-bit rounding.
	constexpr int kN = 65536;
	std::vector<float> lut(kN + 1);
	for (int i = 0; i <= kN; ++i)
		lut[i] =
			static_cast<float>(255.0 * encodeTransfer(double(i) / kN, t, gamma, filmic_strength));
	CV_Assert(img.isContinuous());
	float* p = img.ptr<float>();
	const size_t n = img.total() * img.channels();
	for (size_t i = 0; i < n; ++i)
	{
		const double x = std::clamp(static_cast<double>(p[i]) / 255.0, 0.0, 1.0) * kN;
		const int j = std::min(static_cast<int>(x), kN - 1);
		const double f = x - j;
		p[i] = static_cast<float>(lut[j] + f * (lut[j + 1] - lut[j]));
	}
}

void unsharpMask(cv::Mat& img, double sigma_px, double amount)
{
	if (amount == 0) return;
	cv::Mat blurred;
	cv::GaussianBlur(img, blurred, cv::Size(0, 0), sigma_px, sigma_px, cv::BORDER_REPLICATE);
	cv::addWeighted(img, 1 + amount, blurred, -amount, 0, img);
}

cv::Mat subsampleChroma(const cv::Mat& bgr8, ChromaSubsampling s)
{
	CV_Assert(bgr8.type() == CV_8UC3);
	if (s == ChromaSubsampling::None) return bgr8.clone();
	// In floating point scaled to [0, 1] (OpenCV's chroma offset for float
	// images is 0.5), each plane rounded to 8 bits as the format stores it.
	const auto round8 = [](cv::Mat& plane)
	{
		cv::Mat q;
		plane.convertTo(q, CV_8U, 255.0);
		q.convertTo(plane, CV_32F, 1 / 255.0);
	};
	cv::Mat f, ycc;
	bgr8.convertTo(f, CV_32FC3, 1 / 255.0);
	cv::cvtColor(f, ycc, cv::COLOR_BGR2YCrCb);
	std::vector<cv::Mat> planes;
	cv::split(ycc, planes);
	round8(planes[0]);
	const double fy = s == ChromaSubsampling::S420 ? 0.5 : 1.0;
	for (int p = 1; p < 3; ++p)
	{
		// cv::resize aligns pixel centres: INTER_AREA averages each cell,
		// INTER_LINEAR interpolates between the cells' centres.
		cv::Mat cells;
		cv::resize(planes[p], cells, cv::Size(), 0.5, fy, cv::INTER_AREA);
		round8(cells);
		cv::resize(cells, planes[p], planes[p].size(), 0, 0, cv::INTER_LINEAR);
	}
	cv::merge(planes, ycc);
	cv::cvtColor(ycc, f, cv::COLOR_YCrCb2BGR);
	cv::Mat out;
	f.convertTo(out, CV_8UC3, 255.0);
	return out;
}

cv::Mat jpegRoundTrip(const cv::Mat& img, int quality)
{
	std::vector<uchar> buf;
	// OpenCV 4.6 cannot choose the chroma sampling; libjpeg's default for
	// colour images is 4:2:0 (a test reads it from the stream's SOF marker).
	cv::imencode(".jpg", img, buf, {cv::IMWRITE_JPEG_QUALITY, quality});
	return cv::imdecode(buf, cv::IMREAD_COLOR);
}

cv::Mat cameraImage(cv::Mat& linear, const RenderOptions& o, double cx, double cy, uint64_t seed)
{
	cv::Mat& img = linear;	// linear light until the transfer curve
	CV_Assert(img.type() == CV_32FC3);
	if (!o.range_draws.empty() || !o.choice_draws.empty())
		throw std::invalid_argument("cameraImage: draw the options' ranges first (drawn(seed))");
	// 1. Optics, in linear light.
	if (o.blur_sigma_px > 0)
		cv::GaussianBlur(
			img, img, cv::Size(0, 0), o.blur_sigma_px, o.blur_sigma_px, cv::BORDER_REPLICATE);
	if (o.defocus_radius_px > 0)
		cv::filter2D(
			img, img, -1, defocusKernel(o.defocus_radius_px), cv::Point(-1, -1), 0,
			cv::BORDER_REPLICATE);
	applyMotionBlur(img, o.motion_blur_px, o.motion_blur_angle_rad);
	// 2-4. Lens colour and shading, then exposure and white balance.
	applyChromaticAberration(img, o.ca_red_px, o.ca_blue_px, cx, cy);
	applyVignetting(img, o.vignetting, cx, cy);
	if (o.exposure != 1 || o.wb_red != 1 || o.wb_blue != 1)
		cv::multiply(
			img, cv::Scalar(o.exposure * o.wb_blue, o.exposure, o.exposure * o.wb_red), img);
	// 5. The sensor.
	if (o.noise_sigma > 0)
	{
		cv::RNG rng(detail::streamSeed(seed, 4));
		cv::Mat noise(img.size(), img.type());
		rng.fill(noise, cv::RNG::NORMAL, 0.0, o.noise_sigma);
		img += noise;
	}
	addSensorNoise(img, o.full_well_e, o.read_noise_e, seed);
	// 6-8. The image signal processor.
	if (o.bayer != BayerLayout::None) img = demosaicRaw(mosaic(img, o.bayer), o.bayer, o.demosaic);
	applyTransfer(img, o.transfer, o.gamma, o.filmic_strength);
	unsharpMask(img, o.unsharp_sigma_px, o.unsharp_amount);
	// 9-11. Rounding (and clamping) to 8 bits, the video format, the codec.
	cv::Mat out;
	img.convertTo(out, CV_8UC3);
	if (o.chroma_subsampling != ChromaSubsampling::None)
		out = subsampleChroma(out, o.chroma_subsampling);
	if (o.jpeg_quality > 0) out = jpegRoundTrip(out, o.jpeg_quality);
	return out;
}

}  // namespace codemark::sim
