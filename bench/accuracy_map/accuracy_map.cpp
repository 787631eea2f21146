#include "accuracy_map.h"

#include <mrpt/math/distributions.h>
#include <codemark/detect/detector.h>
#include <codemark/landmark/truth.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pose/consistency.h>
#include <codemark/pose/general.h>
#include <codemark/sim/dataset.h>
#include <codemark/sim/camera_pipeline.h>
#include <codemark/sim/render.h>

extern "C"
{
#include <apriltag.h>
#include <tag36h11.h>
}

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

namespace codemark::accuracy
{
namespace
{
using mrpt::poses::CPose3D;

std::string fmt(double v, int prec)
{
	std::ostringstream s;
	s << std::fixed << std::setprecision(prec) << v;
	return s.str();
}

/** MethodErrors::means()' order, as the CSV names them. */
constexpr const char* kMetricNames[7] = {"l2_m", "phi1_rad",  "phi2_rad",  "x_m",
										 "y_m",	 "theta_rad", "position_m"};

// Errors of one measurement against the truth, accumulated into \a e.
void accumulate(MethodErrors& e, const pose::Measurement& m, const SightingTruth& t)
{
	const Eigen::Vector3d dL(m.L[0] - t.L[0], wrapToPi(m.L[1] - t.L[1]), wrapToPi(m.L[2] - t.L[2]));
	const Eigen::Vector3d dR(
		m.pose_in_landmark[0] - t.pose_in_landmark[0],
		m.pose_in_landmark[1] - t.pose_in_landmark[1],
		wrapToPi(m.pose_in_landmark[2] - t.pose_in_landmark[2]));
	++e.detected;
	// MethodErrors::means()' order.
	const std::array<double, 7> abs_err{std::abs(dL[0]),	std::abs(dL[1]), std::abs(dL[2]),
										std::abs(dR[0]),	std::abs(dR[1]), std::abs(dR[2]),
										dR.head<2>().norm()};
	double* sums[7] = {&e.l2_m, &e.phi1_rad,  &e.phi2_rad,	&e.x_m,
					   &e.y_m,	&e.theta_rad, &e.position_m};
	for (int k = 0; k < 7; ++k)
	{
		*sums[k] += abs_err[k];
		e.sum_sq[k] += abs_err[k] * abs_err[k];
	}
	const double nees = dR.dot(m.C_R.ldlt().solve(dR));
	e.nees += nees;
	e.nees_L += dL.dot(m.C_L.ldlt().solve(dL));
	if (std::sqrt(m.C_L(2, 2)) <= 2 * M_PI / 180)
	{
		e.nees_small_phi2_sum += nees;
		++e.nees_small_phi2_n;
	}
}

void finish(MethodErrors& e)
{
	if (e.detected == 0) return;
	const double n = e.detected;
	for (double* v :
		 {&e.l2_m, &e.phi1_rad, &e.phi2_rad, &e.x_m, &e.y_m, &e.theta_rad, &e.position_m, &e.nees,
		  &e.nees_L})
		*v /= n;
	const auto mean = e.means();
	for (int k = 0; k < 7; ++k)
		e.se[k] = e.detected > 1
					  ? std::sqrt(std::max(0.0, e.sum_sq[k] / n - mean[k] * mean[k]) / (n - 1))
					  : INFINITY;
}

// AprilTag 3 tag36h11 #0, 10 x 10 cells including its white border; the
// detected corners are the outer corners of the black border (8 cells).
struct TagRenderer
{
	std::vector<uint8_t> cells;	 // 10 x 10, row 0 at the top as seen from the front
	int n = 10;
	double cell_m;

	explicit TagRenderer(double corner_square_m) : cell_m(corner_square_m / 8.0)
	{
		apriltag_family_t* tf = tag36h11_create();
		image_u8_t* im = apriltag_to_image(tf, 0);
		n = im->width;
		cells.resize(n * n);
		for (int r = 0; r < n; ++r)
			for (int c = 0; c < n; ++c) cells[r * n + c] = im->buf[r * im->stride + c];
		image_u8_destroy(im);
		tag36h11_destroy(tf);
	}

