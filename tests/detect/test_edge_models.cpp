// The sub-pixel stage's parts on their own: each edge locator on synthetic
// profiles with a known edge, through the transfer curves, blur and
// sharpening of the camera pipeline; the policy's choice per side kind.
#include "edge_models.h"

#include <codemark/sim/camera_pipeline.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

using namespace codemark;
using namespace codemark::detect;

namespace
{
/** A print across a side in linear light [full scale]: per channel (B, G,
 * R), the wall up to the frame's outer edge, the black frame up to the
 * inner edge at x0, the fill beyond. */
struct Print
{
	std::array<double, 3> wall, black, fill;
	double frame_px;
};

/** The camera's view of \a print with the inner edge at \a x0
 * (sim::cameraProfile()): the G profile and -(R + B), \a n samples each. */
void cameraProfile(
	const Print& print, double x0, double sigma, double amount, sim::Transfer curve, int n,
	std::vector<int>& g, std::vector<int>& rb)
{
	sim::PrintProfile p;
	p.edges = {x0 - print.frame_px, x0};
	p.levels = {print.wall, print.black, print.fill};
	const auto px = sim::cameraProfile(p, n, sigma, amount, curve);
	g.resize(n);
	rb.resize(n);
	for (int i = 0; i < n; ++i)
	{
		g[i] = px[i][1];
		rb[i] = -(px[i][0] + px[i][2]);
	}
}

/** The three side kinds the policy tells apart, and the locator each one
 * gets: a wide frame (the centroid), a thin one (the peak with the outer
 * edge's lobe), a fill above the sensor's top on a wide frame (R + B next
 * to G's peak). */
struct Case
{
	const char* name;
	Print print;
	LocatorChoice choice;
};
std::vector<Case> cases()
{
	const std::array<double, 3> wall{0.6, 0.6, 0.6}, black{0.02, 0.02, 0.02};
	return {
		{"wide", {wall, black, {0.05, 0.7, 0.1}, 12}, {LocatorKind::Centroid, 0}},
		{"thin", {wall, black, {0.05, 0.7, 0.1}, 3}, {LocatorKind::Peak, 3}},
		{"clipped", {wall, {0.25, 0.02, 0.25}, {0.0, 1.4, 0.0}, 12}, {LocatorKind::Channels, 0}}};
}

/** Mean signed error [px, positive into the fill] of \a locator over
 * sub-pixel positions of the edge, and the largest error. */
struct Errors
{
	double mean = 0, worst = 0;
};
Errors locatorErrors(
	const EdgeLocator& locator, const Print& print, double sigma, double amount,
	sim::Transfer curve)
{
	const SubpixelParams p;
	const int half = p.search_px + p.reach_px + 2, n = 2 * half + 1;
	std::vector<int> g, rb;
	Errors e;
	int count = 0;
	for (double x0 = half - 0.5; x0 < half + 0.5; x0 += 0.05, ++count)
	{
		cameraProfile(print, x0, sigma, amount, curve, n, g, rb);
		const auto at =
			locator.locate(g.data(), rb.data(), n, half - p.search_px, half + p.search_px);
		EXPECT_TRUE(at.has_value());
		if (!at) return {1e9, 1e9};
		e.mean += *at - x0;
		e.worst = std::max(e.worst, std::abs(*at - x0));
	}
	e.mean /= count;
	return e;
}
}  // namespace

