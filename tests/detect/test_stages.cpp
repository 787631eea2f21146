// Each stage of the detector on small crafted inputs.
#include <codemark/detect/detector.h>
#include <codemark/landmark/codebook.h>

#include "stages.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <optional>
#include <random>
#include <utility>

using namespace codemark;
using namespace codemark::detect;

namespace
{
const cv::Scalar kBlack(25, 25, 25), kGreen(0, 255, 0), kWhite(235, 235, 235);

/** An axis-aligned landmark drawn with whole pixels: outer frame pixels
 * [o, o + 100), inner [o + 10, o + 90), so the inner corners lie at
 * o + 9.5 and o + 89.5; cells of 15 px. */
cv::Mat craftedLandmark(int id, int o = 40, double blur = 0.8, int size = 180)
{
	// Drawn twice as fine and averaged over each pixel: the board's cells
	// start half-way into a pixel.
	cv::Mat fine(2 * size, 2 * size, CV_8UC3, kWhite);
	cv::rectangle(fine, cv::Rect(2 * o, 2 * o, 200, 200), kBlack, cv::FILLED);
	cv::rectangle(fine, cv::Rect(2 * o + 20, 2 * o + 20, 160, 160), kGreen, cv::FILLED);
	const CodeCells cells = encodeId(id);
	// Board: 45 px centred in the 80 px fill: cells start at o + 10 + 17.5.
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
			if (cells[r][c])
				cv::rectangle(
					fine, cv::Rect(2 * o + 55 + 30 * c, 2 * o + 55 + 30 * r, 30, 30), kBlack,
					cv::FILLED);
	cv::Mat img;
	cv::resize(fine, img, cv::Size(size, size), 0, 0, cv::INTER_AREA);
	if (blur > 0) cv::GaussianBlur(img, img, cv::Size(0, 0), blur);
	return img;
}

/** A landmark (ID 0) whose reference square spans \a side px, printed with
 * the fill, frame and sheet levels given (BGR), under a Gaussian blur of
 * \a blur px: drawn 8 times finer, blurred there and averaged over each
 * pixel (so the total blur is a little wider than \a blur). The reference
 * square's corners lie at o - 0.5 and o + side - 0.5. */
cv::Mat printedLandmark(
	int side, const cv::Scalar& fill, const cv::Scalar& frame, const cv::Scalar& sheet, double blur,
	int o = 30, int size = 100)
{
	const int k = 8;
	const double inner = side * k, at = o * k;
	const double f = inner * 20 / 160, cell = inner * 30 / 160, board = at + inner / 2 - 1.5 * cell;
	cv::Mat fine(size * k, size * k, CV_8UC3, sheet);
	const auto box = [&](double x, double y, double w, const cv::Scalar& c) {
		cv::rectangle(
			fine, cv::Rect(cvRound(x), cvRound(y), cvRound(w), cvRound(w)), c, cv::FILLED);
	};
	box(at - f, at - f, inner + 2 * f, frame);
	box(at, at, inner, fill);
	box(board + cell, board + cell, cell, frame);  // the centre cell: ID 0
	if (blur > 0) cv::GaussianBlur(fine, fine, cv::Size(0, 0), blur * k);
	cv::Mat img;
	cv::resize(fine, img, cv::Size(size, size), 0, 0, cv::INTER_AREA);
	return img;
}

std::array<Eigen::Vector2d, 4> craftedCorners(int o = 40)
{
	const double a = o + 9.5, b = o + 89.5;
	return {
		Eigen::Vector2d(a, a), Eigen::Vector2d(b, a), Eigen::Vector2d(b, b), Eigen::Vector2d(a, b)};
}
}  // namespace

// ------------------------------------------------------------ segmentation

TEST(Segmentation, PredicateAcceptsGreensAndRejectsOthers)
{
	const SegmentationParams p;
	EXPECT_TRUE(isFillColour(0, 255, 0, p));
	EXPECT_TRUE(isFillColour(0, 77, 0, p));	 // gain 0.3
	EXPECT_TRUE(isFillColour(20, 200, 40, p));
	EXPECT_FALSE(isFillColour(128, 128, 128, p));  // grey
	EXPECT_FALSE(isFillColour(235, 235, 235, p));  // white
	EXPECT_FALSE(isFillColour(5, 9, 5, p));	 // black: too dark
	EXPECT_FALSE(isFillColour(200, 40, 30, p));	 // red
	EXPECT_FALSE(isFillColour(30, 40, 200, p));	 // blue
	EXPECT_FALSE(isFillColour(0, 220, 230, p));	 // yellow-green? no: cyan-ish (B > G)
	EXPECT_FALSE(isFillColour(230, 240, 0, p));	 // yellow: hue ~62 deg
	EXPECT_FALSE(isFillColour(150, 190, 150, p));  // pale green: low saturation
}

TEST(Segmentation, MaskHasGridSizeAndMarksTheFill)
{
	const cv::Mat img = craftedLandmark(0, 40, 0);
	SegmentationParams p;
	const cv::Mat m = segmentColour(img, p);
	ASSERT_EQ(m.rows, img.rows / 2);
	ASSERT_EQ(m.cols, img.cols / 2);
	// Cell (i, j) is pixel (2j, 2i): fill at pixel 55, frame at 45, white at 10.
	EXPECT_EQ(m.at<uint8_t>(28, 28), 255);
	EXPECT_EQ(m.at<uint8_t>(22, 22), 0);
	EXPECT_EQ(m.at<uint8_t>(5, 5), 0);
	p.step_px = 1;
	p.box_smoothing = true;
	EXPECT_EQ(segmentColour(img, p).size(), img.size());
}

TEST(Segmentation, GridMaskIsThePredicateOnEveryCell)
{
	// The default step-2 mask runs in SIMD over blocks of 16 cells (32 with
	// AVX2) and in scalar code over the rest of a row: every path must be
	// the predicate, cell by cell, for any colour and any width.
	cv::RNG rng(7);
	for (const cv::Size size : {cv::Size(640, 48), cv::Size(67, 33), cv::Size(31, 9)})
		for (const int step : {1, 2, 3})
			for (const SimdPath path : {SimdPath::Best, SimdPath::Baseline, SimdPath::Scalar})
			{
				cv::Mat img(size, CV_8UC3);
				rng.fill(img, cv::RNG::UNIFORM, 0, 256);
				// Half the pixels near green, where the predicate's bounds are.
				for (int y = 0; y < img.rows; ++y)
					for (int x = 0; x < img.cols; x += 2)
					{
						auto& px = img.at<cv::Vec3b>(y, x);
						px[1] = cv::saturate_cast<uint8_t>(
							std::max(px[0], px[2]) + rng.uniform(-5, 60));
					}
				SegmentationParams p;
				p.step_px = step;
				const cv::Mat m = segmentColour(img, p, path);
				int fill = 0;
				for (int i = 0; i < m.rows; ++i)
					for (int j = 0; j < m.cols; ++j)
					{
						const auto& px = img.at<cv::Vec3b>(i * step, j * step);
						const bool want = isFillColour(px[2], px[1], px[0], p);
						ASSERT_EQ(m.at<uint8_t>(i, j) != 0, want)
							<< size << " step " << step << " path " << static_cast<int>(path)
							<< " cell " << i << "," << j;
						fill += want;
					}
				EXPECT_GT(fill, 0);
			}
}

TEST(Segmentation, TinyAndEmptyImagesGiveAnEmptyMask)
{
	const SegmentationParams p;
	EXPECT_TRUE(segmentColour(cv::Mat(0, 0, CV_8UC3), p).empty());
	EXPECT_TRUE(segmentColour(cv::Mat(1, 1, CV_8UC3, kGreen), p).empty());
	EXPECT_THROW(segmentColour(cv::Mat(4, 4, CV_8UC1), p), std::invalid_argument);
}

// -------------------------------------------------------------- components

TEST(Components, HandMadeMask)
{
	cv::Mat mask = cv::Mat::zeros(60, 80, CV_8UC1);
	cv::rectangle(mask, cv::Rect(10, 10, 20, 20), 255, cv::FILLED);	 // a square
	cv::rectangle(mask, cv::Rect(40, 5, 1, 50), 255, cv::FILLED);  // a thin line
	cv::rectangle(mask, cv::Rect(75, 55, 2, 2), 255, cv::FILLED);  // a speck
	// Touching diagonally only: a separate component under N4.
	cv::rectangle(mask, cv::Rect(50, 30, 10, 10), 255, cv::FILLED);
	cv::rectangle(mask, cv::Rect(60, 40, 10, 10), 255, cv::FILLED);
	const cv::Mat img(120, 160, CV_8UC3, kGreen);
	ComponentParams p;
	p.max_frame_ratio = 1;	// no frame in this image: frame evidence off
	cv::Mat labels;
	int n = 0;
	const auto c = findCandidates(mask, 2, img, p, &labels, &n);
	EXPECT_EQ(n, 5);
	EXPECT_NE(labels.at<int>(39, 59), labels.at<int>(40, 60));
	// The line is too elongated, the speck too small: the square and the two
	// small squares remain, largest first.
	ASSERT_EQ(c.size(), 3u);
	EXPECT_EQ(c[0].bbox, cv::Rect(20, 20, 40, 40));
	EXPECT_NEAR(c[0].centroid.x(), 39.5, 1e-9);
	EXPECT_NEAR(c[0].centroid.y(), 39.5, 1e-9);
	EXPECT_NEAR(c[0].compactness, 1.0 / 6, 1e-3);
	EXPECT_NEAR(c[0].elongation, 1.0, 1e-6);
	EXPECT_NEAR(c[0].area_px, 1600, 1e-9);
	EXPECT_NEAR(c[0].fill_g, 255, 1e-9);
	EXPECT_TRUE(c[0].roi.contains(cv::Point(20 - 10, 20 - 10)));
	EXPECT_TRUE(cv::Rect(0, 0, 160, 120).contains(c[0].roi.br() - cv::Point(1, 1)));
}

