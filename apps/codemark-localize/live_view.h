#pragma once
/** \file live_view.h
 * codemark-localize --gui: a live 3D view of a run (mrpt::gui::CDisplayWindow3D):
 * the estimated path (blue), the ground truth when given (green), the
 * landmarks (red points; for SLAM the filter's current map), the current
 * pose (axes) with its 95% position ellipse. World frame, metres.
 */
#include <codemark/eval/ground_truth.h>
#include <codemark/eval/localization.h>

#include <memory>
#include <optional>
#include <string>

namespace codemark::app
{
class LiveView
{
   public:
	/** Opens the window. \a every_n_steps >= 1: redraw period [steps].
	 * Throws std::runtime_error (one line) when no X display can be opened. */
	LiveView(int every_n_steps, const std::optional<eval::GroundTruth>& gt);
	~LiveView();

	/** The StepObserver of runLocalization: redraws every N steps. */
	void update(
		const eval::LocalizeSummary& s, const LandmarkMap& map, const filters::Localizer& f);

	/** Draws the final state; with \a wait_for_key, waits for a key press in
	 * the window (or its closing) before returning. */
	void finish(const eval::LocalizeSummary& s, const LandmarkMap& map, bool wait_for_key);

   private:
	void draw(
		const eval::LocalizeSummary& s, const std::vector<filters::MappedLandmark>& landmarks);

	struct Impl;
	std::unique_ptr<Impl> impl_;
	int every_n_ = 1;
	std::optional<eval::GroundTruth> gt_;
};

}  // namespace codemark::app