// In linear light each locator reads its side kind's edge exactly, up to
// the profile's 8-bit rounding (and R + B's smaller contrast), whatever the
// blur, and with an unsharp mask, which is odd-symmetric about the edge.
// Through a camera's transfer curve (after the blur) each channel's edge
// moves towards that channel's dark side: G's towards the black frame (the
// square looks larger), R + B's into the fill (a clipped fill's locator
// reads R + B only within reach of G's peak, G's peak beyond). That bend is
// what the green band's midline (centreOnBand()) cancels and no
// single-edge locator can.
TEST(EdgeModels, EveryLocatorThroughCurvesBlurAndSharpening)
{
	const SubpixelParams p;
	for (const auto& c : cases())
	{
		const auto locator = makeLocator(c.choice, 5, p);
		for (const double sigma : {0.5, 0.8, 1.2})
			for (const double amount : {0.0, 0.5})
				for (const auto curve :
					 {sim::Transfer::Linear, sim::Transfer::SRGB, sim::Transfer::Gamma,
					  sim::Transfer::Filmic})
				{
					const Errors e = locatorErrors(*locator, c.print, sigma, amount, curve);
					const std::string what =
						std::string(c.name) + " sigma " + std::to_string(sigma) + " sharpen " +
						std::to_string(amount) + " " + sim::transferName(curve);
					std::printf(
						"[ locator ] %-8s %-9s sigma %.1f sharpen %.1f %-7s mean %+.4f worst "
						"%.4f\n",
						c.name, locatorName(c.choice.kind), sigma, amount, sim::transferName(curve),
						e.mean, e.worst);
					if (curve == sim::Transfer::Linear)
					{
						EXPECT_LE(std::abs(e.mean), 0.025) << what;
						EXPECT_LE(e.worst, 0.075) << what;
					}
					else if (c.choice.kind != LocatorKind::Channels)
					{
						EXPECT_LT(e.mean, -0.1) << what;
					}
					else
					{
						// R + B's edge where it lies within reach of G's
						// peak, G's peak where the curve moved it farther.
						EXPECT_GT(std::abs(e.mean), 0.1) << what;
					}
				}
	}
}

// On a clipped fill the edge is read in R + B next to G's peak. A camera's
// lateral chromatic aberration or its demosaicing's fringes can put R + B's
// edge a pixel or more away from G's: R + B farther from G's peak than the
// clip can pull that peak is not the fill's edge, and G's peak stands.
TEST(EdgeModels, ChannelsFarFromGreensPeakAreNotTheEdge)
{
	const SubpixelParams p;
	const Case clipped = cases()[2];
	const auto locator = makeLocator(clipped.choice, 5, p);
	const int half = p.search_px + p.reach_px + 2, n = 2 * half + 1;
	for (const double offset : {0.0, 0.3, 1.5, -1.5})
		for (double x0 = half - 0.5; x0 < half + 0.5; x0 += 0.1)
		{
			// G with its edge at x0; R + B read from a profile whose edge
			// lies offset further into the fill.
			std::vector<int> g, rb, unused;
			cameraProfile(clipped.print, x0, 0.8, 0, sim::Transfer::Linear, n, g, unused);
			cameraProfile(clipped.print, x0 + offset, 0.8, 0, sim::Transfer::Linear, n, unused, rb);
			const auto at =
				locator->locate(g.data(), rb.data(), n, half - p.search_px, half + p.search_px);
			ASSERT_TRUE(at.has_value());
			const std::string what =
				"offset " + std::to_string(offset) + " at " + std::to_string(x0);
			if (std::abs(offset) < 0.5)
				EXPECT_NEAR(*at, x0 + offset, 0.05) << what;  // R + B read
			else
				EXPECT_NEAR(*at, x0, 0.65) << what;	 // G's peak, pulled by the clip
		}
}

