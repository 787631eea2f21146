// Debug images and the overlay drawing.
#include "debug.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <stdexcept>

namespace codemark::detect
{
namespace
{
cv::Point2f pt(const Eigen::Vector2d& p) { return {float(p.x()), float(p.y())}; }

// Sub-pixel drawing: OpenCV's shift parameter with 4 fractional bits.
constexpr int kShift = 4;
cv::Point fix(const Eigen::Vector2d& p)
{
	return {
		static_cast<int>(std::lround(p.x() * (1 << kShift))),
		static_cast<int>(std::lround(p.y() * (1 << kShift)))};
}

void save(const std::string& dir, const std::string& name, const cv::Mat& img)
{
	const std::string path = dir + "/" + name;
	if (!cv::imwrite(path, img)) throw std::runtime_error(path + ": cannot write debug image");
}

cv::Mat greyBackdrop(const cv::Mat& bgr)
{
	cv::Mat g, out;
	cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY);
	g = g / 2;
	cv::cvtColor(g, out, cv::COLOR_GRAY2BGR);
	return out;
}
}  // namespace

void drawDetections(cv::Mat& img, const std::vector<DetectedLandmark>& landmarks)
{
	for (const auto& l : landmarks)
	{
		const auto& c = l.detection.corners;
		for (int k = 0; k < 4; ++k)
			cv::line(img, fix(c[k]), fix(c[(k + 1) % 4]), {0, 0, 255}, 1, cv::LINE_AA, kShift);
		for (int k = 0; k < 4; ++k)
			cv::circle(
				img, fix(c[k]), 3 << kShift,
				k == 0 ? cv::Scalar(255, 0, 255) : cv::Scalar(0, 255, 255), 1, cv::LINE_AA, kShift);
		// Axes of the landmark at its centre: Y_L (right) in red, Z_L (up) in
		// blue, half a side long, along the image of the face axes.
		const Eigen::Vector2d centre = 0.25 * (c[0] + c[1] + c[2] + c[3]);
		const Eigen::Vector2d right = 0.25 * ((c[1] - c[0]) + (c[2] - c[3]));
		const Eigen::Vector2d up = 0.25 * ((c[0] - c[3]) + (c[1] - c[2]));
		cv::arrowedLine(
			img, fix(centre), fix(centre + right), {0, 0, 255}, 2, cv::LINE_AA, kShift, 0.2);
		cv::arrowedLine(
			img, fix(centre), fix(centre + up), {255, 0, 0}, 2, cv::LINE_AA, kShift, 0.2);
		cv::putText(
			img, std::to_string(l.detection.id), pt(c[0] + Eigen::Vector2d(0, -6)),
			cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 255}, 1, cv::LINE_AA);
	}
}

void writeDebugImages(
	const std::string& dir, const cv::Mat& bgr, const DebugRecord& d,
	const std::vector<DetectedLandmark>& found)
{
	// 1: the colour mask at full size.
	cv::Mat mask_full;
	if (!d.mask.empty())
		cv::resize(
			d.mask, mask_full, cv::Size(d.mask.cols * d.step, d.mask.rows * d.step), 0, 0,
			cv::INTER_NEAREST);
	else
		mask_full = cv::Mat::zeros(bgr.size(), CV_8UC1);
	save(dir, "1_mask.png", mask_full);

	// 2: components, the survivors' bounding boxes (green) and ROIs (yellow).
	cv::Mat comp = cv::Mat::zeros(mask_full.size(), CV_8UC3);
	if (!d.labels.empty())
	{
		for (int y = 0; y < d.labels.rows; ++y)
			for (int x = 0; x < d.labels.cols; ++x)
			{
				const int l = d.labels.at<int>(y, x);
				if (!l) continue;
				const cv::Vec3b col((l * 67) % 200 + 55, (l * 131) % 200 + 55, (l * 29) % 200 + 55);
				comp(cv::Rect(x * d.step, y * d.step, d.step, d.step)).setTo(col);
			}
	}
	for (const auto& c : d.candidates)
	{
		cv::rectangle(comp, c.bbox, {0, 255, 0});
		cv::rectangle(comp, c.roi, {0, 255, 255});
	}
	save(dir, "2_components.png", comp);

	// 3: edgels by polarity: top red, right green, bottom blue, left yellow.
	cv::Mat ed = greyBackdrop(bgr);
	const cv::Vec3b colours[5] = {{0, 0, 0}, {0, 0, 255}, {0, 255, 0}, {255, 0, 0}, {0, 255, 255}};
	for (const auto& e : d.edgels)
	{
		for (int y = 0; y < e.polarity.rows; ++y)
			for (int x = 0; x < e.polarity.cols; ++x)
			{
				const uint8_t p = e.polarity.at<uint8_t>(y, x);
				if (p)
					ed(cv::Rect(e.roi.x + x * e.scale, e.roi.y + y * e.scale, e.scale, e.scale))
						.setTo(colours[p]);
			}
		cv::rectangle(ed, e.roi, {255, 255, 255});
	}
	save(dir, "3_edgels.png", ed);

	// 4: sub-pixel edge points and fitted lines (undistorted coordinates,
	// drawn as they are: close to raw for mild distortion); in magenta, the
	// linked quadrangles refused before the sub-pixel stage.
	cv::Mat li = greyBackdrop(bgr);
	for (const auto& q : d.refused)
		for (int k = 0; k < 4; ++k)
			cv::line(li, fix(q[k]), fix(q[(k + 1) % 4]), {255, 0, 255}, 1, cv::LINE_AA, kShift);
	for (const auto& q : d.quads)
	{
		for (int k = 0; k < 4; ++k)
		{
			for (const auto& p : q.sides[k].points)
				cv::circle(li, fix(p), 1 << (kShift - 1), {0, 255, 255}, -1, cv::LINE_AA, kShift);
			cv::line(
				li, fix(q.corners_ideal[k]), fix(q.corners_ideal[(k + 1) % 4]), {0, 0, 255}, 1,
				cv::LINE_AA, kShift);
		}
	}
	save(dir, "4_lines.png", li);

	// 5: the final overlay.
	cv::Mat ov = bgr.clone();
	drawDetections(ov, found);
	save(dir, "5_overlay.png", ov);
}

}  // namespace codemark::detect
