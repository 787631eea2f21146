// The colour report of a detection (codemark-detect --colour-report).
#include <codemark/detect/colour.h>
#include <codemark/detect/json.h>

#include "stages.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

namespace codemark::detect
{
MeasuredColour hsiOf(double r, double g, double b)
{
	MeasuredColour c;
	c.r = r;
	c.g = g;
	c.b = b;
	c.intensity = (r + g + b) / 3;
	const double mx = std::max({r, g, b}), mn = std::min({r, g, b});
	c.saturation = c.intensity > 0 ? 1 - mn / c.intensity : 0;
	const double chroma = mx - mn;
	if (chroma <= 0) return c;
	// Hexcone hue: the form the segmentation predicate evaluates (for G the
	// largest channel, 120 + 60 (B - R) / chroma).
	double h = 0;
	if (mx == g)
		h = 120 + 60 * (b - r) / chroma;
	else if (mx == r)
		h = 60 * (g - b) / chroma;
	else
		h = 240 + 60 * (r - g) / chroma;
	c.hue_deg = std::fmod(h + 360, 360);
	return c;
}

ColourReport colourReport(
	const cv::Mat& bgr, const codemark::Detection& d, const CameraModel& camera,
	const LandmarkGeometry& geometry, const DetectorOptions& opt)
{
	Quad ideal;
	for (int k = 0; k < 4; ++k)
		ideal[k] = camera.hasDistortion() ? camera.undistortPixel(d.corners[k]) : d.corners[k];
	const FaceMap map{faceToImage(ideal), camera, camera.hasDistortion()};
	// Face coordinates: the reference square is [-1, 1]^2. The middle half
	// of the green band (between the code board and the frame) and of the
	// frame, clear of the blur of their edges.
	const double h = geometry.innerHalf();
	const double outer = geometry.outerHalf() / h, board = 1.5 * geometry.cell_size_m / h;
	const double fill_lo = board + 0.25 * (1 - board), fill_hi = 1 - 0.25 * (1 - board);
	const double frame_lo = 1 + 0.25 * (outer - 1), frame_hi = outer - 0.25 * (outer - 1);
	std::array<double, 3> fill{}, frame{};
	std::array<double, 4> side_g{};
	std::array<int, 4> side_n{};
	int n_fill = 0, n_frame = 0;
	// A grid fine enough for a pixel or more per sample at any size the
	// detector finds: the frame's side spans at most the image.
	const int steps =
		std::clamp(static_cast<int>((d.corners[1] - d.corners[0]).norm() * outer), 32, 2048);
	for (int i = 0; i <= steps; ++i)
		for (int j = 0; j <= steps; ++j)
		{
			const double x = outer * (2.0 * i / steps - 1), y = outer * (2.0 * j / steps - 1);
			const double r = std::max(std::abs(x), std::abs(y));
			const bool in_fill = r >= fill_lo && r <= fill_hi;
			const bool in_frame = r >= frame_lo && r <= frame_hi;
			if (!in_fill && !in_frame) continue;
			const Eigen::Vector2d px = map(x, y);
			const int u = static_cast<int>(std::lround(px.x())),
					  v = static_cast<int>(std::lround(px.y()));
			if (u < 0 || v < 0 || u >= bgr.cols || v >= bgr.rows) continue;
			const uint8_t* p = bgr.ptr<uint8_t>(v) + 3 * u;
			auto& acc = in_fill ? fill : frame;
			for (int c = 0; c < 3; ++c) acc[c] += p[c];
			if (in_fill)
				++n_fill;
			else
			{
				++n_frame;
				// Sides top, right, bottom, left (face y up).
				const int side = std::abs(y) >= std::abs(x) ? (y > 0 ? 0 : 2) : (x > 0 ? 1 : 3);
				side_g[side] += p[1];
				++side_n[side];
			}
		}
	ColourReport out;
	const auto mean = [](const std::array<double, 3>& bgr_sum, int n)
	{
		const double k = n > 0 ? 1.0 / n : 0;
		MeasuredColour c = hsiOf(k * bgr_sum[2], k * bgr_sum[1], k * bgr_sum[0]);
		c.samples = n;
		return c;
	};
	out.fill = mean(fill, n_fill);
	out.frame = mean(frame, n_frame);
	const SegmentationParams& s = opt.segmentation;
	out.margin_intensity = out.fill.intensity - s.min_intensity;
	out.margin_saturation = out.fill.saturation - s.min_saturation;
	out.margin_hue_min_deg = out.fill.hue_deg - s.hue_min_deg;
	out.margin_hue_max_deg = s.hue_max_deg - out.fill.hue_deg;
	// The frame's G as the code stage reads it: its two darkest sides, and
	// their ink (the blur's share of the fill and the sheet removed) for the
	// ratio.
	std::array<double, 4> sides{}, inks{};
	for (int k = 0; k < 4; ++k)
	{
		sides[k] = side_n[k] > 0 ? side_g[k] / side_n[k] : 255;
		inks[k] = frameSurround(bgr, map, geometry, k, opt.components.frame_blur_px)
					  .ink(sides[k], out.fill.g);
	}
	std::sort(sides.begin(), sides.end());
	std::sort(inks.begin(), inks.end());
	const double frame_g = 0.5 * (sides[0] + sides[1]), ink_g = 0.5 * (inks[0] + inks[1]);
	out.margin_black_ratio = out.fill.g > 0 ? opt.code.max_black_ratio - ink_g / out.fill.g : -1;
	out.margin_contrast = out.fill.g - frame_g - opt.code.min_contrast;
	return out;
}

std::string colourReportJson(const ColourReport& r)
{
	const auto colour = [](const MeasuredColour& c)
	{
		return "{\"rgb\": [" + jsonNumber(c.r) + ", " + jsonNumber(c.g) + ", " + jsonNumber(c.b) +
			   "], \"hue_deg\": " + jsonNumber(c.hue_deg) +
			   ", \"saturation\": " + jsonNumber(c.saturation) +
			   ", \"intensity\": " + jsonNumber(c.intensity) +
			   ", \"samples\": " + std::to_string(c.samples) + "}";
	};
	std::ostringstream o;
	o << "{\"fill\": " << colour(r.fill) << ", \"frame\": " << colour(r.frame)
	  << ", \"margins\": {\"intensity\": " << jsonNumber(r.margin_intensity)
	  << ", \"saturation\": " << jsonNumber(r.margin_saturation)
	  << ", \"hue_min_deg\": " << jsonNumber(r.margin_hue_min_deg)
	  << ", \"hue_max_deg\": " << jsonNumber(r.margin_hue_max_deg)
	  << ", \"black_ratio\": " << jsonNumber(r.margin_black_ratio)
	  << ", \"contrast\": " << jsonNumber(r.margin_contrast) << "}}";
	return o.str();
}

}  // namespace codemark::detect