namespace
{
/** An axis-aligned print on a wall, as a camera without a transfer curve
 * sees it: the inner square [o, o + side) px with o = 2 frame + 20 +
 * \a shift, a frame \a frame px wide around it, the fill \a fill (B, G,
 * R; above 255 the sensor clips it), blurred by 0.8 px, with Gaussian
 * noise of \a noise_grey grey levels per channel; and the coarse
 * quadrangle of its inner corners, off by a few tenths of a pixel as stage
 * 6 leaves them. A fractional \a shift is drawn at \a k x and averaged
 * down. */
struct PrintImage
{
	cv::Mat bgr;
	Quad coarse;
};
PrintImage printImage(
	int side, int frame, const cv::Scalar& fill, double shift = 0, double noise_grey = 0, int k = 1)
{
	const double o = 2 * frame + 20 + shift;
	const int size = side + 2 * (2 * frame + 20);
	cv::Mat light(k * size, k * size, CV_32FC3, cv::Scalar(200, 200, 200));
	const auto rect = [&](double at, double width)
	{
		const int a = static_cast<int>(std::lround(k * at)),
				  b = static_cast<int>(std::lround(k * (at + width)));
		return cv::Rect(a, a, b - a, b - a);
	};
	cv::rectangle(light, rect(o - frame, side + 2 * frame), cv::Scalar(25, 25, 25), cv::FILLED);
	cv::rectangle(light, rect(o, side), fill, cv::FILLED);
	cv::GaussianBlur(light, light, cv::Size(0, 0), 0.8 * k);
	if (k > 1) cv::resize(light, light, cv::Size(size, size), 0, 0, cv::INTER_AREA);
	if (noise_grey > 0)
	{
		cv::Mat noise(light.size(), light.type());
		cv::RNG rng(7);
		rng.fill(noise, cv::RNG::NORMAL, 0, noise_grey);
		light += noise;
	}
	PrintImage out;
	light.convertTo(out.bgr, CV_8UC3);	// rounds and clips at 255
	const double a = o - 0.5, b = o + side - 0.5;
	out.coarse = {
		Eigen::Vector2d(a + 0.3, a - 0.2), Eigen::Vector2d(b - 0.2, a + 0.3),
		Eigen::Vector2d(b + 0.2, b - 0.3), Eigen::Vector2d(a - 0.3, b + 0.2)};
	return out;
}
}  // namespace

// The policy on each side kind as readSideProfiles() reads it from an
// image: what it measures (the frame's width, saturation, the clip at the
// edge) and the locator it picks, on every side.
TEST(EdgeModels, PolicyPicksTheLocatorFromTheSidesProperties)
{
	const SubpixelParams p;
	const double frame_ratio = 0.125, fill_ratio = 35.0 / 160;
	struct Expected
	{
		const char* name;
		int side, frame, fill_g;
		bool saturated, clipped;
		LocatorKind kind;
		bool outer_edge;  // the Peak locator models the outer edge
		/** The locator's largest error alone [px]. On a thin frame whose
		 * fill clips, the clip cuts the response's bright half and the
		 * peak moves outwards: the clip's imputation (a side model, run
		 * before the locator in refineQuadrangle()) restores it. */
		double locator_px;
	};
	for (const Expected& x : std::vector<Expected>{
			 {"wide frame", 80, 10, 180, false, false, LocatorKind::Centroid, false, 0.05},
			 {"thin frame", 32, 4, 180, false, false, LocatorKind::Peak, true, 0.05},
			 {"clipped fill, wide frame", 80, 10, 400, true, true, LocatorKind::Channels, false,
			  0.05},
			 {"clipped fill, thin frame", 32, 4, 400, true, true, LocatorKind::Peak, false, 0.5}})
	{
		const PrintImage img = printImage(x.side, x.frame, cv::Scalar(5, x.fill_g, 5));
		for (int side = 0; side < 4; ++side)
		{
			SCOPED_TRACE(std::string(x.name) + ", side " + std::to_string(side));
			const SideProfiles prof =
				readSideProfiles(img.bgr, img.coarse, side, frame_ratio, fill_ratio, p);
			EXPECT_GE(prof.count(), static_cast<size_t>(x.side - 2 * p.corner_margin_px - 1));
			const SideProperties s = measureSide(prof);
			EXPECT_NEAR(s.frame_px, x.frame, 0.1 * x.frame);
			EXPECT_EQ(s.saturated, x.saturated);
			EXPECT_EQ(s.clipped, x.clipped);
			const LocatorChoice c = chooseLocator(s, p);
			EXPECT_EQ(c.kind, x.kind) << locatorName(c.kind);
			if (x.outer_edge)
			{
				EXPECT_DOUBLE_EQ(c.outer_edge_px, s.frame_px);
			}
			else
			{
				EXPECT_EQ(c.outer_edge_px, 0);
			}
			// The outer edge's model switched off for an experiment.
			SubpixelModels plain;
			plain.outer_edge = false;
			EXPECT_EQ(chooseLocator(s, p, plain).outer_edge_px, 0);
			// The chosen locator finds the inner edge, half a pixel before
			// the first fill pixel, in every profile.
			const auto edges = locateEdges(prof, *makeLocator(c, 5, p));
			int found = 0;
			double worst = 0;
			const double o = 2 * x.frame + 20 - 0.5, b = o + x.side;
			for (size_t j = 0; j < prof.count(); ++j)
				if (edges[j])
				{
					++found;
					const Eigen::Vector2d pt = prof.point(j, *edges[j]);
					const double across = pt(prof.across);
					worst = std::max(worst, std::min(std::abs(across - o), std::abs(across - b)));
				}
			EXPECT_EQ(found, static_cast<int>(prof.count()));
			EXPECT_LT(worst, x.locator_px);
		}
		// The whole stage, side models and line fits included, puts the
		// corners on the print's.
		const auto r = refineQuadrangle(img.bgr, img.coarse, CameraModel(), 5, frame_ratio, p);
		ASSERT_TRUE(r) << x.name;
		const double a = 2 * x.frame + 20 - 0.5, b = a + x.side;
		const Quad truth{
			Eigen::Vector2d(a, a), Eigen::Vector2d(b, a), Eigen::Vector2d(b, b),
			Eigen::Vector2d(a, b)};
		for (int k = 0; k < 4; ++k)
			EXPECT_LT((r->corners_raw[k] - truth[k]).norm(), 0.05) << x.name << ", corner " << k;
	}
}