TEST(Components, LabelsAreOpenCvsFourConnectedComponents)
{
	// Random blobs and specks, runs of every length, some touching the
	// mask's last column and row (the word-wise scans' ends): the same
	// partition of the cells as cv::connectedComponents with N4.
	cv::Mat mask = cv::Mat::zeros(73, 101, CV_8UC1);
	std::mt19937 rng(3);
	std::uniform_int_distribution<int> x(0, 100), y(0, 72), w(1, 30);
	for (int k = 0; k < 40; ++k)
		cv::rectangle(mask, cv::Rect(x(rng), y(rng), w(rng), w(rng) / 3 + 1), 255, cv::FILLED);
	for (int k = 0; k < 300; ++k) mask.at<uint8_t>(y(rng), x(rng)) = 1;
	const cv::Mat img(146, 202, CV_8UC3, kGreen);
	cv::Mat labels, reference;
	int n = 0;
	findCandidates(mask, 2, img, ComponentParams(), &labels, &n);
	const int n_ref = cv::connectedComponents(mask != 0, reference, 4, CV_32S) - 1;
	ASSERT_GT(n_ref, 50);
	EXPECT_EQ(n, n_ref);
	// One label of ours per reference component and back.
	std::vector<int> ours_of(n_ref + 1, -1), ref_of(n + 1, -1);
	int mismatches = 0;
	for (int r = 0; r < mask.rows; ++r)
		for (int c = 0; c < mask.cols; ++c)
		{
			const int a = labels.at<int>(r, c), b = reference.at<int>(r, c);
			if ((a == 0) != (b == 0))
			{
				++mismatches;
				continue;
			}
			if (a == 0 || a > n || b > n_ref) continue;
			if (ours_of[b] < 0) ours_of[b] = a;
			if (ref_of[a] < 0) ref_of[a] = b;
			mismatches += ours_of[b] != a || ref_of[a] != b;
		}
	EXPECT_EQ(mismatches, 0);
}

TEST(Components, ARingIsCompactEnoughAndALShapeIsNot)
{
	cv::Mat mask = cv::Mat::zeros(100, 100, CV_8UC1);
	cv::rectangle(mask, cv::Rect(10, 10, 32, 32), 255, cv::FILLED);
	cv::rectangle(mask, cv::Rect(17, 17, 18, 18), 0, cv::FILLED);  // an all-black board (90/160)
	cv::rectangle(mask, cv::Rect(50, 50, 45, 3), 255, cv::FILLED);	// a thin L
	cv::rectangle(mask, cv::Rect(50, 50, 3, 45), 255, cv::FILLED);
	const cv::Mat img(200, 200, CV_8UC3, kGreen);
	ComponentParams p;
	p.max_frame_ratio = 1;
	const auto c = findCandidates(mask, 2, img, p);
	ASSERT_EQ(c.size(), 1u);
	EXPECT_NEAR(c[0].compactness, 0.32, 0.03);
}

TEST(Components, FrameEvidence)
{
	// The crafted landmark has its frame; the same fill on grey or on white
	// has none.
	const cv::Mat lm = craftedLandmark(0);
	EXPECT_EQ(
		findCandidates(segmentColour(lm, SegmentationParams()), 2, lm, ComponentParams()).size(),
		1u);
	for (const cv::Scalar& bg : {cv::Scalar(128, 128, 128), kWhite})
	{
		cv::Mat img(180, 180, CV_8UC3, bg);
		cv::rectangle(img, cv::Rect(50, 50, 80, 80), kGreen, cv::FILLED);
		EXPECT_TRUE(
			findCandidates(segmentColour(img, SegmentationParams()), 2, img, ComponentParams())
				.empty());
	}
}

TEST(Frame, TheInkOfABlurredBar)
{
	// A black bar between a fill and a sheet, blurred (sigma 1.5 px) and
	// integrated over pixels: its middle reads lighter than its ink, more the
	// thinner it is; unblurredFrameLevel() gives the ink back.
	const double ink = 40, fill = 160, sheet = 220, blur = 1.5;
	for (const int width : {3, 4, 6, 10})
	{
		const int k = 16, w = 60;
		cv::Mat fine(1, w * k, CV_64F, cv::Scalar(fill));
		fine.colRange(20 * k, (20 + width) * k).setTo(ink);
		fine.colRange((20 + width) * k, w * k).setTo(sheet);
		// The pixel's own width adds a box blur of variance 1/12.
		cv::GaussianBlur(
			fine, fine, cv::Size(0, 0), std::sqrt(blur * blur - 1.0 / 12) * k, 0,
			cv::BORDER_REPLICATE);
		cv::Mat px;
		cv::resize(fine, px, cv::Size(w, 1), 0, 0, cv::INTER_AREA);
		// Pixel 20 + x covers [20 + x, 21 + x): the bar's middle is at
		// 20 + width / 2, i.e. at pixel index 19.5 + width / 2.
		const double mid = 19.5 + 0.5 * width;
		const auto at = [&](double x)
		{
			const int i = static_cast<int>(std::floor(x));
			const double t = x - i;
			return (1 - t) * px.at<double>(0, i) + t * px.at<double>(0, i + 1);
		};
		double band = 0;  // the code stage's samples: the middle half
		for (int i = -2; i <= 2; ++i) band += at(mid + 0.25 * width * i / 2.0) / 5;
		const double middle = at(mid);
		const double middle_ink =
			unblurredFrameLevel(middle, fill, sheet, frameNeighbourShare(width, blur));
		const double band_ink =
			unblurredFrameLevel(band, fill, sheet, frameNeighbourShare(width, blur, 0.25));
		// Within a few levels (the bilinear reads between pixels blur a
		// little more).
		EXPECT_NEAR(middle_ink, ink, 5.0) << width;
		EXPECT_NEAR(band_ink, ink, 5.0) << width;
		if (width <= 4)
		{
			EXPECT_GT(band - ink, 25) << width;	 // what the correction undoes
		}
	}
	// Wide frames need none; frames under two blur widths get none (their
	// depth depends on the actual blur more than on the ink).
	EXPECT_LT(frameNeighbourShare(20, 1.5), 1e-9);
	EXPECT_GT(frameNeighbourShare(3, 1.5), 0.15);
	EXPECT_EQ(frameNeighbourShare(2.9, 1.5), 0);
	EXPECT_EQ(frameNeighbourShare(4, 0), 0);
}

TEST(Components, FrameEvidenceOfAThinFrame)
{
	// A dim laser print (fill G 107, toner G 70, sheet G 140) at 32 px: its
	// 4 px frame reads about 0.75 of the fill under a 1.5 px blur, its ink
	// 0.65. The frame check compares the ink: found; a grey frame (G 95) is
	// still refused.
	const cv::Scalar fill(40, 107, 50), toner(70, 70, 70), grey(95, 95, 95), sheet(140, 140, 140);
	const cv::Mat dim = printedLandmark(32, fill, toner, sheet, 1.5);
	const cv::Mat mask = segmentColour(dim, SegmentationParams());
	ComponentParams p;
	EXPECT_EQ(findCandidates(mask, 2, dim, p).size(), 1u);
	ComponentParams as_read = p;
	as_read.frame_blur_px = 0;
	EXPECT_TRUE(findCandidates(mask, 2, dim, as_read).empty());
	const cv::Mat greyed = printedLandmark(32, fill, grey, sheet, 1.5);
	EXPECT_TRUE(findCandidates(segmentColour(greyed, SegmentationParams()), 2, greyed, p).empty());
	// At 80 px the frame (10 px) reads its ink with or without the model.
	const cv::Mat near = printedLandmark(80, fill, toner, sheet, 1.5, 30, 160);
	const cv::Mat near_mask = segmentColour(near, SegmentationParams());
	EXPECT_EQ(findCandidates(near_mask, 2, near, p).size(), 1u);
	EXPECT_EQ(findCandidates(near_mask, 2, near, as_read).size(), 1u);
}

TEST(Components, CentreEvidence)
{
	// ID 0: only the centre cell is black. With it green the fill is solid:
	// rejected before the gradients once the cell (15 px here) is large
	// enough to open a hole in the mask; kept with the test off.
	const cv::Mat lm = craftedLandmark(0);
	EXPECT_EQ(
		findCandidates(segmentColour(lm, SegmentationParams()), 2, lm, ComponentParams()).size(),
		1u);
	cv::Mat solid = craftedLandmark(0, 40, 0);
	cv::rectangle(solid, cv::Rect(40 + 27 + 15, 40 + 27 + 15, 16, 16), kGreen, cv::FILLED);
	cv::GaussianBlur(solid, solid, cv::Size(0, 0), 0.8);
	const cv::Mat m = segmentColour(solid, SegmentationParams());
	EXPECT_TRUE(findCandidates(m, 2, solid, ComponentParams()).empty());
	ComponentParams off;
	off.min_centre_cell_px = 0;
	EXPECT_EQ(findCandidates(m, 2, solid, off).size(), 1u);
	// A small solid fill (centre cell estimate under min_centre_cell_px) is
	// left to the later stages.
	ComponentParams coarse;
	coarse.min_centre_cell_px = 11;
	EXPECT_EQ(findCandidates(m, 2, solid, coarse).size(), 1u);
}

// ------------------------------------------------------------------ edgels

TEST(Edgels, ReducedGreenIsTheBlocksRoundedMean)
{
	// Random levels (every rounding case) in a ROI off the image's origin;
	// each factor, the unrolled ones and the general loop: the block's mean
	// rounded half up, and cv::resize(INTER_AREA) to a grey level (it
	// rounds some ties down).
	cv::Mat bgr(97, 131, CV_8UC3);
	cv::RNG rng(5);
	rng.fill(bgr, cv::RNG::UNIFORM, 0, 256);
	for (int k = 2; k <= 6; ++k)
	{
		const cv::Rect roi(3, 5, 120 - 120 % k, 90 - 90 % k);
		const cv::Mat got = reducedGreen(bgr, roi, k);
		ASSERT_EQ(got.size(), cv::Size(roi.width / k, roi.height / k)) << "k = " << k;
		int worst = 0;
		for (int y = 0; y < got.rows; ++y)
			for (int x = 0; x < got.cols; ++x)
			{
				int sum = 0;
				for (int r = 0; r < k; ++r)
					for (int c = 0; c < k; ++c)
						sum += bgr.at<cv::Vec3b>(roi.y + y * k + r, roi.x + x * k + c)[1];
				const int mean = static_cast<int>(std::floor(double(sum) / (k * k) + 0.5));
				worst = std::max(worst, std::abs(got.at<uint8_t>(y, x) - mean));
			}
		EXPECT_EQ(worst, 0) << "k = " << k;
		cv::Mat g, area;
		cv::extractChannel(bgr(roi), g, 1);
		cv::resize(g, area, got.size(), 0, 0, cv::INTER_AREA);
		EXPECT_LE(cv::norm(got, area, cv::NORM_INF), 1) << "k = " << k;
	}
}