	// Grey value seen along a ray from o with direction d (frame L), or -1
	// for the background.
	int sample(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const
	{
		if (d.x() >= 0) return -1;
		const double lam = -o.x() / d.x();
		const double s = o.y() + lam * d.y(), t = o.z() + lam * d.z();
		const int col = static_cast<int>(std::floor(s / cell_m + 0.5 * n));
		const int row = static_cast<int>(std::floor(0.5 * n - t / cell_m));
		if (col < 0 || row < 0 || col >= n || row >= n) return -1;
		return cells[row * n + col] ? 235 : 25;	 // printed white / black, as the renderer
	}

	// Pinhole render (the camera's distortion is ignored: the survey uses an
	// undistorted camera), area-sampled: 4 x 4 samples, 32 x 32 where they
	// disagree (edge position error about 1/64 px), then blur and noise.
	/** \a camera_stages: codemark's render options when a camera preset is
	 * set (the tag then goes through the same camera pipeline), else null
	 * and the tag gets \a blur and \a noise. */
	cv::Mat render(
		const CameraModel& cam, const CPose3D& landmark_T_camera, double blur, double noise,
		uint64_t seed, const sim::RenderOptions* camera_stages = nullptr) const
	{
		const Eigen::Matrix3d R = landmark_T_camera.getRotationMatrix().asEigen();
		const Eigen::Vector3d o(
			landmark_T_camera.x(), landmark_T_camera.y(), landmark_T_camera.z());
		const double bg = 128;
		cv::Mat img(cam.height(), cam.width(), CV_32F);
		const auto value = [&](double u, double v)
		{
			const Eigen::Vector3d d =
				R * Eigen::Vector3d((u - cam.cx()) / cam.fx(), (v - cam.cy()) / cam.fy(), 1);
			const int g = sample(o, d);
			return g < 0 ? bg : g;
		};
		for (int v = 0; v < cam.height(); ++v)
			for (int u = 0; u < cam.width(); ++u)
			{
				double sum = 0, first = -1;
				bool same = true;
				for (int j = 0; j < 4; ++j)
					for (int i = 0; i < 4; ++i)
					{
						const double g = value(u - 0.5 + (i + 0.5) / 4, v - 0.5 + (j + 0.5) / 4);
						if (first < 0) first = g;
						same = same && g == first;
						sum += g;
					}
				if (!same)
				{
					sum = 0;
					for (int j = 0; j < 32; ++j)
						for (int i = 0; i < 32; ++i)
							sum += value(u - 0.5 + (i + 0.5) / 32, v - 0.5 + (j + 0.5) / 32);
					img.at<float>(v, u) = static_cast<float>(sum / 1024);
				}
				else
					img.at<float>(v, u) = static_cast<float>(sum / 16);
			}
		if (camera_stages)
		{
			cv::Mat bgr;
			cv::cvtColor(img, bgr, cv::COLOR_GRAY2BGR);
			const cv::Mat out = sim::cameraImage(
				bgr, camera_stages->drawn(seed), cam.cx(), cam.cy(), seed * 7919 + 17);
			cv::Mat grey;
			cv::cvtColor(out, grey, cv::COLOR_BGR2GRAY);
			return grey;
		}
		if (blur > 0) cv::GaussianBlur(img, img, cv::Size(0, 0), blur);
		if (noise > 0)
		{
			cv::Mat n(img.size(), CV_32F);
			cv::RNG rng(seed * 7919 + 17);
			rng.fill(n, cv::RNG::NORMAL, 0, noise);
			img += n;
		}
		cv::Mat out;
		img.convertTo(out, CV_8U);
		return out;
	}
};

struct TagDetector
{
	apriltag_family_t* tf;
	apriltag_detector_t* td;
	TagDetector()
	{
		tf = tag36h11_create();
		td = apriltag_detector_create();
		apriltag_detector_add_family(td, tf);
		td->quad_decimate = 1.0;  // full resolution: best corners
		td->quad_sigma = 0.0;
		td->refine_edges = true;
		td->nthreads = 1;
	}
	~TagDetector()
	{
		apriltag_detector_destroy(td);
		tag36h11_destroy(tf);
	}
	TagDetector(const TagDetector&) = delete;
	TagDetector& operator=(const TagDetector&) = delete;

	// AprilTag 3 puts (0.5, 0.5) at the centre of the top-left pixel
	// (AprilRobotics/apriltag issue #121, confirmed by its maintainer; our
	// noise-free renders give a mean offset of (+0.43, +0.47) px without this
	// correction): shift to the spec's convention, (0, 0) at that centre.
	static Eigen::Vector2d corner(const apriltag_detection_t* det, int j)
	{
		return {det->p[j][0] - 0.5, det->p[j][1] - 0.5};
	}