namespace
{
/** An office printer's green (B, G, R): R and B well above the frame's
 * black, as printed greens are (on #00FF00 paper R and B sit at the
 * sensor's black, where decoding a subsampled chroma clips them, and luma
 * then carries part of the chroma too). */
const cv::Scalar kPrintedGreen(70, 170, 45);

}  // namespace

// A wide frame's side is read in luma where the camera's colour has less
// resolution than its luma, in G where it has the full resolution. Through
// 4:2:0 chroma subsampling, with the edges a quarter pixel into a 2-px
// chroma cell, decoded G carries part of a printed green's step at the
// chroma's resolution: G's edge response is wider than luma's on every
// side, and without noise luma's corners are the closer. With the colour
// at full resolution both see one edge shape, and G, to which luma's R and
// B would only add their noise, is kept on every side.
TEST(EdgeModels, LumaReadsWideSidesWhereTheChromaIsSubsampled)
{
	const SubpixelParams p;
	const double frame_ratio = 0.125, fill_ratio = 35.0 / 160;
	const int side_px = 80, frame = 10;
	for (const double noise : {0.0, 1.5})
		for (const double shift : {0.25, 0.75})
			for (const bool subsampled : {false, true})
			{
				PrintImage img = printImage(side_px, frame, kPrintedGreen, shift, noise, 4);
				if (subsampled)
					img.bgr = sim::subsampleChroma(img.bgr, sim::ChromaSubsampling::S420);
				const std::string what = std::string(subsampled ? "4:2:0" : "full colour") +
										 ", noise " + std::to_string(noise) + ", shift " +
										 std::to_string(shift);
				for (int side = 0; side < 4; ++side)
				{
					SCOPED_TRACE(what + ", side " + std::to_string(side));
					const SideProfiles green =
						readSideProfiles(img.bgr, img.coarse, side, frame_ratio, fill_ratio, p);
					const LocatorChoice c = chooseLocator(measureSide(green), p);
					ASSERT_EQ(c.kind, LocatorKind::Centroid);
					EXPECT_EQ(c.channel, EdgeChannel::Luma);
					SideProfiles luma = green;
					readLumaProfiles(img.bgr, luma);
					// Luma at the same samples, on the fill and in the frame (25
					// grey: 25 / 0.587).
					const int* l = luma.gAt(luma.count() / 2);
					const double fill_luma = (0.114 * kPrintedGreen[0] + 0.587 * kPrintedGreen[1] +
											  0.299 * kPrintedGreen[2]) /
											 0.587;
					EXPECT_NEAR(l[luma.n - 1], fill_luma, 6);
					EXPECT_NEAR(l[luma.half - 5], 25 / 0.587, 6);
					const auto locator = makeLocator(c, 5, p);
					EXPECT_EQ(
						lumaIsSharper(
							green, locateEdges(green, *locator), luma, locateEdges(luma, *locator)),
						subsampled);
				}
				const double a = 2 * frame + 20 + shift - 0.5, b = a + side_px;
				const Quad truth{
					Eigen::Vector2d(a, a), Eigen::Vector2d(b, a), Eigen::Vector2d(b, b),
					Eigen::Vector2d(a, b)};
				const auto error = [&](const SubpixelModels& m, EdgeChannel expected)
				{
					const auto r = refineQuadrangle(
						img.bgr, img.coarse, CameraModel(), 5, frame_ratio, p, fill_ratio, m);
					EXPECT_TRUE(r) << what;
					if (!r) return 1e9;
					double sum = 0;
					for (int k = 0; k < 4; ++k)
					{
						EXPECT_EQ(r->channel[k], expected) << what << ", side " << k;
						sum += (r->corners_raw[k] - truth[k]).norm();
					}
					return sum / 4;
				};
				SubpixelModels g_only;
				g_only.luma_edges = false;
				const double e_g = error(g_only, EdgeChannel::Green);
				const double e = error({}, subsampled ? EdgeChannel::Luma : EdgeChannel::Green);
				if (!subsampled)
				{
					EXPECT_EQ(e, e_g) << what;
				}
				else if (noise == 0)
				{
					EXPECT_LT(e, 0.5 * e_g) << what << ": " << e << " px against G's " << e_g;
				}
				EXPECT_LT(e, 0.03) << what;
			}
}

