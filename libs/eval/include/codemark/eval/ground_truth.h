#pragma once
/** \file ground_truth.h
 * Ground-truth robot paths for codemark-localize --gt, in both forms of
 * docs/spec.md section 6:
 *  - `timestamp x y yaw` rows (UNIX s, m, m, rad; `#` or `%` comments):
 *    matched to steps by timestamp (codemark-simul's gt_path.txt);
 *  - MRPT robot-path files, `x y z yaw pitch roll` rows with `%` comments
 *    (e.g. kf-slam_demo's ground truth), whose row 0 is the start pose and
 *    row k the pose after k actions: an actions-observations step matches
 *    the row of the number of actions read before it (kf-slam's step i, its
 *    (i+1)-th action-observation pair, row i + 1; a sensory frame ahead of
 *    the first action, which kf-slam skips, row 0); in observations-only
 *    rawlogs step i matches row i + 1.
 */
#include <mrpt/poses/CPose2D.h>

#include <optional>
#include <string>
#include <vector>

namespace codemark::eval
{
/** A loaded ground-truth path. */
class GroundTruth
{
   public:
	enum class Form
	{
		Timestamped,  //!< `timestamp x y yaw`
		MrptPath  //!< `x y z yaw pitch roll`, step i = row i + 1
	};

	/** Reads \a path; the form is told by the number of columns of the first
	 * data row (4 or 6). Throws std::runtime_error naming the file and line
	 * on a bad row, a mix of forms, or when the file cannot be opened. */
	static GroundTruth load(const std::string& path);

	/** The true pose at step \a index with timestamp \a t [UNIX s]: by
	 * timestamp (nearest row within \a tolerance_s), or in an MRPT path by
	 * row \a actions when it is >= 0 (RawlogStep::actions: the actions read
	 * so far in an actions-observations rawlog, so that a sensory frame ahead
	 * of the first action matches row 0 and kf-slam's step i row i + 1), else
	 * by row index + 1. None when there is no matching row. */
	std::optional<mrpt::poses::CPose2D> poseAt(
		long index, double t, double tolerance_s = 1e-3, long actions = -1) const;

	Form form() const { return form_; }
	std::size_t size() const { return poses_.size(); }
	/** Every pose of the file in order (for plots). */
	const std::vector<mrpt::poses::CPose2D>& poses() const { return poses_; }
	/** The rows' timestamps [UNIX s], one per pose; empty for an MRPT path. */
	const std::vector<double>& times() const { return times_; }

   private:
	Form form_ = Form::Timestamped;
	std::vector<double> times_;	 // Timestamped only, ascending
	std::vector<mrpt::poses::CPose2D> poses_;
};

}  // namespace codemark::eval