TEST(Edgels, PolarityOfTheInnerEdges)
{
	const cv::Mat img = craftedLandmark(0);
	EdgelParams full;
	full.max_roi_px = 1000;	 // no reduction
	const auto m = findEdgels(img, cv::Rect(20, 20, 140, 140), 10, full);
	ASSERT_EQ(m.scale, 1);
	// Inner left edge between pixels 49 and 50: G rises to the right.
	EXPECT_EQ(
		m.polarity.at<uint8_t>(90 - 20, 49 - 20) | m.polarity.at<uint8_t>(90 - 20, 50 - 20),
		static_cast<uint8_t>(Polarity::Left));
	EXPECT_EQ(
		m.polarity.at<uint8_t>(90 - 20, 129 - 20) | m.polarity.at<uint8_t>(90 - 20, 130 - 20),
		static_cast<uint8_t>(Polarity::Right));
	EXPECT_EQ(
		m.polarity.at<uint8_t>(49 - 20, 90 - 20) | m.polarity.at<uint8_t>(50 - 20, 90 - 20),
		static_cast<uint8_t>(Polarity::Top));
	EXPECT_EQ(
		m.polarity.at<uint8_t>(129 - 20, 90 - 20) | m.polarity.at<uint8_t>(130 - 20, 90 - 20),
		static_cast<uint8_t>(Polarity::Bottom));
	// Non-maximum suppression: one edgel across the edge.
	int across = 0;
	for (int x = 44; x <= 56; ++x)
		across += m.polarity.at<uint8_t>(70, x - 20) == static_cast<uint8_t>(Polarity::Left);
	EXPECT_EQ(across, 1);
	// A long slim domain of each polarity.
	for (const Polarity pol : {Polarity::Top, Polarity::Right, Polarity::Bottom, Polarity::Left})
	{
		double longest = 0;
		for (const auto& d : m.domains)
			if (d.polarity == pol && d.width_px < 1) longest = std::max(longest, d.length_px);
		EXPECT_GT(longest, 60) << static_cast<int>(pol);
	}
	// A large ROI is reduced (here by 2) but domains stay in image pixels:
	// the left inner edge lies at u = 49.5.
	const auto r = findEdgels(img, cv::Rect(20, 20, 140, 140), 10, EdgelParams());
	ASSERT_EQ(r.scale, 2);
	bool left_found = false;
	for (const auto& d : r.domains)
		if (d.polarity == Polarity::Left && d.length_px > 60 &&
			d.mean.x() < 90)  // not the outer right edge
		{
			EXPECT_NEAR(d.mean.x(), 49.5, 1.0);
			EXPECT_NEAR(d.mean.y(), 89.5, 3.0);
			left_found = true;
		}
	EXPECT_TRUE(left_found);
}

TEST(Edgels, DomainsAreTheEightConnectedEdgelsOfEachPolarity)
{
	// A landmark and random bars and specks of other levels: every domain
	// is an 8-connected component of one polarity's edgels in the map
	// (cv::connectedComponentsWithStats, one polarity at a time), with its
	// edgel count and centroid, and every component of at least
	// min_edgels edgels is a domain.
	cv::Mat img = craftedLandmark(77);
	std::mt19937 rng(9);
	std::uniform_int_distribution<int> at(0, 170), len(2, 40), level(0, 255);
	for (int k = 0; k < 30; ++k)
		cv::rectangle(
			img, cv::Rect(at(rng), at(rng), len(rng), len(rng) / 4 + 1),
			cv::Scalar(level(rng), level(rng), level(rng)), cv::FILLED);
	cv::GaussianBlur(img, img, cv::Size(0, 0), 0.7);
	EdgelParams full;
	full.max_roi_px = 1000;	 // no reduction: the map's pixels are the image's
	const cv::Rect roi(7, 11, 160, 150);
	const auto m = findEdgels(img, roi, 6, full);
	ASSERT_EQ(m.scale, 1);
	size_t expected = 0;
	int unmatched = 0;
	for (const Polarity pol : {Polarity::Top, Polarity::Right, Polarity::Bottom, Polarity::Left})
	{
		cv::Mat labels, stats, centroids;
		const int n = cv::connectedComponentsWithStats(
			m.polarity == static_cast<uint8_t>(pol), labels, stats, centroids, 8, CV_32S);
		for (int l = 1; l < n; ++l)
		{
			const int count = stats.at<int>(l, cv::CC_STAT_AREA);
			if (count < full.min_edgels) continue;
			++expected;
			const Eigen::Vector2d mean(
				roi.x + centroids.at<double>(l, 0), roi.y + centroids.at<double>(l, 1));
			unmatched += std::none_of(
				m.domains.begin(), m.domains.end(),
				[&](const EdgelDomain& d)
				{ return d.polarity == pol && d.count == count && (d.mean - mean).norm() < 1e-9; });
		}
	}
	EXPECT_GT(expected, 20u);
	EXPECT_EQ(m.domains.size(), expected);
	EXPECT_EQ(unmatched, 0);
}

TEST(Edgels, FlatImageHasNone)
{
	const cv::Mat img(50, 50, CV_8UC3, kGreen);
	EXPECT_TRUE(findEdgels(img, cv::Rect(0, 0, 50, 50), 5, EdgelParams()).domains.empty());
	EXPECT_TRUE(findEdgels(img, cv::Rect(48, 48, 10, 10), 5, EdgelParams()).domains.empty());
}

// ------------------------------------------------- segments and quadrangle

namespace
{
std::optional<Quad> coarseQuad(const cv::Mat& img)
{
	const cv::Mat mask = segmentColour(img, SegmentationParams());
	const auto cands = findCandidates(mask, 2, img, ComponentParams());
	if (cands.size() != 1) return std::nullopt;
	const auto m = findEdgels(
		img, cands[0].roi, gradientThreshold(cands[0].fill_g, EdgelParams()), EdgelParams());
	const auto s = selectSegments(m.domains, cands[0], mask, 2, SegmentParams());
	if (!s) return std::nullopt;
	return linkQuadrangle(*s, QuadParams());
}
}  // namespace

TEST(Quadrangle, CoarseCornersOfACraftedLandmark)
{
	for (int id : {0, 255, 0x5A})
	{
		const auto q = coarseQuad(craftedLandmark(id));
		ASSERT_TRUE(q) << id;
		const auto truth = craftedCorners();
		for (int k = 0; k < 4; ++k)
			EXPECT_LT(((*q)[k] - truth[k]).norm(), 1.5) << id << " corner " << k;
	}
}

TEST(Quadrangle, GreenSquareOnBlackGivesAQuadrangle)
{
	// A green square on black: the four edges have the inner polarities, so
	// a quadrangle is found; the code stage rejects it (its centre is green).
	cv::Mat img(100, 100, CV_8UC3, kBlack);
	cv::rectangle(img, cv::Rect(20, 20, 60, 60), kGreen, cv::FILLED);
	EXPECT_TRUE(coarseQuad(img));
}

namespace
{
/** A straight domain of polarity \a pol from \a a to \a b, one edgel a
 * pixel. */
EdgelDomain domain(Polarity pol, const Eigen::Vector2d& a, const Eigen::Vector2d& b)
{
	EdgelDomain d;
	d.polarity = pol;
	d.end0 = a;
	d.end1 = b;
	d.mean = 0.5 * (a + b);
	d.dir = (b - a).normalized();
	d.length_px = (b - a).norm();
	d.count = static_cast<int>(d.length_px) + 1;
	return d;
}
}  // namespace

TEST(Segments, AShortGhostBesideTheInnerEdgeDoesNotReplaceIt)
{
	// The fill's box spans [20, 52) both ways. Each side has its inner edge
	// spanning the side; below, a piece of ghost edge 16 px long lies 2 px
	// nearer the box's side than the inner edge (as a sharpened or dim side
	// leaves one): the side is the inner edge, whose ends reach the corners.
	Candidate c;
	c.bbox = cv::Rect(20, 20, 32, 32);
	c.centroid = Eigen::Vector2d(35.5, 35.5);
	std::vector<EdgelDomain> domains{
		domain(Polarity::Top, {21, 20.5}, {50, 20.5}),
		domain(Polarity::Right, {50.5, 21}, {50.5, 50}),
		domain(Polarity::Bottom, {21, 49.5}, {50, 49.5}),
		domain(Polarity::Left, {20.5, 21}, {20.5, 50}),
		domain(Polarity::Bottom, {35, 51.5}, {50, 51.5})};
	const auto s = selectSegments(domains, c, cv::Mat(), 2, SegmentParams());
	ASSERT_TRUE(s);
	EXPECT_NEAR((*s)[2].mean.y(), 49.5, 1e-9);
	EXPECT_NEAR((*s)[2].length_px, 29, 1e-9);
	EXPECT_TRUE(linkQuadrangle(*s, QuadParams()));
	// A long edge a fifth of the side inside (a code cell's row) is not the
	// side either: the nearest qualified domain is.
	domains.pop_back();
	domains.push_back(domain(Polarity::Bottom, {21, 43}, {50, 43}));
	const auto t = selectSegments(domains, c, cv::Mat(), 2, SegmentParams());
	ASSERT_TRUE(t);
	EXPECT_NEAR((*t)[2].mean.y(), 49.5, 1e-9);
}

