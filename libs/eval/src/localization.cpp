// codemark-localize's logic: rawlog -> filter -> output files (spec section 6).
#include <codemark/eval/ground_truth.h>
#include <codemark/filters/mrpt_landmarks.h>
#include <codemark/eval/localization.h>
#include <codemark/filters/stepper.h>
#include <codemark/landmark/text.h>
#include <codemark/landmark/camera.h>
#include <codemark/pose/calibration.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/core/exceptions.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/math/distributions.h>
#include <mrpt/math/wrap2pi.h>
#include <mrpt/opengl/CEllipsoid2D.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/CText.h>
#include <mrpt/poses/CPoint2D.h>
#include <mrpt/serialization/CArchive.h>
#include <nlohmann/json.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

namespace codemark::eval
{
using namespace codemark::filters;

using mrpt::poses::CPose2D;

mrpt::poses::CPose2D alignSE2(
	const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b)
{
	if (a.empty() || a.size() != b.size())
		throw std::invalid_argument("alignSE2: needs as many points in both sets, at least one");
	Eigen::Vector2d ma = Eigen::Vector2d::Zero(), mb = Eigen::Vector2d::Zero();
	for (std::size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
	ma /= static_cast<double>(a.size());
	mb /= static_cast<double>(b.size());
	// The rotation maximising sum (b_i - mb) . R (a_i - ma): atan2 of the
	// cross and dot sums (the 2D case of Umeyama's SVD).
	double sdot = 0, scross = 0;
	for (std::size_t i = 0; i < a.size(); ++i)
	{
		const Eigen::Vector2d p = a[i] - ma, q = b[i] - mb;
		sdot += p.dot(q);
		scross += p.x() * q.y() - p.y() * q.x();
	}
	const double th = (sdot == 0 && scross == 0) ? 0.0 : std::atan2(scross, sdot);
	const Eigen::Rotation2Dd R(th);
	const Eigen::Vector2d t = mb - R * ma;
	return mrpt::poses::CPose2D(t.x(), t.y(), th);
}

std::optional<RelativePoseError> relativePoseError(
	const std::vector<PathRow>& rows, double interval_s)
{
	std::vector<const PathRow*> ok;
	for (const auto& r : rows)
		if (r.estimate.initialized && r.truth) ok.push_back(&r);
	RelativePoseError rpe;
	double st = 0, sy = 0;
	std::size_t j = 0;
	for (std::size_t i = 0; i < ok.size(); ++i)
	{
		j = std::max(j, i + 1);
		while (j < ok.size() && ok[j]->timestamp - ok[i]->timestamp < interval_s) ++j;
		if (j >= ok.size()) break;
		const CPose2D rel_gt = *ok[j]->truth - *ok[i]->truth;
		const CPose2D rel_est = ok[j]->estimate.mean - ok[i]->estimate.mean;
		const CPose2D e = rel_est - rel_gt;	 // rel_gt^-1 (+) rel_est
		st += e.x() * e.x() + e.y() * e.y();
		sy += mrpt::math::wrapToPi(e.phi()) * mrpt::math::wrapToPi(e.phi());
		++rpe.pairs;
	}
	if (rpe.pairs == 0) return std::nullopt;
	rpe.trans_rmse_m = std::sqrt(st / rpe.pairs);
	rpe.yaw_rmse_deg = std::sqrt(sy / rpe.pairs) * 180.0 / M_PI;
	return rpe;
}

std::optional<PathAlignment> alignPath(const std::vector<PathRow>& rows)
{
	const auto m = computeMetrics(rows, true);
	if (!m || m->matched < 2) return std::nullopt;
	return PathAlignment{m->truth_T_estimate, m->ate_rmse_m};
}

std::optional<PathMetrics> computeMetrics(const std::vector<PathRow>& rows, bool align_se2)
{
	PathMetrics m;
	if (align_se2)
	{
		std::vector<Eigen::Vector2d> a, b;
		for (const auto& r : rows)
			if (r.estimate.initialized && r.truth)
			{
				if (a.empty())
					m.truth_T_start =
						*r.truth + (CPose2D() - r.estimate.mean);  // truth_0 (+) estimate_0^-1
				a.emplace_back(r.estimate.mean.x(), r.estimate.mean.y());
				b.emplace_back(r.truth->x(), r.truth->y());
			}
		if (a.empty()) return std::nullopt;
		m.aligned = true;
		m.truth_T_estimate = alignSE2(a, b);
	}
	// The error of an estimate in a frame placed by truth_T_frame, and its
	// covariance rotated into the truth's frame.
	auto error = [](const PathRow& r, const CPose2D& truth_T_frame, Eigen::Matrix3d* cov)
	{
		const CPose2D est = truth_T_frame + r.estimate.mean;
		if (cov)
		{
			Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
			R.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(truth_T_frame.phi()).toRotationMatrix();
			*cov = R * r.estimate.cov * R.transpose();
		}
		return Eigen::Vector3d(
			est.x() - r.truth->x(), est.y() - r.truth->y(),
			mrpt::math::wrapToPi(est.phi() - r.truth->phi()));
	};
	double se = 0, syaw = 0, snees = 0, sanchored = 0;
	for (const auto& r : rows)
	{
		if (!r.estimate.initialized || !r.truth) continue;
		const Eigen::Vector3d e = error(r, m.truth_T_estimate, nullptr);
		const double d2 = e[0] * e[0] + e[1] * e[1];
		se += d2;
		syaw += e[2] * e[2];
		m.max_error_m = std::max(m.max_error_m, std::sqrt(d2));
		Eigen::Matrix3d cov;
		const Eigen::Vector3d en = error(r, m.aligned ? m.truth_T_start : m.truth_T_estimate, &cov);
		snees += en.dot(cov.ldlt().solve(en));
		sanchored += en[0] * en[0] + en[1] * en[1];
		++m.matched;
	}
	if (m.matched == 0) return std::nullopt;
	m.ate_rmse_m = std::sqrt(se / m.matched);
	m.yaw_rmse_deg = std::sqrt(syaw / m.matched) * 180.0 / M_PI;
	m.nees_mean = snees / m.matched;
	if (m.aligned) m.ate_rmse_anchored_m = std::sqrt(sanchored / m.matched);
	const unsigned dof = 3u * static_cast<unsigned>(m.matched);
	m.nees_band_low = mrpt::math::chi2inv(0.025, dof) / m.matched;
	m.nees_band_high = mrpt::math::chi2inv(0.975, dof) / m.matched;
	return m;
}

namespace
{

std::string num(double v, int decimals = 6)
{
	if (!std::isfinite(v)) return "null";
	std::ostringstream os;
	os << std::fixed << std::setprecision(decimals) << v;
	return os.str();
}

void writeTextFiles(const LocalizeSummary& s, const std::string& dir)
{
	std::ofstream path(dir + "/estimated_path.txt"), tum(dir + "/estimated_path.tum"),
		cov(dir + "/covariances.txt");
	if (!path || !tum || !cov) throw std::runtime_error(dir + ": cannot write the path files");
	path << "# timestamp[UNIX s] x[m] y[m] yaw[rad]: robot pose in the map frame, one row per "
			"camera "
			"frame from the first fix on ("
		 << s.method << ")\n";
	tum << "# timestamp tx ty tz qx qy qz qw (TUM format; z = 0, rotation about z)\n";
	cov << "# timestamp then the 3x3 covariance of (x, y, yaw) row by row [m^2, m rad, rad^2]\n";
	for (const auto& r : s.rows)
	{
		if (!r.estimate.initialized) continue;
		const auto& p = r.estimate.mean;
		const std::string t = num(r.timestamp, 6);
		path << t << ' ' << num(p.x()) << ' ' << num(p.y()) << ' ' << num(p.phi()) << '\n';
		tum << t << ' ' << num(p.x()) << ' ' << num(p.y()) << " 0 0 0 "
			<< num(std::sin(p.phi() / 2), 9) << ' ' << num(std::cos(p.phi() / 2), 9) << '\n';
		cov << t;
		for (int i = 0; i < 3; ++i)
			for (int j = 0; j < 3; ++j)
				cov << ' ' << std::setprecision(9) << std::scientific << r.estimate.cov(i, j);
		cov << std::defaultfloat << '\n';
	}
	std::ofstream nis(dir + "/innovations.txt");
	if (!nis) throw std::runtime_error(dir + "/innovations.txt: cannot write");
	nis << "# timestamp[UNIX s] nis dof gated(0/1) id: one row per sighting tested against the "
		   "filter's prediction\n";
	for (const auto& r : s.rows)
		for (const auto& in : r.stats.innovations)
			nis << num(r.timestamp, 6) << ' ' << num(in.nis, 4) << ' ' << in.dof << ' '
				<< (in.gated ? 1 : 0) << ' ' << in.id << '\n';
	if (!s.slam_map.empty())
	{
		LandmarkMap m;
		std::ofstream mc(dir + "/map_covariances.txt");
		mc << "# id then the 3x3 covariance of the landmark's (x, y, yaw) row by row [m^2, m rad, "
			  "rad^2]\n";
		for (const auto& l : s.slam_map)
		{
			m.landmarks.push_back(l.landmark);
			mc << l.landmark.id;
			for (int i = 0; i < 3; ++i)
				for (int j = 0; j < 3; ++j)
					mc << ' ' << std::setprecision(9) << std::scientific << l.cov(i, j);
			mc << std::defaultfloat << '\n';
		}
		m.save(dir + "/map.txt");
	}
}

// 2D plot: estimate (blue), ground truth (green), landmarks (black, with
// their outward normals), 95% position ellipses (red) every N steps.
void writePlot(const LocalizeSummary& s, const LandmarkMap& map, const std::string& file)
{
	double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
	auto grow = [&](double x, double y)
	{ x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y); };
	for (const auto& l : map.landmarks) grow(l.x_m, l.y_m);
	for (const auto& l : s.slam_map) grow(l.landmark.x_m, l.landmark.y_m);
	for (const auto& r : s.rows)
	{
		if (r.estimate.initialized) grow(r.estimate.mean.x(), r.estimate.mean.y());
		if (r.truth) grow(r.truth->x(), r.truth->y());
	}
	if (x0 > x1) x0 = y0 = -1, x1 = y1 = 1;
	const double margin = 0.5;
	x0 -= margin, y0 -= margin, x1 += margin, y1 += margin;
	// The plot area, with margins for the title (top) and the axes' labels
	// (left, bottom), so that no label lies over the data.
	const int W = 1000, left = 45, right = 10, top = 30, bottom = 30;
	const double scale = (W - left - right) / std::max(x1 - x0, 1e-3);
	const int plot_h = std::clamp(static_cast<int>((y1 - y0) * scale), 100, 4000);
	cv::Mat img(plot_h + top + bottom, W, CV_8UC3, cv::Scalar(255, 255, 255));
	auto px = [&](double x, double y)
	{
		return cv::Point(
			left + static_cast<int>((x - x0) * scale),
			top + plot_h - static_cast<int>((y - y0) * scale));
	};
	const cv::Scalar grid(230, 230, 230), label(110, 110, 110);
	for (int g = static_cast<int>(std::ceil(x0)); g <= x1; ++g)
	{
		cv::line(img, px(g, y0), px(g, y1), grid);
		cv::putText(
			img, std::to_string(g), cv::Point(px(g, y0).x - 4, top + plot_h + 15),
			cv::FONT_HERSHEY_SIMPLEX, 0.4, label, 1, cv::LINE_AA);
	}
	for (int g = static_cast<int>(std::ceil(y0)); g <= y1; ++g)
	{
		cv::line(img, px(x0, g), px(x1, g), grid);
		cv::putText(
			img, std::to_string(g), cv::Point(8, px(x0, g).y + 4), cv::FONT_HERSHEY_SIMPLEX, 0.4,
			label, 1, cv::LINE_AA);
	}
	cv::rectangle(img, px(x0, y1), px(x1, y0), cv::Scalar(150, 150, 150));
	cv::putText(
		img, "x [m]", cv::Point(W - right - 40, top + plot_h + 26), cv::FONT_HERSHEY_SIMPLEX, 0.4,
		label, 1, cv::LINE_AA);
	cv::putText(
		img, "y [m]", cv::Point(4, top - 4), cv::FONT_HERSHEY_SIMPLEX, 0.4, label, 1, cv::LINE_AA);
	auto drawLandmark = [&](const MapLandmark& l, const cv::Scalar& c)
	{
		cv::circle(img, px(l.x_m, l.y_m), 4, c, cv::FILLED, cv::LINE_AA);
		cv::line(
			img, px(l.x_m, l.y_m),
			px(l.x_m + 0.25 * std::cos(l.yaw_rad), l.y_m + 0.25 * std::sin(l.yaw_rad)), c, 1,
			cv::LINE_AA);
		cv::putText(
			img, std::to_string(l.id), px(l.x_m, l.y_m) + cv::Point(5, -5),
			cv::FONT_HERSHEY_SIMPLEX, 0.4, c, 1, cv::LINE_AA);
	};
	for (const auto& l : map.landmarks) drawLandmark(l, cv::Scalar(0, 0, 0));
	for (const auto& l : s.slam_map) drawLandmark(l.landmark, cv::Scalar(160, 0, 160));
	std::vector<cv::Point> est, gt;
	for (const auto& r : s.rows)
	{
		if (r.estimate.initialized) est.push_back(px(r.estimate.mean.x(), r.estimate.mean.y()));
		if (r.truth) gt.push_back(px(r.truth->x(), r.truth->y()));
	}
	if (gt.size() > 1) cv::polylines(img, gt, false, cv::Scalar(0, 160, 0), 2, cv::LINE_AA);
	if (est.size() > 1) cv::polylines(img, est, false, cv::Scalar(200, 0, 0), 1, cv::LINE_AA);
	const long every = std::max<long>(1, static_cast<long>(s.rows.size()) / 40);
	const double k95 = std::sqrt(mrpt::math::chi2inv(0.95, 2));
	for (std::size_t i = 0; i < s.rows.size(); i += every)
	{
		const auto& e = s.rows[i].estimate;
		if (!e.initialized) continue;
		Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(e.cov.block<2, 2>(0, 0));
		const Eigen::Vector2d ev = es.eigenvalues().cwiseMax(0.0);
		const Eigen::Vector2d v = es.eigenvectors().col(1);
		const double ang = std::atan2(v[1], v[0]) * 180.0 / M_PI;
		const cv::Size axes(
			std::max(1, static_cast<int>(k95 * std::sqrt(ev[1]) * scale)),
			std::max(1, static_cast<int>(k95 * std::sqrt(ev[0]) * scale)));
		cv::ellipse(
			img, px(e.mean.x(), e.mean.y()), axes, -ang, 0, 360, cv::Scalar(0, 0, 220), 1,
			cv::LINE_AA);
	}
	cv::putText(
		img,
		s.method + ": estimate (blue), ground truth (green), 95% ellipses (red), map landmarks " +
			"(black, with their normals)" + (s.slam_map.empty() ? "" : ", mapped (purple)"),
		cv::Point(left, 18), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	if (!cv::imwrite(file, img)) throw std::runtime_error(file + ": cannot write");
}

void writeScene(const LocalizeSummary& s, const LandmarkMap& map, const std::string& file)
{
	mrpt::opengl::COpenGLScene scene;
	scene.insert(mrpt::opengl::CGridPlaneXY::Create(-10, 10, -10, 10, 0, 1));
	auto est = mrpt::opengl::CSetOfLines::Create();
	est->setColor(0, 0, 0.8);
	est->setLineWidth(2);
	auto gt = mrpt::opengl::CSetOfLines::Create();
	gt->setColor(0, 0.6, 0);
	bool have_est = false, have_gt = false;
	const PathRow* prev = nullptr;
	const long every = std::max<long>(1, static_cast<long>(s.rows.size()) / 40);
	for (std::size_t i = 0; i < s.rows.size(); ++i)
	{
		const auto& r = s.rows[i];
		if (prev && prev->estimate.initialized && r.estimate.initialized)
		{
			est->appendLine(
				prev->estimate.mean.x(), prev->estimate.mean.y(), 0.01, r.estimate.mean.x(),
				r.estimate.mean.y(), 0.01);
			have_est = true;
		}
		if (prev && prev->truth && r.truth)
		{
			gt->appendLine(
				prev->truth->x(), prev->truth->y(), 0.0, r.truth->x(), r.truth->y(), 0.0);
			have_gt = true;
		}
		if (r.estimate.initialized && i % every == 0)
		{
			auto ell = mrpt::opengl::CEllipsoid2D::Create();
			mrpt::math::CMatrixDouble22 C;
			C.asEigen() = r.estimate.cov.block<2, 2>(0, 0);
			ell->setCovMatrix(C);
			ell->setQuantiles(std::sqrt(mrpt::math::chi2inv(0.95, 2)));
			ell->setLocation(r.estimate.mean.x(), r.estimate.mean.y(), 0.02);
			ell->setColor(0.9, 0, 0);
			scene.insert(ell);
		}
		prev = &r;
	}
	if (have_est) scene.insert(est);
	if (have_gt) scene.insert(gt);
	auto lms = mrpt::opengl::CPointCloud::Create();
	lms->setPointSize(8);
	lms->setColor(0, 0, 0);
	auto addLandmark = [&](const MapLandmark& l)
	{
		lms->insertPoint(l.x_m, l.y_m, l.z_m);
		auto t = mrpt::opengl::CText::Create(std::to_string(l.id));
		t->setLocation(l.x_m, l.y_m, l.z_m + 0.1);
		scene.insert(t);
	};
	for (const auto& l : map.landmarks) addLandmark(l);
	for (const auto& l : s.slam_map) addLandmark(l.landmark);
	scene.insert(lms);
	mrpt::io::CFileGZOutputStream f;
	if (!f.open(file)) throw std::runtime_error(file + ": cannot write");
	auto ar = mrpt::serialization::archiveFrom(f);
	ar << scene;
}
}  // namespace

void appendStep(
	LocalizeSummary& s, const RawlogStep& step, const StepStats& stats, const PoseEstimate& e,
	const std::optional<mrpt::poses::CPose2D>& truth)
{
	PathRow row;
	row.step = step.index;
	row.timestamp = step.timestamp;
	row.estimate = e;
	row.stats = stats;
	row.truth = truth;
	if (e.initialized && s.first_fix_step < 0)
	{
		s.first_fix_step = step.index;
		// After the first step's time (this step's when it is the first).
		s.first_fix_time_s =
			step.timestamp - (s.rows.empty() ? step.timestamp : s.rows.front().timestamp);
	}
	s.sightings_used += stats.used;
	s.sightings_rejected += stats.rejected;
	s.sightings_unknown_id += stats.unknown_id;
	s.sightings_too_oblique += step.sightings_too_oblique;
	s.reinitializations += stats.reinitialized ? 1 : 0;
	s.rows.push_back(std::move(row));
	++s.steps;
}

void summariseInnovations(LocalizeSummary& s)
{
	std::vector<const std::vector<Innovation>*> steps;
	for (const auto& r : s.rows) steps.push_back(&r.stats.innovations);
	const InnovationSummary n = filters::summariseInnovations(steps);
	s.nis_count = n.count;
	s.nis_mean = n.nis_mean;
	s.nis_dof = n.nis_dof;
	s.gated_fraction = n.tested ? double(n.gated) / double(n.tested) : 0.0;
	s.nis_verdict = nisVerdict(s.nis_mean, s.nis_dof, s.nis_count);
	s.nis_sighting_share = n.sighting_share;
	s.nis_component_mean = n.component_nis;
	s.nis_component_share = n.component_share;
	s.nis_visits = n.visits;
	s.nis_visit_ratio = n.visit_ratio;
	s.persistent_errors = n.persistent_errors;
	s.prediction = filters::predictionCheck(n, innovationComponentNames(s.method));
}

std::string summaryJson(const LocalizeSummary& s)
{
	// Numbers rounded to their meaningful decimals; non-finite ones null.
	const auto num = [](double v, int decimals) -> nlohmann::ordered_json
	{
		if (!std::isfinite(v)) return nullptr;
		const double k = std::pow(10.0, decimals);
		return std::round(v * k) / k;
	};
	nlohmann::ordered_json j;
	j["method"] = s.method;
	if (s.calibration.empty())
		j["calibration"] = nullptr;
	else
		j["calibration"] = s.calibration;
	j["steps"] = s.steps;
	j["sightings_used"] = s.sightings_used;
	j["sightings_rejected"] = s.sightings_rejected;
	j["sightings_unknown_id"] = s.sightings_unknown_id;
	j["sightings_too_oblique"] = s.sightings_too_oblique;
	j["reinitializations"] = s.reinitializations;
	j["first_fix_step"] = s.first_fix_step;
	j["first_fix_time_s"] = num(s.first_fix_time_s, 3);
	j["detect_ms_per_image"] = num(s.detect_ms_per_image, 3);
	j["nis_mean"] = num(s.nis_mean, 4);
	j["nis_dof"] = num(s.nis_dof, 3);
	j["nis_count"] = s.nis_count;
	j["gated_fraction"] = num(s.gated_fraction, 4);
	j["nis_verdict"] = s.nis_verdict;
	j["nis_sighting_share"] = num(s.nis_sighting_share, 4);
	// Per component, those it reports: which one reads off, and whether its
	// innovation shows the sighting at all.
	nlohmann::ordered_json components = nlohmann::ordered_json::object();
	const auto& names = innovationComponentNames(s.method);
	for (size_t i = 0; i < 3; ++i)
		if (std::isfinite(s.nis_component_mean[i]))
			components[names[i]] = {
				{"nis", num(s.nis_component_mean[i], 4)},
				{"sighting_share", num(s.nis_component_share[i], 4)}};
	j["nis_components"] = components;
	j["nis_visits"] = s.nis_visits;
	j["nis_visit_ratio"] = num(s.nis_visit_ratio, 4);
	j["persistent_errors"] = s.persistent_errors;
	// The components the sightings barely inform test the prediction (the
	// motion noise), not the sightings.
	if (s.prediction.verdict.empty())
		j["prediction_check"] = nullptr;
	else
		j["prediction_check"] = {
			{"components", s.prediction.components},
			{"nis_per_dof", num(s.prediction.ratio, 4)},
			{"verdict", s.prediction.verdict}};
	if (s.metrics)
	{
		const auto& m = *s.metrics;
		j["gt_matched_steps"] = m.matched;
		j["ate_rmse_m"] = num(m.ate_rmse_m, 6);
		j["max_error_m"] = num(m.max_error_m, 6);
		j["yaw_rmse_deg"] = num(m.yaw_rmse_deg, 4);
		j["nees_mean"] = num(m.nees_mean, 4);
		j["nees_band_95"] = {num(m.nees_band_low, 4), num(m.nees_band_high, 4)};
		// SLAM without a prior map: ate, max and yaw errors after an SE(2)
		// least-squares alignment, NEES in the frame anchored at the true
		// first pose (the SLAM covariance is relative to the start).
		j["alignment"] = m.aligned ? "se2_least_squares" : "none";
		if (m.aligned)
		{
			j["alignment_truth_T_estimate"] = {
				num(m.truth_T_estimate.x(), 6), num(m.truth_T_estimate.y(), 6),
				num(m.truth_T_estimate.phi(), 6)};
			j["nees_frame"] = "anchored_at_true_first_pose";
			j["ate_rmse_anchored_m"] = num(m.ate_rmse_anchored_m, 6);
		}
		if (m.landmarks_matched > 0)
		{
			j["landmarks_matched"] = m.landmarks_matched;
			j["landmark_rmse_m"] = num(m.landmark_rmse_m, 6);
			j["landmark_yaw_rmse_deg"] = num(m.landmark_yaw_rmse_deg, 4);
		}
	}
	j["time_per_step_ms"] = num(s.time_per_step_ms, 4);
	return j.dump(2) + "\n";
}

void writeOutputs(const LocalizeSummary& s, const LandmarkMap& map, const std::string& dir)
{
	createFolder(dir, "the output folder");
	writeTextFiles(s, dir);
	writePlot(s, map, dir + "/trajectory.png");
	writeScene(s, map, dir + "/trajectory.3Dscene");
	std::ofstream j(dir + "/summary.json");
	if (!j) throw std::runtime_error(dir + "/summary.json: cannot write");
	j << summaryJson(s);
}

void addLandmarkErrors(
	PathMetrics& m, const std::vector<MappedLandmark>& estimated, const LandmarkMap& truth)
{
	double se = 0, syaw = 0;
	int n = 0;
	for (const auto& l : estimated)
		for (const auto& t : truth.landmarks)
			if (t.id == l.landmark.id)
			{
				const auto p =
					m.truth_T_estimate + mrpt::poses::CPoint2D(l.landmark.x_m, l.landmark.y_m);
				se += std::pow(p.x() - t.x_m, 2) + std::pow(p.y() - t.y_m, 2);
				syaw += std::pow(
					mrpt::math::wrapToPi(l.landmark.yaw_rad + m.truth_T_estimate.phi() - t.yaw_rad),
					2);
				++n;
			}
	m.landmarks_matched = n;
	m.landmark_rmse_m = n ? std::sqrt(se / n) : 0.0;
	m.landmark_yaw_rmse_deg = n ? std::sqrt(syaw / n) * 180.0 / M_PI : 0.0;
}

LocalizeSummary runLocalization(
	const LocalizeRequest& req, const std::function<void(double)>& progress,
	const StepObserver& on_step)
{
	if (!std::ifstream(req.config_file).good())
		throw std::runtime_error(req.config_file + ": cannot open config file");
	mrpt::config::CConfigFile cfg(req.config_file);
	LocalizeSummary s;
	s.method = !req.method.empty() ? req.method : cfg.read_string("localize", "method", "ekf");
	if (!req.calibration.empty()) s.calibration = pose::resolveCalibration(req.calibration);
	const bool slam = s.method == "ekf-slam";
	LandmarkMap map;
	if (!req.map_file.empty())
		map = loadAnyMap(req.map_file);
	else if (!slam)
		throw std::invalid_argument("method '" + s.method + "' needs a landmark map (--map)");
	if (!slam && map.landmarks.empty())
		throw std::invalid_argument(
			req.map_file + ": the map has no landmarks (method '" + s.method +
			"' needs at least one)");
	std::optional<GroundTruth> gt;
	if (!req.gt_file.empty()) gt = GroundTruth::load(req.gt_file);
	LandmarkMap gt_map;
	if (!req.gt_map_file.empty()) gt_map = loadAnyMap(req.gt_map_file);

	// The landmarks' per-ID scales: the map's, else (SLAM) the true map's.
	std::optional<LandmarkMap> sizes;
	if (!req.map_file.empty() && !isMrptLandmarksFile(req.map_file))
		sizes = map;
	else if (
		req.map_file.empty() && !req.gt_map_file.empty() && !isMrptLandmarksFile(req.gt_map_file))
		sizes = gt_map;
	// A method named on the command line is not the config file's error.
	try
	{
		requireLocalizationMethod(s.method);
	}
	catch (const std::exception&)
	{
		if (req.method.empty()) rethrowNamingIniFile(req.config_file);
		throw;
	}
	ReadingOptions reading;
	std::unique_ptr<Localizer> filter;
	try
	{
		reading = readingOptions(cfg, req.calibration, sizes);
		filter = makeLocalizer(s.method, cfg, map, initialPose(cfg));
	}
	catch (const std::exception&)
	{
		rethrowNamingIniFile(req.config_file);	// "FILE:LINE: [SECTION] KEY: ..."
	}
	auto& [so, po] = reading;
	if (!req.camera_file.empty()) po.camera_override = CameraModel::load(req.camera_file);
	RawlogStepper stepper(req.rawlog, so, po);
	RawlogStep step;
	double filter_s = 0;
	long images = 0;
	double detect_s = 0;
	auto t_read = std::chrono::steady_clock::now();
	while (true)
	{
		const bool more = stepper.next(step);
		const auto t0 = std::chrono::steady_clock::now();
		if (!more) break;
		if (step.images_detected > 0)
		{
			images += step.images_detected;
			detect_s += std::chrono::duration<double>(t0 - t_read).count();
		}
		StepStats st;
		try
		{
			st = filter->step(step.odometry.get(), step.observations);
		}
		catch (const std::exception& e)
		{
			// A filter failure (non-finite or non-positive-definite state)
			// names the rawlog entry that caused it.
			throw std::runtime_error(
				req.rawlog + ": entry #" + std::to_string(step.entry) + " (step " +
				std::to_string(step.index) + "): " + mrpt::exception_to_str(e));
		}
		const auto t1 = std::chrono::steady_clock::now();
		filter_s += std::chrono::duration<double>(t1 - t0).count();
		appendStep(
			s, step, st, filter->estimate(),
			gt ? gt->poseAt(step.index, step.timestamp, 1e-3, step.actions) : std::nullopt);
		if (progress) progress(stepper.progress());
		if (on_step) on_step(step, s, map, *filter);
		t_read = std::chrono::steady_clock::now();
	}
	s.time_per_step_ms = s.steps ? 1000.0 * filter_s / s.steps : 0.0;
	s.detect_ms_per_image = images ? 1000.0 * detect_s / images : 0.0;
	s.slam_map = filter->landmarks();
	summariseInnovations(s);
	// SLAM without a prior map estimates in the frame of the robot's start:
	// align it to the ground truth's before comparing.
	s.metrics = computeMetrics(s.rows, slam && map.landmarks.empty());
	// Landmark errors against the true map, in the same alignment.
	if (s.metrics && slam && !req.gt_map_file.empty())
		addLandmarkErrors(*s.metrics, s.slam_map, gt_map);
	if (!req.out_dir.empty()) writeOutputs(s, map.landmarks.empty() ? gt_map : map, req.out_dir);
	return s;
}

}  // namespace codemark::eval