	// Corners of tag #0, matched to the nearest of \a expected (TL TR BR BL).
	bool detect(
		const cv::Mat& grey, const std::array<Eigen::Vector2d, 4>& expected,
		std::array<Eigen::Vector2d, 4>& out) const
	{
		image_u8_t im{grey.cols, grey.rows, static_cast<int32_t>(grey.step), grey.data};
		zarray_t* dets = apriltag_detector_detect(td, &im);
		bool found = false;
		for (int i = 0; i < zarray_size(dets) && !found; ++i)
		{
			apriltag_detection_t* det = nullptr;
			zarray_get(dets, i, &det);
			if (det->id != 0) continue;
			found = true;
			for (int k = 0; k < 4; ++k)
			{
				int best = 0;
				double bd = 1e18;
				for (int j = 0; j < 4; ++j)
				{
					const double dd = (corner(det, j) - expected[k]).squaredNorm();
					if (dd < bd)
					{
						bd = dd;
						best = j;
					}
				}
				out[k] = corner(det, best);
			}
		}
		apriltag_detections_destroy(dets);
		return found;
	}
};
}  // namespace

std::vector<CellResult> runSurvey(
	const CameraModel& camera, const SurveyOptions& o,
	const std::function<void(long, long)>& progress)
{
	if (!(o.cell_m > 0) || o.renders_per_cell < 1)
		throw std::invalid_argument("survey: cell_m must be > 0 and renders_per_cell >= 1");
	sim::Scene scene = sim::singleLandmarkScene(camera);
	const MapLandmark& lm = scene.map.landmarks[0];
	sim::RenderOptions ro =
		o.realistic ? sim::DatasetOptions::realisticRender() : sim::RenderOptions();
	ro.noise_sigma = o.noise_sigma;
	ro.blur_sigma_px = o.blur_sigma_px;
	if (!o.preset.empty()) ro.applyPreset(o.preset);
	const LandmarkGeometry g = lm.geometry();
	const detect::DetectorOptions& dopt = o.detector;
	pose::PoseOptions cf = o.pose, gen = o.pose;
	cf.method = pose::PoseMethod::ClosedForm;
	gen.method = pose::PoseMethod::General6Dof;
	const TagRenderer tag(g.inner_size_m);
	const TagDetector tagdet;

	std::vector<CellResult> cells;
	for (double X = o.cell_m; X <= o.max_distance_m + 1e-9; X += o.cell_m)
		for (double Y = 0; Y <= o.max_distance_m + 1e-9; Y += o.cell_m)
		{
			const double d = std::hypot(X, Y), a = std::atan2(Y, X) * 180 / M_PI;
			if (d < o.min_distance_m - 1e-9 || d > o.max_distance_m + 1e-9 ||
				a > o.max_angle_deg + 1e-9)
				continue;
			CellResult c;
			c.X_m = X;
			c.Y_m = Y;
			c.distance_m = d;
			c.angle_deg = a;
			cells.push_back(c);
		}

	long done = 0;
	for (CellResult& c : cells)
	{
		scene.world_T_camera =
			sim::levelCameraLookingAt(lm, c.distance_m, c.angle_deg * M_PI / 180);
		// Predicted sigmas at the exact corners of the cell's centred view.
		{
			const sim::Render exact = sim::render(scene, sim::RenderOptions(), o.seed);
			const pose::Measurement m = pose::measure(exact.truth[0].corners_px, camera, g, cf);
			c.sigma_l2_m = std::sqrt(m.C_L(0, 0));
			c.sigma_phi1_rad = std::sqrt(m.C_L(1, 1));
			c.sigma_phi2_rad = std::sqrt(m.C_L(2, 2));
			c.sigma_x_m = std::sqrt(m.C_R(0, 0));
			c.sigma_y_m = std::sqrt(m.C_R(1, 1));
		}
		for (int r = 0; r < o.renders_per_cell; ++r)
		{
			const uint64_t seed = o.seed + 1000003ull * done + r;
			// This render's aim and height (SurveyOptions::aim_jitter_rad).
			std::mt19937_64 aim_rng(seed ^ 0x9e3779b97f4a7c15ull);
			std::uniform_real_distribution<double> U(-1, 1);
			const double bearing = o.aim_jitter_rad * U(aim_rng),
						 height = o.height_jitter_m * U(aim_rng);
			scene.world_T_camera = sim::levelCameraLookingAt(
				lm, c.distance_m, c.angle_deg * M_PI / 180, height, bearing);
			const CPose3D landmark_T_camera = scene.world_T_camera - lm.world_T_landmark();
			const SightingTruth truth = sightingTruth(landmark_T_camera);
			const sim::Render img = o.renderer(scene, ro, seed);
			++c.renders;
			const auto res = detect::detect(img.image, camera, g, dopt);
			for (const auto& dl : res.landmarks)
			{
				if (dl.detection.id != lm.id) continue;
				for (int k = 0; k < 4; ++k)
				{
					const Eigen::Vector2d e = dl.detection.corners[k] - img.truth[0].corners_px[k];
					c.corner_dx_px += e.x() / 4;
					c.corner_dy_px += e.y() / 4;
					c.corner_rms_px += e.squaredNorm() / 8;
				}
				try
				{
					accumulate(c.closed_form, pose::measure(dl.detection, camera, g, cf), truth);
					accumulate(c.general, pose::measure(dl.detection, camera, g, gen), truth);
				}
				catch (const std::exception&)
				{
					// degenerate corners: counted as not detected
				}
				break;
			}
			if (o.apriltag)
			{
				const cv::Mat grey = tag.render(
					camera, landmark_T_camera, o.blur_sigma_px, o.noise_sigma, seed,
					o.preset.empty() ? nullptr : &ro);
				std::array<Eigen::Vector2d, 4> corners;
				if (tagdet.detect(grey, img.truth[0].corners_px, corners))
				{
					for (int k = 0; k < 4; ++k)
					{
						const Eigen::Vector2d e = corners[k] - img.truth[0].corners_px[k];
						c.tag_corner_dx_px += e.x() / 4;
						c.tag_corner_dy_px += e.y() / 4;
						c.tag_corner_rms_px += e.squaredNorm() / 8;
					}
					try
					{
						accumulate(c.apriltag, pose::measure(corners, camera, g, gen), truth);
					}
					catch (const std::exception&)
					{
					}
				}
			}
		}
		if (c.closed_form.detected)
		{
			c.corner_dx_px /= c.closed_form.detected;
			c.corner_dy_px /= c.closed_form.detected;
			c.corner_rms_px = std::sqrt(c.corner_rms_px / c.closed_form.detected);
		}
		if (c.apriltag.detected)
		{
			c.tag_corner_dx_px /= c.apriltag.detected;
			c.tag_corner_dy_px /= c.apriltag.detected;
			c.tag_corner_rms_px = std::sqrt(c.tag_corner_rms_px / c.apriltag.detected);
		}
		finish(c.closed_form);
		finish(c.general);
		finish(c.apriltag);
		if (progress) progress(++done, static_cast<long>(cells.size()));
	}
	return cells;
}

namespace
{
// Heat map of one metric: measured mean absolute error (left) beside the
// predicted sigma (right), one square per cell, X_L down and Y_L right as in
// Fig. 3, a shared logarithmic colour scale.
void heatMap(
	const std::vector<CellResult>& cells, const SurveyOptions& o, const std::string& path,
	const std::string& title, const std::string& unit, double to_unit,
	const std::function<double(const CellResult&)>& measured,
	const std::function<double(const CellResult&)>& predicted)
{
	const int cp = 56, header = 50, margin = 30;
	const int nx = static_cast<int>(std::lround(o.max_distance_m / o.cell_m));
	const int panel_w = (nx + 1) * cp, panel_h = nx * cp;
	cv::Mat img(
		header + panel_h + margin, 2 * panel_w + 3 * margin, CV_8UC3, cv::Scalar(255, 255, 255));
	double lo = 1e300, hi = 0;
	for (const auto& c : cells)
		for (const double v : {measured(c), predicted(c)})
			if (v > 0 && std::isfinite(v))
			{
				lo = std::min(lo, v);
				hi = std::max(hi, v);
			}
	if (!(hi > 0)) lo = hi = 1;
	const double llo = std::log10(lo), lhi = std::log10(hi) + 1e-9;
	for (int panel = 0; panel < 2; ++panel)
	{
		const int x0 = margin + panel * (panel_w + margin), y0 = header;
		cv::putText(
			img, panel == 0 ? "measured mean |error|" : "predicted sigma", cv::Point(x0, y0 - 8),
			cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
		for (const auto& c : cells)
		{
			const double v = panel == 0 ? measured(c) : predicted(c);
			const int col = static_cast<int>(std::lround(c.Y_m / o.cell_m));
			const int row = static_cast<int>(std::lround(c.X_m / o.cell_m)) - 1;
			const cv::Rect r(x0 + col * cp, y0 + row * cp, cp - 2, cp - 2);
			if (!(v > 0) || !std::isfinite(v))
			{
				cv::rectangle(img, r, cv::Scalar(200, 200, 200), cv::FILLED);
				cv::putText(
					img, "n/a", r.tl() + cv::Point(14, 32), cv::FONT_HERSHEY_SIMPLEX, 0.4,
					cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
				continue;
			}
			cv::Mat one(
				1, 1, CV_8U,
				cv::Scalar(static_cast<int>(255 * (std::log10(v) - llo) / (lhi - llo))));
			cv::Mat rgb;
			cv::applyColorMap(one, rgb, cv::COLORMAP_VIRIDIS);
			const cv::Vec3b k = rgb.at<cv::Vec3b>(0, 0);
			cv::rectangle(img, r, cv::Scalar(k[0], k[1], k[2]), cv::FILLED);
			const double lum = 0.114 * k[0] + 0.587 * k[1] + 0.299 * k[2];
			const cv::Scalar tc = lum > 128 ? cv::Scalar(0, 0, 0) : cv::Scalar(255, 255, 255);
			const double vu = v * to_unit;
			cv::putText(
				img,
				fmt(vu, vu < 1	   ? 3
						: vu < 10  ? 2
						: vu < 100 ? 1
								   : 0),
				r.tl() + cv::Point(4, 32), cv::FONT_HERSHEY_SIMPLEX, 0.4, tc, 1, cv::LINE_AA);
		}
		// The landmark above the first row at Y = 0.
		cv::rectangle(
			img, cv::Point(x0 - 6, y0 - 4), cv::Point(x0 + 6, y0 - 1), cv::Scalar(0, 160, 0),
			cv::FILLED);
	}
	cv::putText(
		img,
		title + " [" + unit + "]: rows X_L = " + fmt(o.cell_m, 1) + ".." +
			fmt(o.max_distance_m, 1) +
			" m down, columns Y_L = 0.. right; landmark (green) top-left",
		cv::Point(margin, 20), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
	if (!cv::imwrite(path, img)) throw std::runtime_error("cannot write " + path);
}

// Chi-square quantile of probability p with k degrees of freedom.
double chi2Quantile(double p, double k) { return mrpt::math::chi2inv(p, static_cast<unsigned>(k)); }
}  // namespace

std::string writeResults(
	const std::vector<CellResult>& cells, const SurveyOptions& o, const std::string& dir)
{
	std::filesystem::create_directories(dir);
	const std::string csv = dir + "/cells.csv";
	std::ofstream f(csv);
	if (!f) throw std::runtime_error("cannot write " + csv);
	f << "X_m,Y_m,distance_m,angle_deg,renders,sigma_l2_m,sigma_phi1_rad,sigma_phi2_rad,sigma_x_m,"
		 "sigma_y_m";
	for (const char* m : {"cf", "gen", "tag"})
		for (const char* k :
			 {"detected", "l2_m", "phi1_rad", "phi2_rad", "x_m", "y_m", "theta_rad", "position_m",
			  "nees"})
			f << "," << m << "_" << k;
	f << ",corner_dx_px,corner_dy_px,corner_rms_px,tag_corner_dx_px,tag_corner_dy_px,tag_corner_"
		 "rms_px";
	for (const char* k : {"cf", "gen", "tag"})
		for (const char* m : kMetricNames) f << "," << k << "_se_" << m;
	f << "\n" << std::setprecision(9);
	for (const auto& c : cells)
	{
		f << c.X_m << "," << c.Y_m << "," << c.distance_m << "," << c.angle_deg << "," << c.renders
		  << "," << c.sigma_l2_m << "," << c.sigma_phi1_rad << "," << c.sigma_phi2_rad << ","
		  << c.sigma_x_m << "," << c.sigma_y_m;
		for (const MethodErrors* e : {&c.closed_form, &c.general, &c.apriltag})
			f << "," << e->detected << "," << e->l2_m << "," << e->phi1_rad << "," << e->phi2_rad
			  << "," << e->x_m << "," << e->y_m << "," << e->theta_rad << "," << e->position_m
			  << "," << e->nees;
		f << "," << c.corner_dx_px << "," << c.corner_dy_px << "," << c.corner_rms_px << ","
		  << c.tag_corner_dx_px << "," << c.tag_corner_dy_px << "," << c.tag_corner_rms_px;
		for (const MethodErrors* e : {&c.closed_form, &c.general, &c.apriltag})
			for (const double se : e->se) f << "," << se;
		f << "\n";
	}

	const auto cf = [](const CellResult& c) -> const MethodErrors& { return c.closed_form; };
	heatMap(
		cells, o, dir + "/heat_l2.png", "l2 (range), closed form", "mm", 1000,
		[&](const CellResult& c) { return cf(c).detected ? cf(c).l2_m : NAN; },
		[](const CellResult& c) { return c.sigma_l2_m; });
	heatMap(
		cells, o, dir + "/heat_phi2.png", "phi2, closed form", "deg", 180 / M_PI,
		[&](const CellResult& c) { return cf(c).detected ? cf(c).phi2_rad : NAN; },
		[](const CellResult& c) { return c.sigma_phi2_rad; });
	heatMap(
		cells, o, dir + "/heat_x.png", "x of the camera in L, closed form", "mm", 1000,
		[&](const CellResult& c) { return cf(c).detected ? cf(c).x_m : NAN; },
		[](const CellResult& c) { return c.sigma_x_m; });
	heatMap(
		cells, o, dir + "/heat_y.png", "y of the camera in L, closed form", "mm", 1000,
		[&](const CellResult& c) { return cf(c).detected ? cf(c).y_m : NAN; },
		[](const CellResult& c) { return c.sigma_y_m; });

	// Region averages (over cells, each cell's mean over its detections).
	struct Region
	{
		std::string name;
		double dmin, dmax, amax;
		bool holds(const CellResult& c) const
		{
			return c.distance_m > dmin && c.distance_m <= dmax && c.angle_deg <= amax;
		}
	};
	const std::vector<Region> regions{
		{"within 2 m, all angles", 0, 2.0 + 1e-9, 90},
		{"within 2 m, in front (<= 30 deg)", 0, 2.0 + 1e-9, 30 + 1e-9},
		{"2 to 5 m, all angles", 2.0 + 1e-9, 5.0 + 1e-9, 90}};
	std::ostringstream s;
	s << "# codemark accuracy map: " << cells.size() << " cells of " << fmt(o.cell_m, 2) << " m, "
	  << o.renders_per_cell << " renders each by " << o.source_label << ", "
	  << (o.preset.empty()
			  ? "noise " + fmt(o.noise_sigma, 1) + ", blur " + fmt(o.blur_sigma_px, 2) + " px"
			  : "camera preset " + o.preset)
	  << ", C_P " << o.noise_label << ", "
	  << (o.realistic ? "realistic scene (textured wall, light gradient, distractors)"
					  : "plain background")
	  << ", closed form " << (o.pose.refine_on_primary ? "refined on P" : "paper's formulas alone")
	  << (o.pose.fold_ambiguity ? ", mirror-image solutions folded into C_L and C_R" : "")
	  << ", each render aimed off the landmark by up to " << fmt(o.aim_jitter_rad, 2) << " rad and "
	  << fmt(o.height_jitter_m, 2) << " m in height\n";
	s << "# mean absolute errors averaged over the region's cells; cf = closed form, gen = general "
		 "6-DoF,"
		 " tag = AprilTag 3 tag36h11 (same corner square) + general path (its NEES uses codemark's "
		 "sigma)\n";
	for (const Region& r : regions)
	{
		s << "\n## " << r.name << "\n";
		s << "metric            ";
		for (const char* m : {"cf", "gen", "tag"}) s << std::setw(12) << m;
		s << std::setw(14) << "pred sigma"
		  << "\n";
		struct Acc
		{
			double sum[3] = {0, 0, 0};
			int n[3] = {0, 0, 0};
			double pred = 0;
			int np = 0;
		};
		const auto row =
			[&](const std::string& name,
				const std::function<double(const MethodErrors&, const CellResult&)>& get,
				const std::function<double(const CellResult&)>& pred, double unit, int prec)
		{
			Acc a;
			int cells_total = 0, detected[3] = {0, 0, 0}, renders = 0;
			for (const auto& c : cells)
			{
				if (!r.holds(c)) continue;
				++cells_total;
				renders += c.renders;
				const MethodErrors* e[3] = {&c.closed_form, &c.general, &c.apriltag};
				for (int k = 0; k < 3; ++k)
				{
					detected[k] += e[k]->detected;
					if (e[k]->detected == 0) continue;
					a.sum[k] += get(*e[k], c);
					++a.n[k];
				}
				if (pred)
				{
					a.pred += pred(c);
					++a.np;
				}
			}
			s << std::left << std::setw(18) << name << std::right;
			for (int k = 0; k < 3; ++k)
				s << std::setw(12)
				  << (a.n[k] ? fmt(a.sum[k] / a.n[k] * unit, prec) : std::string("-"));
			s << std::setw(14) << (a.np ? fmt(a.pred / a.np * unit, prec) : std::string(""))
			  << "\n";
			return std::make_tuple(cells_total, renders, detected[0], detected[1], detected[2]);
		};
		row(
			"range [% of l2]",
			[](const MethodErrors& e, const CellResult& c) { return e.l2_m / c.distance_m; },
			[](const CellResult& c) { return c.sigma_l2_m / c.distance_m; }, 100, 4);
		row(
			"bearing phi1 [deg]",
			[](const MethodErrors& e, const CellResult&) { return e.phi1_rad; },
			[](const CellResult& c) { return c.sigma_phi1_rad; }, 180 / M_PI, 4);
		row(
			"phi2 [deg]", [](const MethodErrors& e, const CellResult&) { return e.phi2_rad; },
			[](const CellResult& c) { return c.sigma_phi2_rad; }, 180 / M_PI, 3);
		row(
			"x [mm]", [](const MethodErrors& e, const CellResult&) { return e.x_m; },
			[](const CellResult& c) { return c.sigma_x_m; }, 1000, 2);
		row(
			"y [mm]", [](const MethodErrors& e, const CellResult&) { return e.y_m; },
			[](const CellResult& c) { return c.sigma_y_m; }, 1000, 2);
		row(
			"position [mm]", [](const MethodErrors& e, const CellResult&) { return e.position_m; },
			{}, 1000, 2);
		row(
			"heading [deg]", [](const MethodErrors& e, const CellResult&) { return e.theta_rad; },
			{}, 180 / M_PI, 3);
		const auto [nc, nr, d0, d1, d2] = row(
			"mean NEES (3 dof)", [](const MethodErrors& e, const CellResult&) { return e.nees; },
			{}, 1, 2);
		row(
			"mean NEES of L", [](const MethodErrors& e, const CellResult&) { return e.nees_L; }, {},
			1, 2);
		{
			// Each cell's NEES sum and count in the region, path k (1: the
			// general one), over its sightings whose reported phi2 sigma is
			// at most 2 deg or over all.
			const auto clustersOf = [&](int k, bool small_phi2)
			{
				std::vector<pose::NeesCluster> clusters;
				for (const auto& c : cells)
				{
					if (!r.holds(c)) continue;
					const MethodErrors& e = k ? c.general : c.closed_form;
					// finish() made e.nees the cell's mean.
					clusters.push_back(
						small_phi2 ? pose::NeesCluster{e.nees_small_phi2_sum, e.nees_small_phi2_n}
								   : pose::NeesCluster{e.nees * e.detected, e.detected});
				}
				return clusters;
			};
			// Pose NEES pooled over the sightings whose reported phi2 sigma
			// is at most 2 deg, with its own 95% band.
			s << "pose NEES where sigma(phi2) <= 2 deg:";
			for (int k = 0; k < 2; ++k)
			{
				const pose::ClusteredMean m = pose::clusteredMean(clustersOf(k, true), 3);
				const int n = m.count;
				s << (k ? "; gen " : " cf ");
				if (n)
					s << fmt(m.mean, 2) << " over " << n << " ["
					  << fmt(chi2Quantile(0.025, 3.0 * n) / n, 2) << ", "
					  << fmt(chi2Quantile(0.975, 3.0 * n) / n, 2) << "]";
				else
					s << "-";
			}
			s << "\n";
			// A cell's renders share its geometry and so the detector's
			// systematic error there: the chi-square bands above assume
			// independent sightings. With the cells as the units
			// (pose/consistency.h) the interval of the mean is honest.
			s << "cells as units (95% interval of the mean NEES; design effect):";
			for (const bool small_phi2 : {false, true})
			{
				s << (small_phi2 ? "; where sigma(phi2) <= 2 deg" : " all");
				for (int k = 0; k < 2; ++k)
				{
					const pose::ClusteredMean m = pose::clusteredMean(clustersOf(k, small_phi2), 3);
					s << (k ? ", gen " : " cf ");
					if (m.clusters >= 2)
						s << fmt(m.mean, 2) << " [" << fmt(m.low, 2) << ", " << fmt(m.high, 2)
						  << "] " << fmt(m.design_effect, 1);
					else
						s << "-";
				}
			}
			s << "\n";
		}
		if (o.pose.growth_x_px == 0 && o.pose.growth_y_px == 0 && o.pose.sigma_y_px == 0 &&
			o.pose.sigma_source == pose::SigmaSource::Fixed)
		{
			// NEES scales as 1 / sigma^2: the sigma_px that would make the
			// region's mean NEES 3 (for calibrating the default).
			double sum[2] = {0, 0};
			int n[2] = {0, 0};
			for (const auto& c : cells)
			{
				if (!r.holds(c)) continue;
				const MethodErrors* e[2] = {&c.closed_form, &c.general};
				for (int k = 0; k < 2; ++k)
					if (e[k]->detected)
					{
						sum[k] += e[k]->nees;
						++n[k];
					}
			}
			s << "sigma_px for mean NEES 3:";
			for (int k = 0; k < 2; ++k)
				s << (k ? ", gen " : " cf ")
				  << (n[k] ? fmt(o.pose.sigma_px * std::sqrt(sum[k] / n[k] / 3), 4)
						   : std::string("-"));
			s << "\n";
		}
		{
			double dx = 0, dy = 0, rms = 0, tdx = 0, tdy = 0, trms = 0;
			int n = 0, tn = 0;
			for (const auto& c : cells)
			{
				if (!r.holds(c)) continue;
				if (c.closed_form.detected)
				{
					dx += c.corner_dx_px;
					dy += c.corner_dy_px;
					rms += c.corner_rms_px * c.corner_rms_px;
					++n;
				}
				if (c.apriltag.detected)
				{
					tdx += c.tag_corner_dx_px;
					tdy += c.tag_corner_dy_px;
					trms += c.tag_corner_rms_px * c.tag_corner_rms_px;
					++tn;
				}
			}
			if (n)
				s << "corner error [px]: codemark mean (" << fmt(dx / n, 4) << ", "
				  << fmt(dy / n, 4) << "), rms " << fmt(std::sqrt(rms / n), 4);
			if (tn)
				s << "; AprilTag mean (" << fmt(tdx / tn, 4) << ", " << fmt(tdy / tn, 4)
				  << "), rms " << fmt(std::sqrt(trms / tn), 4);
			s << "\n";
		}
		s << "cells " << nc << ", renders " << nr << ", detected cf/gen/tag " << d0 << "/" << d1
		  << "/" << d2 << "\n";
		if (d0 > 0)
			s << "95% band of the mean NEES over " << d0 << " sightings: ["
			  << fmt(chi2Quantile(0.025, 3.0 * d0) / d0, 3) << ", "
			  << fmt(chi2Quantile(0.975, 3.0 * d0) / d0, 3) << "]\n";
	}
	// The target: at every distance and angle no worse than AprilTag on the
	// same metrics. A cell's mean over a few renders is noisy (10 renders:
	// about 25% of the error), so "worse" counts twice and the excess is
	// set against the standard error of the difference of the two means.
	bool any_tag = false;
	for (const auto& c : cells) any_tag = any_tag || c.apriltag.detected > 0;
	if (any_tag)
	{
		s << "\n## per cell against AprilTag (mean |error| over the cell's renders)\n";
		s << "metric            cf worse (> 2 se)   gen worse (> 2 se)   cells\n";
		std::vector<std::string> significant;
		for (int m = 0; m < 7; ++m)
		{
			int worse[2] = {0, 0}, sig[2] = {0, 0}, compared = 0;
			for (const auto& c : cells)
			{
				if (c.apriltag.detected == 0) continue;
				++compared;
				const MethodErrors* e[2] = {&c.closed_form, &c.general};
				for (int k = 0; k < 2; ++k)
				{
					if (e[k]->detected == 0) continue;
					const double d = e[k]->means()[m] - c.apriltag.means()[m];
					if (d <= 0) continue;
					++worse[k];
					const double se = std::hypot(e[k]->se[m], c.apriltag.se[m]);
					if (d > 2 * se)
					{
						++sig[k];
						significant.push_back(
							std::string(k ? "gen " : "cf ") + kMetricNames[m] + " at " +
							fmt(c.distance_m, 2) + " m, " + fmt(c.angle_deg, 1) +
							" deg: " + fmt(e[k]->means()[m], 6) + " against " +
							fmt(c.apriltag.means()[m], 6) + " (" + fmt(d / se, 1) + " se)");
					}
				}
			}
			s << std::left << std::setw(18) << kMetricNames[m] << std::right << std::setw(9)
			  << worse[0] << " (" << sig[0] << ")" << std::setw(16) << worse[1] << " (" << sig[1]
			  << ")" << std::setw(10) << compared << "\n";
		}
		s << "worse by more than 2 standard errors of the difference: "
		  << (significant.empty() ? std::string("none") : std::to_string(significant.size()))
		  << "\n";
		for (const auto& line : significant) s << "  " << line << "\n";
	}
	s << "\n# paper (real images, 1 px sigma): about 50 mm in x and y and < 2 deg within 2 m in "
		 "front\n"
		 "# targets (within 2 m): range <= 0.05%, bearing <= 0.005 deg, phi2 <= 0.4 deg, "
		 "position <= 10 mm;"
		 " 2-5 m: range <= 0.15%, bearing <= 0.005 deg, phi2 <= 2 deg; NEES in the 95% band\n";
	const std::string text = s.str();
	std::ofstream sf(dir + "/summary.txt");
	sf << text;
	if (!sf) throw std::runtime_error("cannot write " + dir + "/summary.txt");
	return text;
}

}  // namespace codemark::accuracy