TEST(Segments, AGreenTintedWallIsNotTheFill)
{
	// A dim print (fill G 107) on a grey wall that the white balance tints
	// green (G 60, R = B = 50) next to it, darker beyond. The codec smeared
	// the green over the thin frame, so the fill's box reaches past the
	// frame and the tinted wall's edge is the right-side domain nearest it;
	// inside that edge the image is green-ish but not saturated: the inner
	// edge is the side.
	cv::Mat img(90, 90, CV_8UC3, cv::Scalar(30, 35, 30));
	cv::rectangle(img, cv::Rect(10, 10, 56, 56), cv::Scalar(50, 60, 50), cv::FILLED);
	cv::rectangle(img, cv::Rect(16, 16, 40, 40), kBlack, cv::FILLED);
	cv::rectangle(img, cv::Rect(20, 20, 32, 32), cv::Scalar(40, 107, 50), cv::FILLED);
	Candidate c;
	c.bbox = cv::Rect(20, 20, 44, 32);
	c.centroid = Eigen::Vector2d(35.5, 35.5);
	c.fill_g = 107;
	const std::vector<EdgelDomain> domains{
		domain(Polarity::Top, {21, 19.5}, {50, 19.5}),
		domain(Polarity::Right, {51.5, 21}, {51.5, 50}),
		domain(Polarity::Bottom, {21, 51.5}, {50, 51.5}),
		domain(Polarity::Left, {19.5, 21}, {19.5, 50}),
		domain(Polarity::Right, {65.5, 12}, {65.5, 64})};
	const auto s = selectSegments(domains, c, cv::Mat(), 2, SegmentParams(), &img);
	ASSERT_TRUE(s);
	EXPECT_NEAR((*s)[1].mean.x(), 51.5, 1e-9);
}

TEST(Quadrangle, RejectsSegmentsFarFromTheirCorners)
{
	SideSegments s;
	const Eigen::Vector2d c[4] = {{10, 10}, {50, 10}, {50, 50}, {10, 50}};
	for (int k = 0; k < 4; ++k)
	{
		s[k].mean = 0.5 * (c[k] + c[(k + 1) % 4]);
		s[k].dir = (c[(k + 1) % 4] - c[k]).normalized();
		s[k].end0 = c[k] + 2 * s[k].dir;
		s[k].end1 = c[(k + 1) % 4] - 2 * s[k].dir;
	}
	const auto q = linkQuadrangle(s, QuadParams());
	ASSERT_TRUE(q);
	for (int k = 0; k < 4; ++k) EXPECT_LT(((*q)[k] - c[k]).norm(), 1e-9);
	s[0].end0 = c[0] + 30 * s[0].dir;  // a short top segment far from TL
	EXPECT_FALSE(linkQuadrangle(s, QuadParams()));
}

// ---------------------------------------------------------------- sub-pixel

namespace
{
/** A step from 30 to 230 at \a x0 sampled at integers, blurred by a
 * Gaussian of \a sigma (exact, via erf) and integrated over each pixel
 * (numerically). */
std::vector<int> stepProfile(double x0, double sigma, int n, double hi = 230)
{
	std::vector<int> v(n);
	for (int i = 0; i < n; ++i)
	{
		double s = 0;
		constexpr int kSub = 64;
		for (int k = 0; k < kSub; ++k)
		{
			const double x = i - 0.5 + (k + 0.5) / kSub;
			s += sigma > 0 ? 0.5 * (1 + std::erf((x - x0) / (std::sqrt(2.0) * sigma)))
						   : (x > x0 ? 1.0 : 0.0);
		}
		v[i] = static_cast<int>(std::lround(std::min(255.0, 30 + (hi - 30) * s / kSub)));
	}
	return v;
}
}  // namespace

