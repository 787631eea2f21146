#pragma once
/** \file camera_pipeline.h
 * The camera pipeline: what a real camera does to the light a renderer
 * computes, in a real camera's order. Every stage works on a linear image
 * (CV_32FC3, BGR, 0..255 = the sensor's full scale) until the transfer
 * curve; the last stages (sharpening, 8-bit rounding, JPEG) work on the
 * encoded image, as an image signal processor does.
 *
 * The stages, in order (each off at its default):
 *  1. optics: Gaussian blur (blur_sigma_px), a defocus disc
 *     (defocus_radius_px) and linear motion blur, in linear light;
 *  2. lateral chromatic aberration: R and B scaled radially about the
 *     principal point against G (ca_red_px, ca_blue_px at the farthest
 *     image corner);
 *  3. vignetting: gain 1 - vignetting (r / r_corner)^2;
 *  4. exposure gain and white balance (R and B gains against G);
 *  5. sensor noise: Gaussian grey-level noise (noise_sigma) and shot plus
 *     read noise in electrons (full_well_e, read_noise_e), then clipping
 *     at full scale;
 *  6. Bayer mosaic (bayer) and OpenCV's demosaicing (demosaic);
 *  7. the transfer curve (linear, sRGB, pure gamma, filmic S-curve);
 *  8. unsharp masking (unsharp_sigma_px, unsharp_amount);
 *  9. rounding to 8 bits;
 * 10. chroma subsampling of a YCbCr video format (chroma_subsampling:
 *     4:2:2 or 4:2:0, without compression);
 * 11. the JPEG round trip (jpeg_quality, 4:2:0 chroma subsampling).
 *
 * The stage functions are public so that each can be tested on its own;
 * cameraImage() runs them all from a RenderOptions.
 */
