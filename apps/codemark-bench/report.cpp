// codemark-bench: results.csv, report.md and the per-dataset plots.
#include <codemark/filters/mrpt_landmarks.h>
#include <mrpt/math/wrap2pi.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>
#include <unistd.h>

#include "bench.h"

namespace codemark::bench
{
namespace
{
std::string fmt(double v, int decimals)
{
	if (!std::isfinite(v)) return "nan";
	std::ostringstream o;
	o << std::fixed << std::setprecision(decimals) << v;
	return o.str();
}
template <typename T>
std::string opt(const std::optional<T>& v, int decimals)
{
	return v ? fmt(*v, decimals) : std::string();
}
std::optional<double> ratio(long num, long den)
{
	if (den <= 0) return std::nullopt;
	return static_cast<double>(num) / den;
}
bool neesInside(const eval::PathMetrics& m)
{
	return m.nees_mean >= m.nees_band_low && m.nees_mean <= m.nees_band_high;
}
// CSV/Markdown-safe: no commas or pipes or newlines in free text.
std::string clean(std::string s)
{
	for (auto& c : s)
		if (c == ',' || c == '|' || c == '\n' || c == '"') c = ';';
	return s;
}
}  // namespace

std::string csvHeader()
{
	return "dataset,method,status,steps,frames_in_view,detection_rate,sighting_detection_rate,"
		   "wrong_ids,"
		   "detect_ms_per_frame,ate_m,ate_aligned_m,max_error_m,rpe_trans_m,rpe_yaw_deg,yaw_rmse_"
		   "deg,"
		   "nees_mean,nees_low_95,nees_high_95,nees_inside,first_fix_step,first_fix_s,sightings_"
		   "used,"
		   "sightings_rejected,filter_ms_per_step,wall_s,error,nis_mean,nis_dof,nis_count,gated_"
		   "fraction,nis_verdict,prediction_nis_per_dof,prediction_verdict";
}

std::string csvRow(const JobResult& r)
{
	const auto& s = r.summary;
	const auto& d = r.detection;
	const auto& m = s.metrics;
	std::ostringstream o;
	o << r.dataset << ',' << r.method << ',' << (r.ok ? "ok" : "error") << ',' << s.steps << ','
	  << d.frames_in_view << ',' << opt(ratio(d.frames_detected, d.frames_in_view), 4) << ','
	  << opt(ratio(d.sightings_detected, d.sightings_in_view), 4) << ','
	  << (d.frames ? std::to_string(d.wrong_ids) : "") << ','
	  << (d.images ? fmt(d.detect_ms_per_image, 3) : "") << ',' << (m ? fmt(m->ate_rmse_m, 4) : "")
	  << ',' << (r.aligned ? fmt(r.aligned->ate_m, 4) : "") << ','
	  << (m ? fmt(m->max_error_m, 4) : "") << ',' << (r.rpe ? fmt(r.rpe->trans_rmse_m, 4) : "")
	  << ',' << (r.rpe ? fmt(r.rpe->yaw_rmse_deg, 3) : "") << ','
	  << (m ? fmt(m->yaw_rmse_deg, 3) : "") << ',' << (m ? fmt(m->nees_mean, 3) : "") << ','
	  << (m ? fmt(m->nees_band_low, 3) : "") << ',' << (m ? fmt(m->nees_band_high, 3) : "") << ','
	  << (m ? (neesInside(*m) ? "yes" : "no") : "") << ',' << s.first_fix_step << ','
	  << (s.first_fix_step >= 0 ? fmt(s.first_fix_time_s, 2) : "") << ',' << s.sightings_used << ','
	  << s.sightings_rejected << ',' << fmt(s.time_per_step_ms, 4) << ',' << fmt(r.wall_s, 2) << ','
	  << clean(r.error) << ',' << fmt(s.nis_mean, 4) << ',' << fmt(s.nis_dof, 3) << ','
	  << s.nis_count << ',' << fmt(s.gated_fraction, 4) << ',' << clean(s.nis_verdict) << ','
	  << (s.prediction.verdict.empty() ? "" : fmt(s.prediction.ratio, 4)) << ','
	  << clean(s.prediction.verdict);
	return o.str();
}

namespace
{
const cv::Scalar kMethodColours[] = {{200, 60, 0},	{0, 0, 210},   {170, 0, 170},
									 {0, 140, 230}, {120, 120, 0}, {80, 80, 80}};

// A panel of an error plot: |position error| and the 3-sigma bound against
// time since the first frame.
void drawErrorPanel(
	cv::Mat& img, const cv::Rect& box, const JobResult& r, double t0, double t1, double ymax,
	const cv::Scalar& colour)
{
	cv::rectangle(img, box, cv::Scalar(0, 0, 0));
	auto px = [&](double t, double v)
	{
		return cv::Point(
			box.x + static_cast<int>((t - t0) / (t1 - t0) * box.width),
			box.y + box.height - static_cast<int>(std::min(v, ymax) / ymax * box.height));
	};
	// Horizontal grid: five ticks of error.
	const double tick = ymax / 5;
	for (int k = 1; k < 5; ++k)
	{
		cv::line(img, px(t0, k * tick), px(t1, k * tick), cv::Scalar(225, 225, 225));
		cv::putText(
			img, fmt(k * tick * 100, tick < 0.01 ? 2 : 1) + " cm",
			cv::Point(box.x - 52, px(t0, k * tick).y + 4), cv::FONT_HERSHEY_SIMPLEX, 0.35,
			cv::Scalar(120, 120, 120), 1, cv::LINE_AA);
	}
	// Vertical grid: every 5 s (every 30 s on long runs), labelled.
	const double every_s = t1 - t0 > 120 ? 30 : 5;
	for (double t = every_s; t < t1 - t0; t += every_s)
	{
		cv::line(img, px(t0 + t, 0), px(t0 + t, ymax), cv::Scalar(235, 235, 235));
		cv::putText(
			img, fmt(t, 0) + " s", px(t0 + t, 0) + cv::Point(-8, 12), cv::FONT_HERSHEY_SIMPLEX,
			0.33, cv::Scalar(140, 140, 140), 1, cv::LINE_AA);
	}
	std::vector<cv::Point> err, bound;
	for (const auto& row : r.summary.rows)
	{
		if (!row.estimate.initialized || !row.truth) continue;
		const double t = row.timestamp;
		const double e = std::hypot(
			row.estimate.mean.x() - row.truth->x(), row.estimate.mean.y() - row.truth->y());
		Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(row.estimate.cov.block<2, 2>(0, 0));
		const double b = 3 * std::sqrt(std::max(0.0, es.eigenvalues()[1]));
		err.push_back(px(t, e));
		bound.push_back(px(t, b));
	}
	if (bound.size() > 1) cv::polylines(img, bound, false, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	if (err.size() > 1) cv::polylines(img, err, false, colour, 2, cv::LINE_AA);
	cv::putText(
		img,
		r.method + ": |position error| (colour), 3-sigma bound (black)" +
			(r.method == "ekf-slam" ? "; in the map frame, unaligned" : ""),
		cv::Point(box.x, box.y - 7), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1,
		cv::LINE_AA);
}

// A panel of a NIS plot: each sighting's NIS over its degrees of freedom
// (dots, log scale) and its mean over the last 5 s (line) against time,
// with the consistent band [0.5, 2] of the run's mean.
void drawNisPanel(
	cv::Mat& img, const cv::Rect& box, const JobResult& r, double t0, double t1,
	const cv::Scalar& colour)
{
	constexpr double lo = 0.01, hi = 100.0;
	cv::rectangle(img, box, cv::Scalar(0, 0, 0));
	auto px = [&](double t, double v)
	{
		const double f = (std::log10(std::clamp(v, lo, hi)) - std::log10(lo)) /
						 (std::log10(hi) - std::log10(lo));
		return cv::Point(
			box.x + static_cast<int>((t - t0) / (t1 - t0) * box.width),
			box.y + box.height - static_cast<int>(f * box.height));
	};
	for (const double v : {filters::kNisConsistentLow, filters::kNisConsistentHigh})
		cv::line(img, px(t0, v), px(t1, v), cv::Scalar(150, 200, 150), 2);
	// Decades, labelled at the right edge below their line.
	for (const double v : {0.01, 0.1, 1.0, 10.0})
	{
		cv::line(img, px(t0, v), px(t1, v), cv::Scalar(225, 225, 225));
		cv::putText(
			img, fmt(v, v < 0.1 ? 2 : (v < 1 ? 1 : 0)), cv::Point(box.x - 40, px(t0, v).y + 4),
			cv::FONT_HERSHEY_SIMPLEX, 0.35, cv::Scalar(120, 120, 120), 1, cv::LINE_AA);
	}
	const double every_s = t1 - t0 > 120 ? 30 : 5;
	for (double t = every_s; t < t1 - t0; t += every_s)
		cv::putText(
			img, fmt(t, 0) + " s", px(t0 + t, lo) + cv::Point(-8, 12), cv::FONT_HERSHEY_SIMPLEX,
			0.33, cv::Scalar(140, 140, 140), 1, cv::LINE_AA);
	std::vector<std::pair<double, double>> points;	// time, NIS / DoF
	for (const auto& row : r.summary.rows)
		for (const auto& in : row.stats.innovations)
			if (std::isfinite(in.nis) && in.dof > 0)
				points.emplace_back(row.timestamp, in.nis / in.dof);
	std::vector<cv::Point> mean_line;
	for (std::size_t i = 0; i < points.size(); ++i)
	{
		const auto& [t, v] = points[i];
		cv::circle(img, px(t, v), 2, colour, cv::FILLED, cv::LINE_AA);
		double sum = 0;
		int n = 0;
		for (std::size_t j = i + 1; j-- > 0 && points[j].first > t - 5.0;)
			sum += points[j].second, ++n;
		mean_line.push_back(px(t, sum / n));
	}
	if (mean_line.size() > 1)
		cv::polylines(img, mean_line, false, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	cv::putText(
		img, r.method + ": each sighting (dots), mean over 5 s (black); " + r.summary.nis_verdict,
		cv::Point(box.x, box.y - 7), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1,
		cv::LINE_AA);
}
}  // namespace

std::vector<std::string> writeDatasetPlots(
	const std::string& name, const std::vector<const JobResult*>& jobs, const std::string& map_file,
	const std::string& dir)
{
	std::vector<std::string> files;
	std::vector<const JobResult*> ok;
	for (auto* j : jobs)
		if (j->ok) ok.push_back(j);
	if (ok.empty()) return files;

	// Error against time, one panel per method, each with its own scale:
	// 1.2 x the 95th percentile of its errors and bounds (the first frames'
	// wide bounds and a diverging method are clipped at the top).
	double t0 = 1e300, t1 = -1e300;
	for (auto* j : ok)
		for (const auto& row : j->summary.rows)
			t0 = std::min(t0, row.timestamp), t1 = std::max(t1, row.timestamp);
	if (!(t1 > t0)) t1 = t0 + 1;
	auto scaleOf = [](const JobResult& j)
	{
		std::vector<double> values;
		for (const auto& row : j.summary.rows)
		{
			if (!row.estimate.initialized || !row.truth) continue;
			values.push_back(std::hypot(
				row.estimate.mean.x() - row.truth->x(), row.estimate.mean.y() - row.truth->y()));
			Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(row.estimate.cov.block<2, 2>(0, 0));
			values.push_back(3 * std::sqrt(std::max(0.0, es.eigenvalues()[1])));
		}
		if (values.empty()) return 0.05;
		std::sort(values.begin(), values.end());
		return std::max(0.005, 1.2 * values[static_cast<std::size_t>(0.95 * (values.size() - 1))]);
	};
	// A figure of one panel per method, each with a label line above its
	// box and its ticks' labels in the margins.
	const auto writePanels =
		[&](const std::string& suffix, const std::string& title,
			const std::function<void(cv::Mat&, const cv::Rect&, std::size_t)>& draw)
	{
		const int W = 900, ph = 150, margin = 34, top = 45;
		cv::Mat img(
			top + static_cast<int>(ok.size()) * (ph + margin), W, CV_8UC3,
			cv::Scalar(255, 255, 255));
		cv::putText(
			img, name + ": " + title, cv::Point(10, 17), cv::FONT_HERSHEY_SIMPLEX, 0.42,
			cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
		for (std::size_t k = 0; k < ok.size(); ++k)
			draw(img, cv::Rect(60, top + static_cast<int>(k) * (ph + margin), W - 70, ph), k);
		const std::string file = name + suffix;
		if (!cv::imwrite(dir + "/" + file, img, {cv::IMWRITE_PNG_COMPRESSION, 9}))
			throw std::runtime_error(dir + "/" + file + ": cannot write");
		files.push_back(file);
	};
	writePanels(
		"-error.png",
		"position error against time [" + fmt(t1 - t0, 0) +
			" s], 3-sigma = 3 sqrt(largest eigenvalue of the xy covariance)",
		[&](cv::Mat& img, const cv::Rect& box, std::size_t k)
		{ drawErrorPanel(img, box, *ok[k], t0, t1, scaleOf(*ok[k]), kMethodColours[k % 6]); });
	// Innovation consistency against time.
	writePanels(
		"-nis.png",
		"NIS / DoF against time [" + fmt(t1 - t0, 0) +
			" s], log scale; green: the band [0.5, 2] of a consistent mean",
		[&](cv::Mat& img, const cv::Rect& box, std::size_t k)
		{ drawNisPanel(img, box, *ok[k], t0, t1, kMethodColours[k % 6]); });

	// Trajectories: ground truth, every method, the landmarks.
	const LandmarkMap map = filters::isMrptLandmarksFile(map_file)
								? filters::loadMrptLandmarksFile(map_file)
								: LandmarkMap::load(map_file);
	double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
	auto grow = [&](double x, double y)
	{ x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y); };
	for (const auto& l : map.landmarks) grow(l.x_m, l.y_m);
	for (const auto& row : ok.front()->summary.rows)
		if (row.truth) grow(row.truth->x(), row.truth->y());
	if (x0 > x1) x0 = y0 = -1, x1 = y1 = 1;
	// Estimates far outside the map (a diverged filter) are clipped.
	x0 -= 0.7, y0 -= 0.7, x1 += 0.7, y1 += 0.7;
	const int TW = 900;
	const double scale = (TW - 20) / std::max(x1 - x0, 1e-3);
	const int TH = std::clamp(
		static_cast<int>((y1 - y0) * scale) + 20 + 20 * static_cast<int>(ok.size() + 1), 200, 3000);
	cv::Mat tr(TH, TW, CV_8UC3, cv::Scalar(255, 255, 255));
	auto P = [&](double x, double y)
	{
		return cv::Point(
			10 + static_cast<int>((x - x0) * scale), TH - 10 - static_cast<int>((y - y0) * scale));
	};
	for (int g = static_cast<int>(std::ceil(x0)); g <= x1; ++g)
		cv::line(tr, P(g, y0), P(g, y1), cv::Scalar(230, 230, 230));
	for (int g = static_cast<int>(std::ceil(y0)); g <= y1; ++g)
		cv::line(tr, P(x0, g), P(x1, g), cv::Scalar(230, 230, 230));
	for (const auto& l : map.landmarks)
	{
		cv::circle(tr, P(l.x_m, l.y_m), 4, cv::Scalar(0, 0, 0), cv::FILLED, cv::LINE_AA);
		cv::line(
			tr, P(l.x_m, l.y_m),
			P(l.x_m + 0.25 * std::cos(l.yaw_rad), l.y_m + 0.25 * std::sin(l.yaw_rad)),
			cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
		cv::putText(
			tr, std::to_string(l.id), P(l.x_m, l.y_m) + cv::Point(5, -5), cv::FONT_HERSHEY_SIMPLEX,
			0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	}
	std::vector<cv::Point> gt;
	for (const auto& row : ok.front()->summary.rows)
		if (row.truth) gt.push_back(P(row.truth->x(), row.truth->y()));
	if (gt.size() > 1) cv::polylines(tr, gt, false, cv::Scalar(0, 170, 0), 3, cv::LINE_AA);
	cv::putText(
		tr, name + ": ground truth (green), landmarks (black, with normals), 1 m grid",
		cv::Point(10, 16), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	for (std::size_t k = 0; k < ok.size(); ++k)
	{
		// ekf-slam's path lives in the frame of its first fix: drawn aligned.
		const bool align = ok[k]->method == "ekf-slam" && ok[k]->aligned;
		const mrpt::poses::CPose2D A =
			align ? ok[k]->aligned->truth_T_estimate : mrpt::poses::CPose2D();
		const Eigen::Rotation2Dd R(A.phi());
		const Eigen::Vector2d t = align ? Eigen::Vector2d(A.x(), A.y()) : Eigen::Vector2d::Zero();
		std::vector<cv::Point> est;
		for (const auto& row : ok[k]->summary.rows)
			if (row.estimate.initialized)
			{
				const Eigen::Vector2d p =
					R * Eigen::Vector2d(row.estimate.mean.x(), row.estimate.mean.y()) + t;
				est.push_back(P(p.x(), p.y()));
			}
		if (est.size() > 1) cv::polylines(tr, est, false, kMethodColours[k % 6], 1, cv::LINE_AA);
		std::string label = ok[k]->method;
		if (align) label += " (its own frame, aligned onto the ground truth)";
		cv::putText(
			tr, label, cv::Point(10, 16 + 20 * static_cast<int>(k + 1)), cv::FONT_HERSHEY_SIMPLEX,
			0.45, kMethodColours[k % 6], 1, cv::LINE_AA);
	}
	const std::string tr_file = name + "-trajectories.png";
	if (!cv::imwrite(dir + "/" + tr_file, tr, {cv::IMWRITE_PNG_COMPRESSION, 9}))
		throw std::runtime_error(dir + "/" + tr_file + ": cannot write");
	files.push_back(tr_file);
	return files;
}

namespace
{
std::string machine()
{
	std::string cpu = "unknown CPU";
	std::ifstream in("/proc/cpuinfo");
	std::string line;
	while (std::getline(in, line))
		if (line.rfind("model name", 0) == 0)
		{
			cpu = line.substr(line.find(':') + 2);
			break;
		}
	char host[256] = {0};
	gethostname(host, sizeof(host) - 1);
	return cpu + ", " + std::to_string(std::thread::hardware_concurrency()) +
		   " hardware threads (host " + host + ")";
}

std::string cell(const std::optional<double>& v, int decimals)
{
	return v ? fmt(*v, decimals) : "–";
}
}  // namespace

std::string markdownReport(
	const BenchConfig& cfg, const std::vector<JobResult>& results,
	const std::vector<std::pair<std::string, std::vector<std::string>>>& plots, int jobs,
	double total_wall_s)
{
	std::ostringstream o;
	const std::time_t now = std::time(nullptr);
	char date[64];
	std::strftime(date, sizeof(date), "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
	o << "# codemark-bench report\n\n";
	o << "- Date: " << date << "\n- Machine: " << machine() << "\n- Benchmark ini: `" << cfg.file
	  << "`; method inis: `" << cfg.config_dir << "`\n- " << cfg.datasets.size() << " datasets x "
	  << cfg.methods.size() << " methods = " << results.size() << " jobs on " << jobs
	  << " threads; total wall time " << fmt(total_wall_s, 1) << " s\n\n";

	// Headline: per method, the mean over the datasets where it ran.
	o << "## Summary (mean over the datasets)\n\n";
	o << "| method | runs ok | ATE [m] | ATE aligned [m] | RPE [m / " << fmt(cfg.rpe_interval_s, 1)
	  << " s] | yaw RMSE [deg] | mean NEES | NEES inside 95% band | first fix [s] | filter ms/step "
		 "|\n";
	o << "|---|---|---|---|---|---|---|---|---|---|\n";
	for (const auto& m : cfg.methods)
	{
		int n = 0, inside = 0, with_m = 0, with_rpe = 0, with_al = 0, with_fix = 0, runs = 0;
		double ate = 0, al = 0, rpe = 0, yaw = 0, nees = 0, fix = 0, ms = 0;
		for (const auto& r : results)
		{
			if (r.method != m) continue;
			++runs;
			if (!r.ok) continue;
			++n;
			ms += r.summary.time_per_step_ms;
			if (r.summary.metrics)
			{
				++with_m;
				ate += r.summary.metrics->ate_rmse_m, yaw += r.summary.metrics->yaw_rmse_deg;
				nees += r.summary.metrics->nees_mean;
				inside += neesInside(*r.summary.metrics);
			}
			if (r.rpe) ++with_rpe, rpe += r.rpe->trans_rmse_m;
			if (r.aligned) ++with_al, al += r.aligned->ate_m;
			if (r.summary.first_fix_step >= 0) ++with_fix, fix += r.summary.first_fix_time_s;
		}
		auto mean = [](double s, int k) { return k ? std::optional<double>(s / k) : std::nullopt; };
		o << "| " << m << " | " << n << "/" << runs << " | " << cell(mean(ate, with_m), 4) << " | "
		  << cell(mean(al, with_al), 4) << " | " << cell(mean(rpe, with_rpe), 4) << " | "
		  << cell(mean(yaw, with_m), 2) << " | " << cell(mean(nees, with_m), 2) << " | " << inside
		  << "/" << with_m << " | " << cell(mean(fix, with_fix), 2) << " | " << cell(mean(ms, n), 3)
		  << " |\n";
	}

	o << "\n## Per dataset and method\n\n";
	o << "| dataset | method | steps | detection rate | sighting rate | wrong IDs | detect "
		 "ms/frame | ATE [m] | "
		 "ATE aligned [m] | max err [m] | RPE [m] | RPE yaw [deg] | yaw RMSE [deg] | mean NEES "
		 "[95% band] | "
		 "first fix [s] | filter ms/step | wall [s] | NIS/DoF: verdict |\n";
	o << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
	for (const auto& r : results)
	{
		const auto& s = r.summary;
		const auto& d = r.detection;
		if (!r.ok)
		{
			o << "| " << r.dataset << " | " << r.method << " | error: " << clean(r.error)
			  << " | | | | | | | | | | | | | | " << fmt(r.wall_s, 1) << " | |\n";
			continue;
		}
		const auto& m = s.metrics;
		auto pct = [](const std::optional<double>& v)
		{ return v ? fmt(100 * *v, 1) + "%" : std::string("–"); };
		o << "| " << r.dataset << " | " << r.method << " | " << s.steps << " | "
		  << pct(ratio(d.frames_detected, d.frames_in_view)) << " | "
		  << pct(ratio(d.sightings_detected, d.sightings_in_view)) << " | "
		  << (d.frames ? std::to_string(d.wrong_ids) : "–") << " | "
		  << (d.images ? fmt(d.detect_ms_per_image, 2) : "–") << " | "
		  << (m ? fmt(m->ate_rmse_m, 4) : "–") << " | "
		  << (r.aligned ? fmt(r.aligned->ate_m, 4) : "–") << " | "
		  << (m ? fmt(m->max_error_m, 3) : "–") << " | "
		  << (r.rpe ? fmt(r.rpe->trans_rmse_m, 4) : "–") << " | "
		  << (r.rpe ? fmt(r.rpe->yaw_rmse_deg, 2) : "–") << " | "
		  << (m ? fmt(m->yaw_rmse_deg, 2) : "–") << " | ";
		if (m)
			o << fmt(m->nees_mean, 2) << " [" << fmt(m->nees_band_low, 2) << ", "
			  << fmt(m->nees_band_high, 2) << "] " << (neesInside(*m) ? "in" : "**out**");
		else
			o << "–";
		o << " | " << (s.first_fix_step >= 0 ? fmt(s.first_fix_time_s, 1) : "never") << " | "
		  << fmt(s.time_per_step_ms, 3) << " | " << fmt(r.wall_s, 1) << " | "
		  << (s.nis_count ? fmt(s.nis_mean / s.nis_dof, 2) + ": " : std::string()) << s.nis_verdict
		  << (s.prediction.off() ? "; the prediction (" + s.prediction.components + ") " +
									   fmt(s.prediction.ratio, 2) + ": " + s.prediction.verdict
								 : std::string())
		  << " |\n";
	}

	o << "\n## Definitions\n\n"
		 "- **detection rate**: frames where at least one landmark is in view according to the "
		 "ground truth (fully "
		 "visible, facing the camera, reference square spanning >= "
	  << fmt(cfg.min_span_px, 0)
	  << " px, seen within the method ini's [stepper] max_view_angle_deg of its normal, beyond "
		 "which sightings are dropped before the filter) and at least one of those was detected "
		 "with its right ID, over the frames with one in view. "
		 "**sighting rate**: the same per landmark and frame. **wrong IDs**: detections of an ID "
		 "that no landmark "
		 "in (even partial) view carries. Computed from the landmark observations of every camera "
		 "frame (detected "
		 "on the fly when the rawlog holds images, read when it is annotated).\n"
		 "- **detect ms/frame**: wall time per image of reading it from disk, decoding, detecting "
		 "and measuring "
		 "(– for pre-annotated rawlogs).\n"
		 "- **ATE**: RMS of the position error against the ground truth over the frames from the "
		 "first fix on, "
		 "in the map frame; **ATE aligned**: the same after the least-squares rigid 2D alignment "
		 "(rotation and "
		 "translation) of the estimated path onto the true one, the figure to read for ekf-slam, "
		 "whose map and "
		 "path live in the frame of its first fix.\n"
		 "- **RPE**: for each frame i the first frame j at least "
	  << fmt(cfg.rpe_interval_s, 1)
	  << " s later, the error (gt_i^-1 gt_j)^-1 (est_i^-1 est_j); RMS of its translation [m] and "
		 "rotation [deg].\n"
		 "- **yaw RMSE**: RMS of the wrapped yaw error. **mean NEES**: mean of e^T P^-1 e over the "
		 "frames "
		 "(3 DoF: x, y, yaw), with the two-sided 95% band of the mean of a consistent filter, "
		 "chi2inv(0.025 / "
		 "0.975, 3N) / N; for ekf-slam unaligned, so not meaningful.\n"
		 "- **first fix**: time from the first camera frame to the first frame with an estimate "
		 "(global "
		 "initialisation from an unknown start, unless the method ini gives an initial pose).\n"
		 "- **filter ms/step**: mean wall time of one filter step (prediction + update), on one "
		 "core of a loaded "
		 "machine (jobs run in parallel). **wall**: the job's total, including reading, detection "
		 "and outputs.\n"
		 "- **NIS/DoF: verdict**: summary.json's mean NIS over its degrees of freedom and "
		 "`nis_verdict`; then, when it reads outside [0.5, 2], `prediction_check`: the "
		 "components the sightings barely inform (the bearing), which judge the filter's "
		 "prediction (its motion noise), not the sightings.\n"
		 "- Each job's spec section 6 outputs (estimated_path.txt, covariances.txt, summary.json, "
		 "trajectory.png, "
		 "...) are in `<dataset>/<method>/`.\n";

	if (!plots.empty())
	{
		o << "\n## Plots\n";
		for (const auto& [name, files] : plots)
		{
			o << "\n### " << name << "\n\n";
			for (const auto& f : files) o << "![" << f << "](" << f << ")\n";
		}
	}
	return o.str();
}

}  // namespace codemark::bench