TEST(Subpixel, PixelStepIsTheIntegratedBlurredStep)
{
	// A unit step at 0 blurred by sigma, integrated over the pixel [x - 1/2,
	// x + 1/2]: sigma (F(z+) - F(z-)), F(z) = z Phi(z) + phi(z), from
	// std::erfc here; pixelSteps() interpolates a table. Its derivatives in
	// x and sigma against central differences of the exact value.
	const auto exact = [](double x, double sigma)
	{
		const auto F = [](double z) {
			return z * 0.5 * std::erfc(-z / std::sqrt(2.0)) +
				   std::exp(-0.5 * z * z) / std::sqrt(2 * M_PI);
		};
		return sigma * (F((x + 0.5) / sigma) - F((x - 0.5) / sigma));
	};
	std::mt19937 rng(3);
	std::uniform_real_distribution<double> ux(-12, 12), us(0.05, 3);
	for (int t = 0; t < 20000; ++t)
	{
		const double x = ux(rng), sigma = us(rng), h = 1e-5;
		const PixelStep s = pixelStep(x, sigma);
		ASSERT_NEAR(s.value, exact(x, sigma), 2e-8) << x << " " << sigma;
		ASSERT_NEAR(s.d_x, (exact(x + h, sigma) - exact(x - h, sigma)) / (2 * h), 2e-6);
		ASSERT_NEAR(s.d_sigma, (exact(x, sigma + h) - exact(x, sigma - h)) / (2 * h), 2e-6);
	}
	// Five neighbouring samples share their boundaries: the same values.
	std::array<PixelStep, 5> st;
	pixelSteps(-2.3, 0.7, 5, st.data());
	for (int i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(st[i].value, pixelStep(-2.3 + i, 0.7).value);
	// At arbitrary positions with one blur: the same steps.
	const double at[3] = {-4.1, 0.37, 2.9};
	std::array<PixelStep, 3> sa;
	pixelStepsAt(at, 3, 0.8, sa.data());
	for (int i = 0; i < 3; ++i)
	{
		const PixelStep one = pixelStep(at[i], 0.8);
		EXPECT_NEAR(sa[i].value, one.value, 1e-14);
		EXPECT_NEAR(sa[i].d_x, one.d_x, 1e-14);
		EXPECT_NEAR(sa[i].d_sigma, one.d_sigma, 1e-14);
	}
}

TEST(Subpixel, CentroidLocatesABlurredStep)
{
	const SubpixelParams p;
	for (double sigma : {0.0, 0.5, 0.8, 1.5})
		for (double x0 = 9.0; x0 < 10.0; x0 += 0.1)
		{
			const auto v = stepProfile(x0, sigma, 21);
			const auto e = locateRisingEdge(v.data(), 21, 7, 13, 5, p);
			ASSERT_TRUE(e);
			EXPECT_NEAR(*e, x0, 0.03) << "sigma " << sigma;
		}
}

TEST(Subpixel, PeakModeLocatesAGaussianBlurredStep)
{
	const SubpixelParams p;
	for (double x0 = 9.0; x0 < 10.0; x0 += 0.1)
	{
		const auto v = stepProfile(x0, 1.0, 21);
		const auto e = locateRisingEdge(v.data(), 21, 7, 13, 5, p, EdgeMode::Peak);
		ASSERT_TRUE(e);
		EXPECT_NEAR(*e, x0, 0.05);
	}
}

// The three samples around the derivative's peak fix a pixel-integrated
// Gaussian step exactly (stepPeak): on a sharp edge, where a Gaussian
// through them (the log-parabola) errs with the edge's phase in its pixel,
// and on blurred ones alike, down to the profile's 8-bit rounding.
TEST(Subpixel, PeakModeStepModelLocatesSharpAndBlurredSteps)
{
	const SubpixelParams p;
	for (double sigma : {0.0, 0.3, 0.5, 0.8, 1.2})
	{
		double worst_model = 0, worst_gauss = 0;
		for (double x0 = 9.0; x0 < 10.0; x0 += 0.05)
		{
			const auto v = stepProfile(x0, sigma, 21);
			const auto e = locateRisingEdge(v.data(), 21, 7, 13, 5, p, EdgeMode::Peak);
			const auto g = locateRisingEdge(v.data(), 21, 7, 13, 5, p, EdgeMode::PeakGaussian);
			ASSERT_TRUE(e && g);
			worst_model = std::max(worst_model, std::abs(*e - x0));
			worst_gauss = std::max(worst_gauss, std::abs(*g - x0));
		}
		std::printf(
			"sigma %.1f: worst %.4f px (Gaussian through the samples %.4f)\n", sigma, worst_model,
			worst_gauss);
		// At wide blur the three samples differ little and the profile's
		// rounding limits both (about 0.01 px at sigma 1.2).
		EXPECT_LE(worst_model, 0.012) << "sigma " << sigma;
		if (sigma <= 0.5)
		{
			EXPECT_GT(worst_gauss, 3 * worst_model) << "sigma " << sigma;
		}
	}
}

namespace
{
/** Noise-free sharp profiles, the frame at \a lo and the fill at \a hi
 * (real levels, rounded in each sample), the edge at e0 + slope j in
 * profile j of \a m, and their edges as locateRisingEdge() reads them. */
struct SharpSide
{
	std::vector<int> g, along;
	std::vector<int> origin;  // all 0: the across coordinate is the edge
	std::vector<std::optional<double>> edges;
};
SharpSide sharpSide(double lo, double hi, double e0, double slope, int m, int n, double noise = 0)
{
	SharpSide side;
	std::mt19937 rng(3);
	std::normal_distribution<double> gauss(0, noise);
	for (int j = 0; j < m; ++j)
	{
		for (int i = 0; i < n; ++i)
		{
			const double f = std::clamp(i + 0.5 - (e0 + slope * j), 0.0, 1.0);
			const double v = lo + (hi - lo) * f + (noise > 0 ? gauss(rng) : 0);
			side.g.push_back(static_cast<int>(std::clamp(std::lround(v), 0L, 255L)));
		}
		side.along.push_back(j);
		side.origin.push_back(0);
		side.edges.push_back(locateRisingEdge(
			side.g.data() + size_t(j) * n, n, 7, 13, 5, SubpixelParams(), EdgeMode::Peak));
	}
	return side;
}
/** The error of the slope of the least-squares line through the edges, as
 * a distance across the side [px]. */
double tiltError(const SharpSide& side, double slope)
{
	double sx = 0, sy = 0, sxx = 0, sxy = 0;
	const int m = static_cast<int>(side.edges.size());
	for (int j = 0; j < m; ++j)
	{
		sx += j;
		sy += *side.edges[j];
		sxx += double(j) * j;
		sxy += j * *side.edges[j];
	}
	return ((m * sxy - sx * sy) / (m * sxx - sx * sx) - slope) * (m - 1);
}
}  // namespace

// A noise-free sharp side's frame and fill levels are rounded once for all
// its profiles (22.4 and 229.6 read 22 and 230: the contrast is 0.8 levels
// too high), which tilts its line where the edge crosses a pixel boundary.
// correctLevelRounding() reads each edge from its mixed pixel exactly and
// fits that rounding with the line. Over frame and fill levels that round
// up and down, edges crossing a pixel boundary anywhere along the side, and
// slopes from near-aligned to steep, the line's tilt error falls (RMS) at
// every slope, by at least a tenth (near-aligned sides, where the edges
// cross few pixel boundaries, gain least). Noise, or two fill levels along
// the side, switch it off.
TEST(Subpixel, LevelRoundingOfANoiseFreeSharpSideIsFitted)
{
	constexpr int m = 60, n = 21;
	for (const double slope : {0.0005, 0.001, 0.002, 0.005, 0.01, 0.05})
	{
		double before = 0, after = 0;
		int cases = 0;
		for (const double lo : {22.4, 22.5001, 24.8})
			for (const double hi : {229.6, 229.4999, 231.3, 254.7})
				for (double at = 0.1; at < 0.95; at += 0.1)
				{
					SharpSide side = sharpSide(lo, hi, 10.5 - slope * m * at, slope, m, n);
					before += std::pow(tiltError(side, slope), 2);
					const auto c =
						correctLevelRounding(side.g, n, side.along, side.origin, 0, 1, side.edges);
					ASSERT_TRUE(c) << lo << " " << hi;
					EXPECT_LE(std::abs(*c), 1.0);
					after += std::pow(tiltError(side, slope), 2);
					++cases;
				}
		before = std::sqrt(before / cases);
		after = std::sqrt(after / cases);
		std::printf("edge slope %.4f: line tilt RMS %.4f -> %.4f px\n", slope, before, after);
		EXPECT_LT(after, 0.9 * before) << "slope " << slope;
	}
	// Noise: each profile's rounding is its own.
	{
		SharpSide side = sharpSide(22.4, 229.6, 10.2, 0.01, m, n, 1.0);
		EXPECT_FALSE(correctLevelRounding(side.g, n, side.along, side.origin, 0, 1, side.edges));
	}
	// The fill brighter along half of the side: two roundings.
	{
		SharpSide side = sharpSide(22.4, 229.6, 10.2, 0.01, m, n);
		const SharpSide other = sharpSide(22.4, 240.2, 10.2, 0.01, m, n);
		std::copy(other.g.begin() + (m / 2) * n, other.g.end(), side.g.begin() + (m / 2) * n);
		EXPECT_FALSE(correctLevelRounding(side.g, n, side.along, side.origin, 0, 1, side.edges));
	}
}

namespace
{
/** Noisy profiles across a thin frame as a camera sees the print: a grey
 * wall, the sheet's quiet margin (\a margin px), the black frame (\a frame
 * px), the green fill; blur 0.8 px, noise 2; the inner edge at 10 + slope j
 * in profile j of 60. */
void thinFrameProfiles(
	double frame, double margin, double slope, std::vector<int>& g, std::vector<double>& truth,
	int n)
{
	constexpr double W = 128, M = 235, K = 25, G = 240, sigma = 0.8;
	std::mt19937 rng(11);
	std::normal_distribution<double> noise(0, 2);
	g.clear();
	truth.clear();
	for (int j = 0; j < 60; ++j)
	{
		const double e = 10 + slope * j;
		truth.push_back(e);
		for (int i = 0; i < n; ++i)
		{
			const double v = W + (M - W) * pixelStep(i - (e - frame - margin), sigma).value +
							 (K - M) * pixelStep(i - (e - frame), sigma).value +
							 (G - K) * pixelStep(i - e, sigma).value + noise(rng);
			g.push_back(static_cast<int>(std::clamp(std::lround(v), 0L, 255L)));
		}
	}
}
}  // namespace

// A thin frame's peak-model edges lie inwards where the quiet margin is
// under a pixel (the wall's edge to it cancels part of the frame's lobe);
// thinFrameOffset() measures that shift from all the side's profiles with
// a model of the whole print. Slanted sides (phases across the pixel) fit
// the blur too; a side along the grid takes one. On a wide margin the peak
// model is right and the offset stays near 0.
TEST(Subpixel, ThinFrameOffsetRemovesTheNarrowMarginsPull)
{
	constexpr int n = 21;
	std::vector<int> g;
	std::vector<double> truth;
	for (const double frame : {2.4, 2.7, 3.0})
		for (const double slope : {0.013, 0.0})
		{
			const double sigma = slope > 0 ? 0 : 0.8;
			for (const double margin : {0.66, 5.0})
			{
				thinFrameProfiles(frame, margin, slope, g, truth, n);
				std::vector<std::optional<double>> edges;
				double before = 0;
				for (int j = 0; j < 60; ++j)
				{
					edges.push_back(locateRisingEdge(
						g.data() + j * n, n, 7, 13, 5, SubpixelParams(), EdgeMode::Peak, frame));
					ASSERT_TRUE(edges.back());
					before += (*edges.back() - truth[j]) / 60;
				}
				const auto offset = thinFrameOffset(g, n, edges, frame, sigma);
				ASSERT_TRUE(offset) << frame << " " << margin << " " << slope;
				const double after = before + *offset;
				std::printf(
					"frame %.1f px, margin %.2f px, %s: edges' mean error %+.4f -> %+.4f px\n",
					frame, margin, slope > 0 ? "slanted" : "along the grid", before, after);
				if (margin < 1)
				{
					EXPECT_GT(before, 0.02);
					EXPECT_LT(std::abs(after), 0.5 * before);
				}
				else
					EXPECT_LT(std::abs(after), std::abs(before) + 0.01);
			}
		}
}

namespace
{
/** Profiles across a sharp inner edge as the renderer makes them: frame G
 * 25 and B + R 50, fill G = \a level clipped at 255 and B + R 0 (B and R
 * rounded alike), the edge at \a e0 + \a slope j in profile j of \a m. */
void sharpEdgeProfiles(
	double level, double e0, double slope, int m, int n, std::vector<int>& g, std::vector<int>& rb)
{
	g.assign(size_t(m) * n, 0);
	rb.assign(size_t(m) * n, 0);
	for (int j = 0; j < m; ++j)
		for (int i = 0; i < n; ++i)
		{
			const double f = std::clamp(i + 0.5 - (e0 + slope * j), 0.0, 1.0);
			g[size_t(j) * n + i] =
				static_cast<int>(std::min(255L, std::lround(25 + (level - 25) * f)));
			rb[size_t(j) * n + i] = -2 * static_cast<int>(std::lround(25 * (1 - f)));
		}
}
}  // namespace

// A band at 255 throughout is at the sensor's top or above it; B + R of the
// transition pixels tell which, where the edge crosses pixel phases.
TEST(Subpixel, FillLevelFromChannelsTellsATopFillFromAClippedOne)
{
	constexpr int m = 60, n = 21;
	std::vector<int> g, rb;
	for (const double e0 : {9.2, 9.6})
	{
		sharpEdgeProfiles(255, e0, 0.013, m, n, g, rb);
		const auto top = fillLevelFromChannels(g, rb, n, 7, 13, 13, 18);
		ASSERT_TRUE(top);
		EXPECT_NEAR(top->level, 255, 1.5);
		EXPECT_TRUE(top->atTop()) << top->level << " +- " << top->se;
		for (const double level : {275.0, 300.0, 400.0})
		{
			sharpEdgeProfiles(level, e0, 0.013, m, n, g, rb);
			const auto above = fillLevelFromChannels(g, rb, n, 7, 13, 13, 18);
			ASSERT_TRUE(above);
			EXPECT_FALSE(above->consistentWithTop()) << level;
			EXPECT_FALSE(above->atTop()) << level;
		}
	}
	// One phase all along (a side on the pixel grid): inconclusive, its
	// rounding shared by every pixel.
	sharpEdgeProfiles(255, 9.3, 0, m, n, g, rb);
	const auto aligned = fillLevelFromChannels(g, rb, n, 7, 13, 13, 18);
	ASSERT_TRUE(aligned);
	EXPECT_FALSE(aligned->atTop()) << aligned->level << " +- " << aligned->se;
	EXPECT_TRUE(aligned->consistentWithTop());
	// On a pixel boundary: no mixed pixels, the level unknown.
	sharpEdgeProfiles(255, 9.5, 0, m, n, g, rb);
	const auto boundary = fillLevelFromChannels(g, rb, n, 7, 13, 13, 18);
	ASSERT_TRUE(boundary);
	EXPECT_FALSE(std::isfinite(boundary->se));
	EXPECT_TRUE(boundary->consistentWithTop());
	EXPECT_FALSE(boundary->atTop());
	// Without B + R contrast: nothing.
	sharpEdgeProfiles(255, 9.2, 0.013, m, n, g, rb);
	for (int& v : rb) v /= 10;
	EXPECT_FALSE(fillLevelFromChannels(g, rb, n, 7, 13, 13, 18));
}

namespace
{
/** Steps of \a heights at \a positions on a level \a base, blurred by a
 * Gaussian of \a sigma and integrated over each pixel (numerically). */
std::vector<int> blurredSteps(
	double base, std::initializer_list<std::pair<double, double>> steps, double sigma, int n)
{
	std::vector<int> v(n);
	const auto Phi = [&](double x) { return 0.5 * (1 + std::erf(x / (std::sqrt(2.0) * sigma))); };
	for (int i = 0; i < n; ++i)
	{
		double s = 0;
		constexpr int kSub = 64;
		for (int k = 0; k < kSub; ++k)
		{
			const double x = i - 0.5 + (k + 0.5) / kSub;
			double y = base;
			for (const auto& [at, height] : steps) y += height * Phi(x - at);
			s += y;
		}
		v[i] = static_cast<int>(std::lround(s / kSub));
	}
	return v;
}

/** A thin black frame: wall level \a wall up to x0 - width, black (20)
 * up to x0, green fill (250) beyond. */
std::vector<int> thinFrameProfile(double x0, double width, double sigma, double wall, int n)
{
	return blurredSteps(wall, {{x0 - width, 20 - wall}, {x0, 250 - 20}}, sigma, n);
}
}  // namespace

// The frame's outer edge 1.6-3.2 px away pulls the inner edge's derivative
// peak inwards; the lobe model removes most of that pull, also when the
// lobe makes the peak's outer neighbour sample negative (a bright wall: the
// log-parabola then has no width of its own, and the model must not be
// skipped). Largest error over sub-pixel positions, with and without it.
TEST(Subpixel, PeakModeRemovesMostOfTheOuterEdgeOfAThinFrame)
{
	const SubpixelParams p;
	for (double blur : {0.6, 0.8, 1.0})
		for (double width : {1.6, 2.0, 2.5, 3.2})
			for (double wall : {90.0, 150.0, 220.0})
			{
				double with = 0, without = 0;
				for (double x0 = 9.0; x0 < 10.0; x0 += 0.05)
				{
					const auto v = thinFrameProfile(x0, width, blur, wall, 21);
					const auto e =
						locateRisingEdge(v.data(), 21, 7, 13, 5, p, EdgeMode::Peak, width);
					const auto e0 = locateRisingEdge(v.data(), 21, 7, 13, 5, p, EdgeMode::Peak);
					ASSERT_TRUE(e && e0);
					with = std::max(with, std::abs(*e - x0));
					without = std::max(without, std::abs(*e0 - x0));
				}
				const std::string what = "blur " + std::to_string(blur) + " width " +
										 std::to_string(width) + " wall " + std::to_string(wall);
				if (width >= 2.0)
				{
					EXPECT_LT(with, without) << what;
					EXPECT_LE(with, 0.35) << what;
				}
				else if (wall >= 150)
				{
					EXPECT_LT(with, 0.75 * without) << what;
				}
			}
}

namespace
{
/** The frame's outer edge read outwards: black (20) up to x0, the sheet's
 * white (235) for \a margin px, then the wall's level \a wall. */
std::vector<int> marginProfile(double x0, double margin, double sigma, double wall, int n)
{
	return blurredSteps(20, {{x0, 235 - 20}, {x0 + margin, wall - 235}}, sigma, n);
}
}  // namespace

// Read from the frame outwards, the quiet margin's edge to a darker wall
// follows the frame's outer edge a margin's width later; its lobe pulls the
// derivative's peak towards the frame. A negative neighbour_px puts the
// lobe model after the edge and removes most of that pull. Largest error
// over sub-pixel positions, with and without it.
TEST(Subpixel, PeakModeRemovesTheMarginsEdgeAfterIt)
{
	const SubpixelParams p;
	for (double blur : {0.6, 0.8, 1.0})
		for (double margin : {1.2, 1.6, 2.0, 3.0})
			for (double wall : {60.0, 150.0})
			{
				if (margin < std::sqrt(2 * std::log(2.0)) * blur) continue;
				double with = 0, without = 0;
				for (double x0 = 9.0; x0 < 10.0; x0 += 0.05)
				{
					const auto v = marginProfile(x0, margin, blur, wall, 21);
					const auto e =
						locateRisingEdge(v.data(), 21, 7, 12, 5, p, EdgeMode::Peak, -margin);
					const auto e0 = locateRisingEdge(v.data(), 21, 7, 12, 5, p, EdgeMode::Peak);
					ASSERT_TRUE(e && e0);
					with = std::max(with, std::abs(*e - x0));
					without = std::max(without, std::abs(*e0 - x0));
				}
				const std::string what = "blur " + std::to_string(blur) + " margin " +
										 std::to_string(margin) + " wall " + std::to_string(wall);
				std::printf(
					"%s: worst %.3f px with the lobe model, %.3f without\n", what.c_str(), with,
					without);
				// A margin of 1.2 px against a mid-grey wall is beyond the
				// model: its lobe and the edge's overlap to their peaks.
				if (margin < 1.5) continue;
				EXPECT_LT(with, without) << what;
				EXPECT_LT(with, margin < 2 ? 0.25 : 0.11) << what;
			}
}

TEST(Subpixel, NoEdgeOrFallingEdgeGivesNothing)
{
	const SubpixelParams p;
	std::vector<int> flat(21, 100);
	EXPECT_FALSE(locateRisingEdge(flat.data(), 21, 7, 13, 5, p));
	auto v = stepProfile(10, 0.8, 21);
	std::reverse(v.begin(), v.end());
	EXPECT_FALSE(locateRisingEdge(v.data(), 21, 7, 13, 5, p));
	// Too weak a step.
	const auto w = stepProfile(10, 0.8, 21, 36);
	EXPECT_FALSE(locateRisingEdge(w.data(), 21, 7, 13, 5, p));
}

TEST(Subpixel, LineFitRejectsOutliers)
{
	std::mt19937 rng(3);
	std::normal_distribution<double> noise(0, 0.05);
	std::vector<Eigen::Vector2d> pts;
	// v = 0.1 u + 20
	for (int u = 0; u < 60; ++u) pts.emplace_back(u, 0.1 * u + 20 + noise(rng));
	pts[10].y() += 3;
	pts[40].y() -= 2;
	const auto f = fitLine(pts, SubpixelParams());
	ASSERT_TRUE(f);
	EXPECT_EQ(f->support, 58);
	EXPECT_LT(f->rms_px, 0.08);
	// Distance of a point of the true line to the fit.
	for (double u : {0.0, 59.0})
		EXPECT_LT(std::abs(f->normal.dot(Eigen::Vector2d(u, 0.1 * u + 20)) + f->c), 0.05);
	EXPECT_FALSE(fitLine({pts.begin(), pts.begin() + 3}, SubpixelParams()));
}

// A side's points scattered block by block (a dim edge through JPEG's 8 x 8
// blocks): refused at the pixel limit, kept where the scatter is within what
// SubpixelParams::max_rms_grey on the side's response would cause, measured
// along the line's normal.
TEST(Subpixel, LineFitLimitFollowsTheEdgeResponse)
{
	const SubpixelParams p;
	const auto staircase = [](double angle_deg)
	{
		const double a = angle_deg * M_PI / 180;
		const Eigen::Vector2d along(std::cos(a), std::sin(a)), normal(-along.y(), along.x());
		std::vector<Eigen::Vector2d> pts;
		for (int i = 0; i < 48; ++i)
			pts.push_back(
				Eigen::Vector2d(100, 100) + i * along + ((i / 8) % 2 ? 0.7 : -0.7) * normal);
		return pts;
	};
	// Along the u axis, profiles along v: the response's slope is the normal's.
	const auto level = staircase(0);
	const auto f0 = fitLine(level, p);
	EXPECT_FALSE(f0);
	const auto f1 = fitLine(level, p, EdgeResponse{7, 1});	// 8 / 7 = 1.14 px
	ASSERT_TRUE(f1);
	EXPECT_NEAR(f1->rms_px, 0.7, 0.05);
	EXPECT_NEAR(std::abs(f1->normal.dot(Eigen::Vector2d(120, 100)) + f1->c), 0, 0.15);
	EXPECT_FALSE(fitLine(level, p, EdgeResponse{20, 1}));  // 0.4 px: the pixel limit
	EXPECT_FALSE(fitLine(level, p, EdgeResponse{0, 1}));  // no response measured
	// At 45 deg the profiles' slope is the normal's x cos 45 deg: 7 per
	// sample is 9.9 per px along the normal (limit 0.81 px), 10 is 14.1 (0.57).
	const auto oblique = staircase(45);
	EXPECT_TRUE(fitLine(oblique, p, EdgeResponse{7, 1}));
	EXPECT_FALSE(fitLine(oblique, p, EdgeResponse{10, 1}));
}

TEST(Subpixel, RefinedCornersOfACraftedLandmark)
{
	// The crafted fill is G = 255 without noise: as seen by the sensor, a
	// fill at or above its top. Read as unclipped, the corners are exact to
	// 0.02 px; read as clipped (the default), its level comes from B and R
	// (8-bit steps of 25 levels), good to about 1 level, which moves the
	// corners by up to 0.03 px.
	for (const bool clipping : {false, true})
		for (double blur : {0.0, 0.8, 1.5})
		{
			const cv::Mat img = craftedLandmark(0x5A, 40, blur);
			const auto q = coarseQuad(img);
			ASSERT_TRUE(q);
			SubpixelModels models;
			models.clipping = clipping;
			const auto r = refineQuadrangle(
				img, *q, CameraModel(), 10, 0.125, SubpixelParams(), 35.0 / 160, models);
			ASSERT_TRUE(r);
			const auto truth = craftedCorners();
			for (int k = 0; k < 4; ++k)
			{
				EXPECT_LT((r->corners_raw[k] - truth[k]).norm(), clipping ? 0.03 : 0.02)
					<< "blur " << blur << " corner " << k << " clipping " << clipping;
				EXPECT_LT(r->sides[k].rms_px, 0.05);
				EXPECT_GT(r->sides[k].support, 60);
			}
		}
}

// -------------------------------------------------------------------- code

TEST(Code, HomographyMapsTheUnitSquareToTheCorners)
{
	const Quad c = {
		Eigen::Vector2d(10, 12), Eigen::Vector2d(50, 8), Eigen::Vector2d(55, 60),
		Eigen::Vector2d(8, 50)};
	const Eigen::Matrix3d H = faceToImage(c);
	const double src[4][2] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
	for (int k = 0; k < 4; ++k)
	{
		const Eigen::Vector3d q = H * Eigen::Vector3d(src[k][0], src[k][1], 1);
		EXPECT_LT((q.head<2>() / q.z() - c[k]).norm(), 1e-9);
	}
}

TEST(Code, SampleGIsBilinearAndBounded)
{
	cv::Mat img(2, 2, CV_8UC3, cv::Scalar(0, 0, 0));
	img.at<cv::Vec3b>(0, 1)[1] = 100;
	EXPECT_NEAR(*sampleG(img, 0.5, 0), 50, 1e-9);
	EXPECT_NEAR(*sampleG(img, 0.5, 0.5), 25, 1e-9);
	EXPECT_FALSE(sampleG(img, -0.1, 0));
	EXPECT_FALSE(sampleG(img, 0, 1.01));
}

TEST(Code, ReadsEveryIdOfCraftedLandmarks)
{
	const LandmarkGeometry g;
	for (int id = 0; id < 256; id += 17)
	{
		const cv::Mat img = craftedLandmark(id);
		RefinedQuad q;
		q.corners_raw = q.corners_ideal = craftedCorners();
		const auto r = readCode(img, q, CameraModel(), g, CodeParams());
		ASSERT_TRUE(r) << id;
		EXPECT_EQ(r->id, id);
		EXPECT_GT(r->margin, 50);
		EXPECT_LT(r->black_g, 60);
		EXPECT_GT(r->green_g, 200);
	}
}

TEST(Code, RejectsGreenCentreOtherFillAndMissingFrame)
{
	const LandmarkGeometry g;
	RefinedQuad q;
	q.corners_raw = q.corners_ideal = craftedCorners();
	cv::Mat img = craftedLandmark(0);
	cv::rectangle(
		img, cv::Rect(40 + 43, 40 + 43, 15, 15), kGreen, cv::FILLED);  // centre cell green
	EXPECT_FALSE(readCode(img, q, CameraModel(), g, CodeParams()));
	// No frame: the frame painted white.
	img = craftedLandmark(0, 40, 0);
	cv::rectangle(img, cv::Rect(40, 40, 100, 10), kWhite, cv::FILLED);
	EXPECT_FALSE(readCode(img, q, CameraModel(), g, CodeParams()));
	// A cut landmark: the outer frame outside the image.
	img = craftedLandmark(0, 40, 0);
	const cv::Mat cut = img(cv::Rect(45, 0, 135, 180)).clone();
	RefinedQuad qc = q;
	for (auto& c : qc.corners_raw) c.x() -= 45;
	qc.corners_ideal = qc.corners_raw;
	EXPECT_FALSE(readCode(cut, qc, CameraModel(), g, CodeParams()));
}

namespace
{
/** \a q with each corner moved by a pixel, in direction \a shift (0..15,
 * sixteenths of a turn), each corner a quarter turn further than the last. */
Quad movedByAPixel(Quad q, int shift)
{
	for (int k = 0; k < 4; ++k)
	{
		const double a = M_PI / 8 * shift + k * M_PI / 2;
		q[k] += Eigen::Vector2d(std::cos(a), std::sin(a));
	}
	return q;
}
}  // namespace

// The gate before the sub-pixel stage reads the centre cell at corners a
// pixel off in any direction: a code board passes, a green centre and a
// green square without a board do not.
TEST(Code, CentreGateToleratesAPixelsCornerErrorAndRefusesAGreenCentre)
{
	const LandmarkGeometry g;
	const CodeParams p;
	const Quad truth = craftedCorners();
	for (int id = 0; id < 256; id += 51)
	{
		const cv::Mat img = craftedLandmark(id, 40, 0.8);
		cv::Mat green_centre = img.clone();
		cv::rectangle(green_centre, cv::Rect(40 + 43, 40 + 43, 15, 15), kGreen, cv::FILLED);
		for (int shift = 0; shift < 16; ++shift)
		{
			const Quad q = movedByAPixel(truth, shift);
			EXPECT_TRUE(centreMayBeBlack(img, q, CameraModel(), g, p)) << id << " " << shift;
			EXPECT_FALSE(centreMayBeBlack(green_centre, q, CameraModel(), g, p))
				<< id << " " << shift;
		}
	}
	// A landmark 26 px across (5 m at 60 deg: cells of 5 px), blurred.
	for (const double blur : {0.6, 1.2})
	{
		const int side = 26, o = 30;
		const cv::Mat small = printedLandmark(side, kGreen, kBlack, kWhite, blur, o, 90);
		const double a = o - 0.5, b = o + side - 0.5;
		const Quad corners{
			Eigen::Vector2d(a, a), Eigen::Vector2d(b, a), Eigen::Vector2d(b, b),
			Eigen::Vector2d(a, b)};
		for (int shift = 0; shift < 16; ++shift)
			EXPECT_TRUE(centreMayBeBlack(small, movedByAPixel(corners, shift), CameraModel(), g, p))
				<< blur << " " << shift;
	}
	// A green square on black: a frame, but no code board.
	cv::Mat square(180, 180, CV_8UC3, kBlack);
	cv::rectangle(square, cv::Rect(50, 50, 80, 80), kGreen, cv::FILLED);
	cv::GaussianBlur(square, square, cv::Size(0, 0), 0.8);
	EXPECT_FALSE(centreMayBeBlack(square, truth, CameraModel(), g, p));
	// Corners whose patches leave the image: readCode() decides.
	Quad outside = truth;
	for (auto& c : outside) c *= 3;
	EXPECT_TRUE(centreMayBeBlack(square, outside, CameraModel(), g, p));
}

TEST(Code, TheFrameCheckComparesTheInk)
{
	// The dim laser print of FrameEvidenceOfAThinFrame, its corners known:
	// read with the blur's correction, refused without; a grey frame is
	// refused either way.
	const LandmarkGeometry g;
	const cv::Scalar fill(40, 107, 50), toner(70, 70, 70), grey(95, 95, 95), sheet(140, 140, 140);
	RefinedQuad q;
	const double a = 30 - 0.5, b = 30 + 32 - 0.5;
	q.corners_raw = q.corners_ideal = {
		Eigen::Vector2d(a, a), Eigen::Vector2d(b, a), Eigen::Vector2d(b, b), Eigen::Vector2d(a, b)};
	const cv::Mat dim = printedLandmark(32, fill, toner, sheet, 1.5);
	const auto r = readCode(dim, q, CameraModel(), g, CodeParams());
	ASSERT_TRUE(r);
	EXPECT_EQ(r->id, 0);
	EXPECT_GT(r->black_g, 0.7 * r->green_g);  // as read: lighter than the ratio allows
	EXPECT_FALSE(readCode(dim, q, CameraModel(), g, CodeParams(), 0));
	const cv::Mat greyed = printedLandmark(32, fill, grey, sheet, 1.5);
	EXPECT_FALSE(readCode(greyed, q, CameraModel(), g, CodeParams()));
}

namespace
{
/** Landmark \a id whose reference square spans \a w x \a h px (a view
 * from the side foreshortens it), drawn 8 times finer, blurred there by
 * \a blur px and averaged over each pixel; the square's corners lie at
 * o - 0.5 and o + w - 0.5 (x), o + h - 0.5 (y). */
cv::Mat narrowLandmark(int id, int w, int h, double blur, int o = 30, int size = 100)
{
	const int k = 8;
	const double at = o * k, iw = w * k, ih = h * k;
	cv::Mat fine(size * k, size * k, CV_8UC3, kWhite);
	const auto box = [&](double x, double y, double bw, double bh, const cv::Scalar& c) {
		cv::rectangle(
			fine, cv::Rect(cvRound(x), cvRound(y), cvRound(bw), cvRound(bh)), c, cv::FILLED);
	};
	// The frame is 20 / 160 of the square, a cell 30 / 160.
	box(at - iw / 8, at - ih / 8, iw * 10 / 8, ih * 10 / 8, kBlack);
	box(at, at, iw, ih, kGreen);
	const double cw = iw * 3 / 16, ch = ih * 3 / 16;
	const CodeCells cells = encodeId(id);
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
			if (cells[r][c])
				box(at + iw / 2 + (c - 1.5) * cw, at + ih / 2 + (r - 1.5) * ch, cw, ch, kBlack);
	if (blur > 0) cv::GaussianBlur(fine, fine, cv::Size(0, 0), blur * k);
	cv::Mat img;
	cv::resize(fine, img, cv::Size(size, size), 0, 0, cv::INTER_AREA);
	return img;
}
}  // namespace

TEST(Code, BlurSharesAreTheCellsWithoutBlurAndSpreadWithIt)
{
	const LandmarkGeometry g;
	const CameraModel cam;
	const FaceMap map{faceToImage(craftedCorners()), cam, false};
	const auto sharp = blurredCellShares(map, g, 0.4, 1e-3);
	const Eigen::Matrix<double, 9, 9> cells = sharp.topLeftCorner(9, 9);
	EXPECT_LT((cells - Eigen::Matrix<double, 9, 9>::Identity()).cwiseAbs().maxCoeff(), 1e-9);
	EXPECT_LT(sharp.col(9).head(9).cwiseAbs().maxCoeff(), 1e-9);
	// The ring's patches lie on the ring alone.
	EXPECT_LT((sharp.col(9).tail(4).array() - 1).abs().maxCoeff(), 1e-9);
	EXPECT_LT(sharp.bottomRows(4).leftCols(9).cwiseAbs().maxCoeff(), 1e-9);
	// A blur of a third of a cell (15 px here): each patch keeps most of its
	// own cell, takes a share of its neighbours and none of a far cell; all
	// shares of a patch sum to at most one (the frame is black).
	const auto soft = blurredCellShares(map, g, 0.4, 5);
	for (int i = 0; i < 9; ++i)
	{
		EXPECT_GT(soft(i, i), 0.6) << i;
		EXPECT_LT(soft(i, i), 1) << i;
		EXPECT_LE(soft.row(i).sum(), 1 + 1e-12) << i;
	}
	EXPECT_GT(soft(0, 1), 0.01);  // neighbours along a row
	EXPECT_GT(soft(0, 3), 0.01);  // and a column
	EXPECT_LT(soft(0, 8), 1e-3);  // opposite corners
	EXPECT_GT(soft(0, 9), 0.01);  // a corner cell touches the ring
	EXPECT_LT(soft(4, 9), soft(0, 9));	// the centre is farthest from it
}

TEST(Code, ThroughBlurIsTheThresholdOnSharpCells)
{
	// Cell means at two levels, each off by a few grey levels: the blur read
	// finds the code and, for cells 15 px wide, the threshold's margin.
	const LandmarkGeometry g;
	const CameraModel cam;
	const FaceMap map{faceToImage(craftedCorners()), cam, false};
	std::mt19937 rng(3);
	std::uniform_real_distribution<double> off(-8, 8);
	const std::array<double, 4> ring{200, 200, 200, 200};
	for (int id = 0; id < 256; id += 11)
	{
		const CodeCells cells = encodeId(id);
		std::array<double, 9> m{};
		double margin = 1e9;
		for (int k = 0; k < 9; ++k)
		{
			m[k] = (cells[k / 3][k % 3] ? 30 : 200) + off(rng);
			margin = std::min(margin, std::abs(m[k] - 115));
		}
		const auto r = readCellsThroughBlur(m, ring, 30, 30, map, g, 0.4, 0.15, 1.5);
		ASSERT_TRUE(r) << id;
		EXPECT_EQ(decodeCells(r->cells), id);
		EXPECT_NEAR(r->margin, margin, 10) << id;
	}
	// A cell halfway between the levels is ambiguous whatever the blur.
	std::array<double, 9> m{};
	const CodeCells cells = encodeId(0);
	for (int k = 0; k < 9; ++k) m[k] = cells[k / 3][k % 3] ? 30 : 200;
	m[0] = 115;
	EXPECT_FALSE(readCellsThroughBlur(m, ring, 30, 30, map, g, 0.4, 0.15, 1.5));
}

// The frame and the cells are one ink: a dark print on green inside a grey
// surround (a poster, a sticker on a wall) is not read as a code, though
// its cells alone would make one.
TEST(Code, ThroughBlurRefusesCellsOfAnotherInkThanTheFrame)
{
	const LandmarkGeometry g;
	const CameraModel cam;
	const FaceMap map{faceToImage(craftedCorners()), cam, false};
	const std::array<double, 4> ring{220, 220, 220, 220};
	const CodeCells cells = encodeId(192);
	std::array<double, 9> m{};
	for (int k = 0; k < 9; ++k) m[k] = cells[k / 3][k % 3] ? 40 : 220;
	const auto same_ink = readCellsThroughBlur(m, ring, 40, 40, map, g, 0.4, 0.15, 1.5);
	ASSERT_TRUE(same_ink);
	EXPECT_EQ(decodeCells(same_ink->cells), 192);
	// A grey surround at 130 (its ink as the frame's would be read).
	EXPECT_FALSE(readCellsThroughBlur(m, ring, 130, 125, map, g, 0.4, 0.15, 1.5));
	// Within the margin of the cells' black: still the same ink.
	EXPECT_TRUE(readCellsThroughBlur(m, ring, 60, 60, map, g, 0.4, 0.15, 1.5));
}

TEST(Code, ReadsANarrowBlurredBoard)
{
	// A landmark seen about 60 deg from its normal at 4-5 m: 10-12 x 30 px,
	// its cells 2-2.3 px wide, blurred by 1-1.2 px. Where a cell's mean lies
	// near the threshold between the frame's and the ring's levels (its
	// neighbours' share), the cells are read through the blur; every ID is
	// read, and read right.
	const LandmarkGeometry g;
	const CodeParams p;
	for (const auto& [w, blur] : {std::pair{12, 1.2}, std::pair{10, 1.0}})
	{
		RefinedQuad q;
		const double x0 = 30 - 0.5, y0 = 30 - 0.5;
		q.corners_raw = q.corners_ideal = {
			Eigen::Vector2d(x0, y0), Eigen::Vector2d(x0 + w, y0), Eigen::Vector2d(x0 + w, y0 + 30),
			Eigen::Vector2d(x0, y0 + 30)};
		int read = 0, through_blur = 0;
		for (int id = 0; id < 256; id += 5)
		{
			const auto r = readCode(narrowLandmark(id, w, 30, blur), q, CameraModel(), g, p);
			if (!r) continue;
			++read;
			EXPECT_EQ(r->id, id) << w;
			const double thr = 0.5 * (r->green_g + r->black_g), contrast = r->green_g - r->black_g;
			bool near = false;
			for (const double c : r->cell_g) near |= std::abs(c - thr) < p.min_margin * contrast;
			through_blur += near;
		}
		EXPECT_EQ(read, 52) << w;
		EXPECT_GE(through_blur, 15) << w;
	}
}

TEST(Code, AmbiguousCellIsRejected)
{
	const LandmarkGeometry g;
	RefinedQuad q;
	q.corners_raw = q.corners_ideal = craftedCorners();
	cv::Mat img = craftedLandmark(0);
	// Cell (0, 0) halfway between black and green.
	cv::rectangle(img, cv::Rect(40 + 27, 40 + 27, 16, 16), cv::Scalar(0, 140, 0), cv::FILLED);
	EXPECT_FALSE(readCode(img, q, CameraModel(), g, CodeParams()));
}

// ------------------------------------------------------------------ noise

// surroundNoiseRms(): the noise of the flat blocks around a quadrangle,
// with most of its window covered by edges and clipped pixels.
TEST(Noise, SurroundIsTheFlatBlocksNoise)
{
	const Quad q{{{100, 100}, {130, 100}, {130, 130}, {100, 130}}};	 // 30 px: a 90 px window
	for (const double sigma : {1.0, 2.0, 5.0})
	{
		std::mt19937 rng(7);
		std::normal_distribution<double> n01;
		cv::Mat img(240, 240, CV_8UC3);
		for (int y = 0; y < img.rows; ++y)
			for (int x = 0; x < img.cols; ++x)
			{
				// A horizontal shading (cancels in each block), stripes 5 px
				// wide over the left half (edges in every block there), and a
				// clipped band.
				double g = 60 + 0.5 * x;
				if (x < 115 && (x / 5) % 2) g += 120;
				if (y >= 120 && y < 150) g = 300;
				const double v = std::clamp(std::round(g + sigma * n01(rng)), 0.0, 255.0);
				img.at<cv::Vec3b>(y, x) = cv::Vec3b(0, uint8_t(v), 0);
			}
		const auto m = surroundNoiseRms(img, q);
		ASSERT_TRUE(m) << sigma;
		// Within 10% and the rounding (1 / 12 in variance).
		EXPECT_NEAR(*m, std::sqrt(sigma * sigma + 1.0 / 12), 0.1 * sigma) << sigma;
	}
	// All of the window clipped, or edges everywhere: nothing to measure
	// (or an overestimate, never an underestimate).
	cv::Mat clipped(240, 240, CV_8UC3, cv::Scalar(0, 255, 0));
	EXPECT_FALSE(surroundNoiseRms(clipped, q));
	cv::Mat stripes(240, 240, CV_8UC3, cv::Scalar(0, 60, 0));
	for (int x = 0; x < stripes.cols; x += 2) stripes.col(x).setTo(cv::Scalar(0, 180, 0));
	const auto m = surroundNoiseRms(stripes, q);
	EXPECT_TRUE(!m || *m > 10);
	// A window off the image: nothing.
	const Quad outside{{{-300, -300}, {-270, -300}, {-270, -270}, {-300, -270}}};
	EXPECT_FALSE(surroundNoiseRms(cv::Mat(240, 240, CV_8UC3, cv::Scalar(0, 128, 0)), outside));
}

// --------------------------------------------------------------- detect()

TEST(Detect, CraftedLandmarkEndToEnd)
{
	const cv::Mat img = craftedLandmark(201);
	const auto r = detect::detect(img, CameraModel(), LandmarkGeometry(), DetectorOptions());
	ASSERT_EQ(r.landmarks.size(), 1u);
	const auto& d = r.landmarks[0].detection;
	EXPECT_EQ(d.id, 201);
	const auto truth = craftedCorners();
	for (int k = 0; k < 4; ++k) EXPECT_LT((d.corners[k] - truth[k]).norm(), 0.02);
	EXPECT_NEAR(d.quality.area_px, 80.0 * 80.0, 5);
	EXPECT_GT(d.quality.code_margin, 50);
	EXPECT_LT(d.quality.corner_sigma_px, 0.05);
	// P from the corners (lambda = 800, principal point 319.5, 239.5).
	EXPECT_NEAR(r.landmarks[0].P(0), 49.5 - 319.5, 0.02);
	EXPECT_NEAR(r.landmarks[0].P(1), 40, 0.02);
	EXPECT_EQ(r.counts.decoded, 1);
	EXPECT_GE(r.timings.total_us, r.timings.segmentation_us);
}

TEST(Detect, DegenerateInputsGiveNothing)
{
	const CameraModel cam;
	const LandmarkGeometry g;
	const DetectorOptions o;
	EXPECT_TRUE(detect::detect(cv::Mat(), cam, g, o).landmarks.empty());
	EXPECT_TRUE(detect::detect(cv::Mat(0, 0, CV_8UC3), cam, g, o).landmarks.empty());
	EXPECT_TRUE(detect::detect(cv::Mat(1, 1, CV_8UC3, kGreen), cam, g, o).landmarks.empty());
	EXPECT_TRUE(detect::detect(cv::Mat(3, 2, CV_8UC3, kGreen), cam, g, o).landmarks.empty());
	EXPECT_TRUE(detect::detect(cv::Mat(480, 640, CV_8UC3, cv::Scalar(128, 128, 128)), cam, g, o)
					.landmarks.empty());
	EXPECT_TRUE(detect::detect(cv::Mat(480, 640, CV_8UC3, kGreen), cam, g, o).landmarks.empty());
	EXPECT_THROW(detect::detect(cv::Mat(10, 10, CV_8UC1), cam, g, o), std::invalid_argument);
}

TEST(Detect, GreenPostersWithoutAFrameAreNotLandmarks)
{
	for (const cv::Scalar& bg : {cv::Scalar(128, 128, 128), kWhite, cv::Scalar(60, 140, 160)})
	{
		cv::Mat img(200, 200, CV_8UC3, bg);
		cv::rectangle(img, cv::Rect(50, 50, 100, 100), kGreen, cv::FILLED);
		cv::rectangle(
			img, cv::Rect(90, 90, 20, 20), kBlack, cv::FILLED);	 // even with a black centre
		cv::GaussianBlur(img, img, cv::Size(0, 0), 0.8);
		EXPECT_TRUE(detect::detect(img, CameraModel(), LandmarkGeometry(), DetectorOptions())
						.landmarks.empty());
	}
	// A green square on black: a frame, but the centre cell is green.
	cv::Mat img(200, 200, CV_8UC3, kBlack);
	cv::rectangle(img, cv::Rect(50, 50, 100, 100), kGreen, cv::FILLED);
	EXPECT_TRUE(detect::detect(img, CameraModel(), LandmarkGeometry(), DetectorOptions())
					.landmarks.empty());
}
