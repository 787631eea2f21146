#pragma once
// Internal: what detect() keeps for the debug images.
#include <codemark/detect/detector.h>

#include "stages.h"

#include <string>
#include <vector>

namespace codemark::detect
{
struct DebugRecord
{
	cv::Mat mask;  //!< stage 1-2 output
	cv::Mat labels;	 //!< stage 3 labels
	int step = 1;
	std::vector<Candidate> candidates;
	std::vector<EdgelMap> edgels;  //!< one per examined ROI
	std::vector<RefinedQuad> quads;	 //!< every refined quadrangle, decoded or not
	/** The linked quadrangles (raw corners) that the centre gate refused
	 * (centreMayBeBlack()). */
	std::vector<Quad> refused;
};

/** Writes 1_mask.png, 2_components.png, 3_edgels.png, 4_lines.png and
 * 5_overlay.png into \a dir. Throws std::runtime_error when a file cannot be
 * written. */
void writeDebugImages(
	const std::string& dir, const cv::Mat& bgr, const DebugRecord& d,
	const std::vector<DetectedLandmark>& found);

}  // namespace codemark::detect
