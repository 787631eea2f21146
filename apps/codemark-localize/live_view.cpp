// codemark-localize --gui (see live_view.h).
#include "live_view.h"

#include "x_display.h"

#include <mrpt/gui/CDisplayWindow3D.h>
#include <mrpt/math/distributions.h>
#include <mrpt/opengl/CEllipsoid2D.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/stock_objects.h>

#include <Eigen/Dense>
#include <chrono>
#include <thread>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace codemark::app
{
struct LiveView::Impl
{
	mrpt::gui::CDisplayWindow3D::Ptr win;
	bool camera_set = false;
};

LiveView::LiveView(int every_n_steps, const std::optional<eval::GroundTruth>& gt)
	: impl_(std::make_unique<Impl>()), every_n_(std::max(1, every_n_steps)), gt_(gt)
{
	requireDisplay();
	impl_->win = mrpt::gui::CDisplayWindow3D::Create("codemark-localize", 800, 600);
	if (!impl_->win->isOpen())
		throw std::runtime_error(
			"--gui: the 3D window could not be opened (see the messages above)");
	impl_->win->setCameraElevationDeg(90.0f);
	impl_->win->setCameraAzimuthDeg(-90.0f);
}

LiveView::~LiveView() = default;

void LiveView::update(
	const eval::LocalizeSummary& s, const LandmarkMap& map, const filters::Localizer& f)
{
	if (s.steps % every_n_ != 0) return;
	std::vector<filters::MappedLandmark> lms = f.landmarks();
	if (lms.empty())
		for (const auto& l : map.landmarks) lms.push_back({l, Eigen::Matrix3d::Zero()});
	draw(s, lms);
}

void LiveView::finish(const eval::LocalizeSummary& s, const LandmarkMap& map, bool wait_for_key)
{
	std::vector<filters::MappedLandmark> lms = s.slam_map;
	if (lms.empty())
		for (const auto& l : map.landmarks) lms.push_back({l, Eigen::Matrix3d::Zero()});
	draw(s, lms);
	if (wait_for_key && impl_->win->isOpen())
	{
		impl_->win->addTextMessage(0.02, 0.02, "done: press a key in this window to exit", 1);
		impl_->win->forceRepaint();
		// MRPT's waitForKey() returns at once here (a stale key flag): poll.
		impl_->win->clearKeyHitFlag();
		while (impl_->win->isOpen() && !impl_->win->keyHit())
			std::this_thread::sleep_for(std::chrono::milliseconds(50));
	}
}

void LiveView::draw(
	const eval::LocalizeSummary& s, const std::vector<filters::MappedLandmark>& landmarks)
{
	if (!impl_->win || !impl_->win->isOpen()) return;  // closed by the user: the run goes on
	double xmin = 1e9, xmax = -1e9, ymin = 1e9, ymax = -1e9;
	auto extend = [&](double x, double y)
	{
		xmin = std::min(xmin, x), xmax = std::max(xmax, x), ymin = std::min(ymin, y),
		ymax = std::max(ymax, y);
	};
	{
		auto& scene = impl_->win->get3DSceneAndLock();
		scene->clear();
		scene->insert(mrpt::opengl::CGridPlaneXY::Create(-20, 20, -20, 20, 0, 1));

		if (gt_)
		{
			auto gl = mrpt::opengl::CSetOfLines::Create();
			gl->setColor_u8(0, 160, 0);
			gl->setLineWidth(2);
			const auto& p = gt_->poses();
			for (std::size_t i = 1; i < p.size(); ++i)
			{
				gl->appendLine(p[i - 1].x(), p[i - 1].y(), 0.01, p[i].x(), p[i].y(), 0.01);
				extend(p[i].x(), p[i].y());
			}
			scene->insert(gl);
		}

		auto est = mrpt::opengl::CSetOfLines::Create();
		est->setColor_u8(0, 0, 255);
		est->setLineWidth(2);
		const eval::PathRow* last = nullptr;
		for (const auto& r : s.rows)
		{
			if (!r.estimate.initialized) continue;
			if (last)
				est->appendLine(
					last->estimate.mean.x(), last->estimate.mean.y(), 0.02, r.estimate.mean.x(),
					r.estimate.mean.y(), 0.02);
			last = &r;
			extend(r.estimate.mean.x(), r.estimate.mean.y());
		}
		scene->insert(est);

		auto pts = mrpt::opengl::CPointCloud::Create();
		pts->setColor_u8(220, 0, 0);
		pts->setPointSize(6);
		for (const auto& l : landmarks)
		{
			pts->insertPoint(l.landmark.x_m, l.landmark.y_m, 0.03);
			extend(l.landmark.x_m, l.landmark.y_m);
		}
		scene->insert(pts);

		if (last)
		{
			const auto& e = last->estimate;
			auto axes = mrpt::opengl::stock_objects::CornerXYZSimple(0.3f, 3.0f);
			axes->setPose(mrpt::poses::CPose3D(e.mean.x(), e.mean.y(), 0.05, e.mean.phi(), 0, 0));
			scene->insert(axes);
			auto ell = mrpt::opengl::CEllipsoid2D::Create();
			mrpt::math::CMatrixDouble22 C;
			C.asEigen() = e.cov.block<2, 2>(0, 0);
			ell->setCovMatrix(C);
			ell->setQuantiles(std::sqrt(mrpt::math::chi2inv(0.95, 2)));	 // 95% in 2 DoF
			ell->setColor_u8(255, 0, 0);
			ell->setLineWidth(2);
			ell->setLocation(e.mean.x(), e.mean.y(), 0.04);
			scene->insert(ell);
		}
		impl_->win->unlockAccess3DScene();
	}
	if (xmax >= xmin && !impl_->camera_set)
	{
		// Frame the ground truth and map once (the view then stays put).
		impl_->win->setCameraPointingToPoint(
			static_cast<float>(0.5 * (xmin + xmax)), static_cast<float>(0.5 * (ymin + ymax)), 0.0f);
		impl_->win->setCameraZoom(
			static_cast<float>(2.4 * std::max({xmax - xmin, ymax - ymin, 2.0})));
		impl_->camera_set = gt_ || !landmarks.empty();
	}
	impl_->win->addTextMessage(
		0.02, 0.95,
		"step " + std::to_string(s.steps) +
			"  blue: estimate  green: truth  red: landmarks, 95% ellipse",
		0);
	impl_->win->forceRepaint();
}

}  // namespace codemark::app
