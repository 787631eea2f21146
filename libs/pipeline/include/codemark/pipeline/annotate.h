#pragma once
/** \file annotate.h
 * Rawlog annotation: every CObservationImage of a rawlog (either format,
 * embedded or external images) gets a codemark::CObservationCodedLandmarks
 * right after it, and optionally its CObservationBearingRange twin.
 */
#include <codemark/pipeline/pipeline.h>

#include <functional>
#include <map>
#include <string>

namespace codemark::pipeline
{
struct AnnotateOptions
{
	PipelineOptions pipeline;
	bool bearing_range = false;	 //!< also insert the CObservationBearingRange twin (`<CAM>_BR`)
	bool drop_images = false;  //!< leave the image observations out of the output
	int threads = 0;  //!< worker threads; 0: the number of cores
};

struct AnnotateSummary
{
	long entries = 0;  //!< objects read from the input
	long images = 0;  //!< image observations processed
	long detections = 0;  //!< landmark sightings written
	std::map<int, long> per_id;	 //!< sightings per landmark ID
	double detect_ms_per_image = 0;	 //!< mean detector time per image
	double wall_s = 0;	//!< total wall time
	bool actions_observations = false;	//!< the input's format
};

/** Annotates \a in_path into \a out_path. Calls \a progress(bytes read,
 * total bytes). Throws std::runtime_error naming the entry index when an
 * entry cannot be read (never a silent truncation). Output order is the
 * input's whatever the number of threads. */
AnnotateSummary annotateRawlog(
	const std::string& in_path, const std::string& out_path, const AnnotateOptions& o,
	const std::function<void(long, long)>& progress = {});

}  // namespace codemark::pipeline
