// The detector: paper section 2.2, one stage after the other.
#include <codemark/detect/detector.h>
#include <codemark/landmark/primary.h>

#include "debug.h"
#include "stages.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace codemark::detect
{
namespace
{
using Clock = std::chrono::steady_clock;

double microsSince(Clock::time_point& t)
{
	const auto now = Clock::now();
	const double us = std::chrono::duration<double, std::micro>(now - t).count();
	t = now;
	return us;
}

double meanCornerDistance(const Quad& a, const std::array<Eigen::Vector2d, 4>& b)
{
	double s = 0;
	for (int k = 0; k < 4; ++k) s += (a[k] - b[k]).norm();
	return s / 4;
}
}  // namespace

DetectionResult detect(
	const cv::Mat& bgr, const CameraModel& camera, const LandmarkGeometry& geometry,
	const DetectorOptions& opt, const std::string& debug_dir)
{
	return detectWithModels(bgr, camera, geometry, opt, SubpixelModels(), debug_dir);
}

DetectionResult detectWithModels(
	const cv::Mat& bgr, const CameraModel& camera, const LandmarkGeometry& geometry,
	const DetectorOptions& opt, const SubpixelModels& models, const std::string& debug_dir)
{
	DetectionResult res;
	if (bgr.empty()) return res;
	if (bgr.type() != CV_8UC3)
		throw std::invalid_argument("detect: expected a CV_8UC3 (BGR) image");
	const bool debug = !debug_dir.empty();
	DebugRecord dbg;
	const auto t_start = Clock::now();
	auto t = t_start;
	StageTimings& tm = res.timings;

	// 1-2. Smoothing and colour segmentation (HSI predicate).
	const cv::Mat mask = segmentColour(bgr, opt.segmentation);
	tm.segmentation_us = microsSince(t);

	// 3. N4-connected components, cardinality and compactness: ROIs.
	// The landmark's proportions over the reference square's side: the black
	// frame's width, and the green band's between it and the code board.
	const double frame_ratio =
		(geometry.outerHalf() - geometry.innerHalf()) / geometry.inner_size_m;
	const double fill_ratio =
		(geometry.inner_size_m - 3 * geometry.cell_size_m) / (2 * geometry.inner_size_m);
	cv::Mat labels;
	const auto candidates = findCandidates(
		mask, opt.segmentation.step_px, bgr, opt.components, debug ? &labels : nullptr,
		&res.counts.components, geometry.cell_size_m / geometry.inner_size_m, frame_ratio);
	res.counts.rois = static_cast<int>(candidates.size());
	tm.components_us = microsSince(t);

	for (const Candidate& cand : candidates)
	{
		// 4. Gradients of G in the ROI: edgels with polarity, edgel domains.
		const double thr = gradientThreshold(cand.fill_g, opt.edgels);
		EdgelMap edgels = findEdgels(bgr, cand.roi, thr, opt.edgels);
		tm.edgels_us += microsSince(t);

		// 5. Segment selection: size, polarity, slimness, relative length.
		const auto sides = selectSegments(
			edgels.domains, cand, mask, opt.segmentation.step_px, opt.segments, &bgr, fill_ratio,
			opt.segmentation);
		tm.segments_us += microsSince(t);
		if (debug) dbg.edgels.push_back(std::move(edgels));
		if (!sides) continue;

		// 6. Four segments linked into a quadrangle.
		const auto quad = linkQuadrangle(*sides, opt.quads);
		tm.quads_us += microsSince(t);
		if (!quad) continue;
		++res.counts.quads;

		// 6b. The code's centre cell at the linked corners: a green surface
		// that links a quadrangle without a code board is refused before the
		// sub-pixel stage's work.
		if (models.centre_gate)
		{
			Quad ideal;
			for (int k = 0; k < 4; ++k) ideal[k] = camera.undistortPixel((*quad)[k]);
			const bool pass = centreMayBeBlack(bgr, ideal, camera, geometry, opt.code);
			tm.code_us += microsSince(t);
			if (!pass)
			{
				if (debug) dbg.refused.push_back(*quad);
				continue;
			}
		}

		// 7. Sub-pixel edges, a line per side, corners.
		auto refined = refineQuadrangle(
			bgr, *quad, camera, thr, frame_ratio, opt.subpixel, fill_ratio, models);
		tm.subpixel_us += microsSince(t);
		if (!refined) continue;
		if (models.band_midline)
			centreOnBand(bgr, *refined, camera, thr, frame_ratio, fill_ratio, opt.subpixel);
		tm.subpixel_us += microsSince(t);
		++res.counts.fitted;

		// 8. Code cells through the corners' homography.
		const auto code =
			readCode(bgr, *refined, camera, geometry, opt.code, opt.components.frame_blur_px);
		tm.code_us += microsSince(t);
		if (debug) dbg.quads.push_back(*refined);
		if (!code) continue;

		DetectedLandmark d;
		d.detection.id = code->id;
		d.detection.corners = refined->corners_raw;
		auto& qual = d.detection.quality;
		double var_end = 0;
		for (int k = 0; k < 4; ++k)
		{
			qual.line_rms_px[k] = refined->sides[k].rms_px;
			qual.line_support[k] = refined->sides[k].support;
			// A line fitted to n evenly spread points is 2 sigma / sqrt(n)
			// uncertain at its ends.
			var_end += 4 * refined->sides[k].rms_px * refined->sides[k].rms_px /
					   std::max(1, refined->sides[k].support);
		}
		qual.corner_sigma_px = std::sqrt(var_end / 4);
		qual.fill_clipped = refined->fill_clipped;
		qual.edge_bend_px = refined->bend_px;
		qual.edge_bend_se_px = refined->bend_se_px;
		qual.image_noise_grey =
			landmarkNoiseRms(bgr, refined->corners_raw, codeCellRatio(fill_ratio));
		qual.code_margin = code->margin;
		const auto& c = refined->corners_ideal;
		double area2 = 0;
		for (int k = 0; k < 4; ++k)
			area2 += c[k].x() * c[(k + 1) % 4].y() - c[(k + 1) % 4].x() * c[k].y();
		qual.area_px = 0.5 * std::abs(area2);
		d.P = primaryMeasurementFromIdeal(refined->corners_ideal, camera);
		// A fill split into two components gives the same landmark twice:
		// keep the one with the larger code margin.
		bool duplicate = false;
		for (auto& other : res.landmarks)
			if (meanCornerDistance(d.detection.corners, other.detection.corners) < 2.0)
			{
				duplicate = true;
				if (d.detection.quality.code_margin > other.detection.quality.code_margin)
					other = d;
			}
		if (!duplicate) res.landmarks.push_back(d);
	}
	std::sort(
		res.landmarks.begin(), res.landmarks.end(),
		[](const auto& a, const auto& b) { return a.detection.id < b.detection.id; });
	res.counts.decoded = static_cast<int>(res.landmarks.size());
	tm.total_us = std::chrono::duration<double, std::micro>(Clock::now() - t_start).count();

	if (debug)
	{
		dbg.mask = mask;
		dbg.labels = labels;
		dbg.step = opt.segmentation.step_px;
		dbg.candidates = candidates;
		writeDebugImages(debug_dir, bgr, dbg, res.landmarks);
	}
	return res;
}

}  // namespace codemark::detect