// The slope the line fit's grey-level limit divides by: the profiles'
// central difference at their located edges, the median over the side;
// profiles without an edge do not count.
TEST(EdgeModels, EdgeSlopeIsTheMedianResponseSlopeAtTheEdges)
{
	SideProfiles side;
	side.n = 21;
	std::vector<std::optional<double>> edges;
	// Ramps of slope 5, 7, 7, 9 and 30 grey levels per sample about sample 10,
	// then one without an edge (a steep one, which must not count).
	for (const double s : {5.0, 7.0, 7.0, 9.0, 30.0, 100.0})
	{
		for (int i = 0; i < side.n; ++i)
			side.g.push_back(static_cast<int>(std::clamp(40 + s * (i - 10), 10.0, 250.0)));
		side.pos.push_back(static_cast<int>(side.pos.size()));
		edges.emplace_back(s < 100 ? std::optional<double>(10.3) : std::nullopt);
	}
	EXPECT_DOUBLE_EQ(edgeSlope(side, edges), 7.0);
	EXPECT_EQ(edgeSlope(side, std::vector<std::optional<double>>(6)), 0.0);
}

// midmeanOf(): the mean of the middle half. Two equal populations (a
// noise-free side's alternate rows) give their middle, where the median
// gives one of them; a quarter of wild values on either side leaves it;
// up to six values it is the median.
TEST(EdgeModels, MidmeanLiesBetweenPopulationsAndIgnoresTheWildQuarter)
{
	std::vector<double> two;
	for (int k = 0; k < 20; ++k) two.push_back(k % 2 ? 0.3 : 0.1);
	std::vector<double> copy = two;
	EXPECT_NEAR(midmeanOf(two), 0.2, 1e-12);
	EXPECT_NEAR(std::abs(medianOf(copy) - 0.2), 0.1, 1e-12);

	std::vector<double> wild;
	for (int k = 0; k < 12; ++k) wild.push_back(0.01 * (k % 3));
	for (int k = 0; k < 4; ++k) wild.push_back(k % 2 ? 5.0 : -3.0);
	EXPECT_NEAR(midmeanOf(wild), 0.01, 1e-12);

	for (std::vector<double> x :
		 {std::vector<double>{7.0},
		  {1.0, 3.0},
		  {9.0, 1.0, 2.0},
		  {9.0, -4.0, 1.0, 2.0},
		  {9.0, -4.0, 1.0, 2.0, 1.5},
		  {9.0, -4.0, 1.0, 2.0, 1.5, 0.0}})
	{
		std::vector<double> y = x;
		std::sort(y.begin(), y.end());
		const size_t n = y.size();
		const double median = n % 2 ? y[n / 2] : 0.5 * (y[n / 2 - 1] + y[n / 2]);
		EXPECT_DOUBLE_EQ(midmeanOf(x), median) << n << " values";
	}
}