#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace codemark::sim
{
struct RenderOptions;

/** Colour filter array layout, named by the 2 x 2 block at the image's
 * top-left pixel, row by row. */
enum class BayerLayout
{
	None,  //!< no mosaic: three full colour planes (a 3-chip camera, or a renderer)
	RGGB,
	BGGR,
	GRBG,
	GBRG
};

/** Demosaicing algorithm (OpenCV's cv::demosaicing). */
enum class Demosaic
{
	Bilinear,  //!< COLOR_Bayer*2BGR
	VNG,  //!< COLOR_Bayer*2BGR_VNG (variable number of gradients; 8-bit raw)
	EdgeAware  //!< COLOR_Bayer*2BGR_EA
};

/** Transfer curve from linear light to the encoded value, both in [0, 1]. */
enum class Transfer
{
	Linear,	 //!< y = x
	SRGB,  //!< IEC 61966-2-1
	Gamma,	//!< y = x^(1 / gamma)
	/** sRGB followed by a monotone S-curve s(y) = y - k sin(2 pi y) / (2 pi)
	 * of strength k (filmic_strength): slope 1 + k at mid-grey, 1 - k at
	 * the ends, the ends fixed. */
	Filmic
};

/** Chroma subsampling of a YCbCr image format (a webcam's YUYV or NV12
 * stream): the colour difference planes at half the luma's resolution. */
enum class ChromaSubsampling
{
	None,  //!< 4:4:4: every pixel keeps its colour
	S422,  //!< 4:2:2: half the columns (YUYV, UYVY)
	S420  //!< 4:2:0: half the columns and half the rows (NV12, I420, MJPEG)
};

const char* bayerName(BayerLayout b);  //!< "none", "RGGB", ...
const char* demosaicName(Demosaic d);  //!< "bilinear", "vng", "edge-aware"
const char* transferName(Transfer t);  //!< "linear", "srgb", "gamma", "filmic"
const char* chromaName(ChromaSubsampling c);  //!< "none", "422", "420"
/** Parsers of the names above (case-insensitive); throw
 * std::invalid_argument naming \a key and the accepted names. */
BayerLayout bayerFromName(const std::string& name, const std::string& key = "bayer");
Demosaic demosaicFromName(const std::string& name, const std::string& key = "demosaic");
Transfer transferFromName(const std::string& name, const std::string& key = "transfer");
ChromaSubsampling chromaFromName(
	const std::string& name, const std::string& key = "chroma_subsampling");

/** The encoded value of linear \a x in [0, 1] (clamped) under \a t. */
double encodeTransfer(double x, Transfer t, double gamma = 2.2, double filmic_strength = 0.25);
/** The inverse of encodeTransfer (the filmic S-curve by Newton's method). */
double decodeTransfer(double y, Transfer t, double gamma = 2.2, double filmic_strength = 0.25);

/** Linear motion blur in place: a normalised line kernel of \a length_px
 * along \a angle_rad (counter-clockwise from +u as displayed, i.e. towards
 * -v), with bilinear splats for sub-pixel lengths; length 0: nothing. */
void applyMotionBlur(cv::Mat& img, double length_px, double angle_rad);

/** The defocus point spread function: a disc of \a radius_px with each
 * kernel pixel weighted by its exact covered area (16 x 16 samples per
 * pixel), normalised to sum 1; CV_32F, odd size. radius 0: the 1 x 1 unit
 * kernel. */
cv::Mat defocusKernel(double radius_px);

/** Radial magnification of R and B against G about (cx, cy): a point at
 * radius r from the principal point in G appears at r (1 + shift / r_c) in
 * R (shift = red_px) and B (blue_px), r_c the distance to the farthest
 * image corner [px]. Bilinear resampling; a zero shift leaves the plane
 * untouched. In place on a CV_32FC3 BGR image. */
void applyChromaticAberration(cv::Mat& img, double red_px, double blue_px, double cx, double cy);

/** Multiplies by 1 - amount (r / r_c)^2 (r from (cx, cy), r_c as above). */
void applyVignetting(cv::Mat& img, double amount, double cx, double cy);

/** Adds shot noise (Poisson, drawn as a Gaussian of the same variance
 * e = x / 255 * full_well_e electrons) and read noise (\a read_noise_e
 * electrons RMS) to a linear image whose 255 is the full well, then clips
 * to [0, 255] (saturation). full_well_e <= 0: nothing. */
void addSensorNoise(cv::Mat& img, double full_well_e, double read_noise_e, uint64_t seed);

/** The raw mosaic of linear \a img (CV_32FC3 BGR): one CV_32F plane holding
 * at each pixel the colour its filter passes under \a layout. */
cv::Mat mosaic(const cv::Mat& img, BayerLayout layout);
/** Full colour (CV_32FC3 BGR, 0..255) from a CV_32F raw mosaic in
 * 0..255: quantised to 16 bits (8 bits for VNG, OpenCV's limit) as a
 * raw file is, then cv::demosaicing. */
cv::Mat demosaicRaw(const cv::Mat& raw, BayerLayout layout, Demosaic method);

/** An 8-bit BGR image through a YCbCr format with subsampled chroma and
 * back: converted to full-range YCbCr (BT.601, as JPEG), Cb and Cr
 * averaged over 2 x 1 (4:2:2) or 2 x 2 (4:2:0) pixel cells and
 * interpolated back linearly between the cells' centres (a decoder's
 * upsampling), then to BGR; Y is kept at full resolution. None: a copy. */
cv::Mat subsampleChroma(const cv::Mat& bgr8, ChromaSubsampling s);

/** A print across its edges in one dimension, in linear light: levels[0]
 * (B, G, R) [0..1 of full scale, above 1 clips] up to edges[0] [px],
 * levels[1] up to edges[1], and so on; levels has one more entry than
 * edges. */
struct PrintProfile
{
	std::vector<double> edges;
	std::vector<std::array<double, 3>> levels;
};

/** Pixels 0..n-1 of \a print through the camera pipeline's stages that act
 * on a profile across edges, in its order: a Gaussian blur of \a sigma
 * [px] integrated over each pixel (exact, through the normal's CDF), the
 * sensor's clip at full scale, an unsharp mask of radius 1 px and \a
 * amount, the transfer curve \a curve, 8-bit rounding. For tests and
 * benchmarks of edge locators against a known edge. B, G, R per pixel. */
std::vector<std::array<int, 3>> cameraProfile(
	const PrintProfile& print, int n, double sigma, double unsharp_amount, Transfer curve,
	double gamma = 2.2, double filmic_strength = 0.25);

/** Encodes a linear CV_32FC3 image in place (0..255 in and out, clamped). */
void applyTransfer(cv::Mat& img, Transfer t, double gamma, double filmic_strength);

/** img += amount (img - Gaussian(img, sigma_px)), in place. */
void unsharpMask(cv::Mat& img, double sigma_px, double amount);

/** Encodes \a img (CV_8UC3) as JPEG at \a quality with 4:2:0 chroma
 * subsampling and decodes it. */
cv::Mat jpegRoundTrip(const cv::Mat& img, int quality);

/** Runs the whole pipeline on \a linear (CV_32FC3 BGR, 0..255 = full
 * scale; modified) with the stages of \a o, which must have no ranges
 * left (use RenderOptions::drawn(seed) first); (cx, cy) is the principal
 * point [px]. Returns the CV_8UC3 BGR image a camera would deliver. The
 * noise is a function of \a seed. */
cv::Mat cameraImage(cv::Mat& linear, const RenderOptions& o, double cx, double cy, uint64_t seed);

}  // namespace codemark::sim
