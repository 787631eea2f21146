// Ad-hoc probe (not a unit test): renders scenes and prints detection,
// corner errors and timings; compares with cv::aruco::detectMarkers.
#include <codemark/detect/detector.h>
#include <codemark/sim/render.h>

#include <opencv2/aruco.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

using namespace codemark;

int main(int argc, char** argv)
{
	cv::setNumThreads(1);
	double dist = argc > 1 ? atof(argv[1]) : 2.0;
	double ang = argc > 2 ? atof(argv[2]) * M_PI / 180 : 0.0;
	double gain = argc > 3 ? atof(argv[3]) : 1.0;
	double noise = argc > 4 ? atof(argv[4]) : 2.0;
	double blur = argc > 5 ? atof(argv[5]) : 0.8;
	int jpeg = argc > 6 ? atoi(argv[6]) : 0;
	int bg = argc > 7 ? atoi(argv[7]) : 1;
	const char* dbg = argc > 8 ? argv[8] : "";
	sim::Scene sc;
	MapLandmark lm;
	lm.id = 37;
	sc.map.landmarks.push_back(lm);
	sim::RenderOptions ro;
	ro.background = static_cast<sim::Background>(bg);
	ro.distractors = 8;
	ro.gain = gain;
	ro.gradient = std::getenv("GRAD") ? atof(std::getenv("GRAD")) : 0.3;
	ro.noise_sigma = noise;
	ro.blur_sigma_px = blur;
	ro.jpeg_quality = jpeg;
	detect::DetectorOptions opt;
	if (std::getenv("INI")) opt = detect::DetectorOptions::load(std::getenv("INI"));
	double err_sum = 0, err_max = 0;
	int found = 0, n = 0;
	std::vector<double> times;
	for (int trial = 0; trial < 20; ++trial)
	{
		sc.world_T_camera = sim::levelCameraLookingAt(
			lm, dist, ang, 0.05 * (trial % 3 - 1), 0.1 * ((trial % 5) - 2));
		auto r = sim::render(sc, ro, trial);
		if (!r.truth[0].fully_visible) continue;
		++n;
		auto res =
			detect::detect(r.image, sc.camera, LandmarkGeometry(), opt, trial == 0 ? dbg : "");
		times.push_back(res.timings.total_us);
		if (res.landmarks.empty() && *dbg && std::getenv("FAILS"))
		{
			detect::detect(r.image, sc.camera, LandmarkGeometry(), opt, dbg);
			cv::imwrite(std::string(dbg) + "/input.png", r.image);
			dbg = "";
		}
		if (trial == 0 || (std::getenv("FAILS") && res.landmarks.empty()))
			printf(
				"counts comp %d rois %d quads %d fitted %d dec %d | seg %.0f comp %.0f edg %.0f "
				"segm %.0f quad %.0f sub %.0f code %.0f total %.0f us\n",
				res.counts.components, res.counts.rois, res.counts.quads, res.counts.fitted,
				res.counts.decoded, res.timings.segmentation_us, res.timings.components_us,
				res.timings.edgels_us, res.timings.segments_us, res.timings.quads_us,
				res.timings.subpixel_us, res.timings.code_us, res.timings.total_us);
		for (auto& d : res.landmarks)
		{
			if (d.detection.id != 37)
			{
				printf("WRONG ID %d\n", d.detection.id);
				continue;
			}
			++found;
			for (int k = 0; k < 4; ++k)
			{
				double e = (d.detection.corners[k] - r.truth[0].corners_px[k]).norm();
				if (trial == 0 && std::getenv("VERBOSE"))
					printf(
						"corner %d err (%.4f, %.4f)\n", k,
						(d.detection.corners[k] - r.truth[0].corners_px[k]).x(),
						(d.detection.corners[k] - r.truth[0].corners_px[k]).y());
				err_sum += e;
				err_max = std::max(err_max, e);
			}
		}
		if (trial == 0 && std::getenv("ARUCO"))
		{
			// Minimum and median over repetitions (the machine is shared:
			// the minimum is the least disturbed figure).
			auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
			auto params = cv::aruco::DetectorParameters::create();
			params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
			std::vector<int> ids;
			std::vector<std::vector<cv::Point2f>> corners;
			auto timeIt = [](auto&& f, int n)
			{
				std::vector<double> t;
				for (int k = 0; k < n; ++k)
				{
					auto t0 = std::chrono::steady_clock::now();
					f();
					t.push_back(std::chrono::duration<double, std::micro>(
									std::chrono::steady_clock::now() - t0)
									.count());
				}
				std::sort(t.begin(), t.end());
				return std::make_pair(t.front(), t[t.size() / 2]);
			};
			// A background-only frame: the same wall with clutter, no landmark.
			sim::Scene bg_scene = sc;
			bg_scene.world_T_camera = sim::levelCameraLookingAt(lm, dist, ang, 0, M_PI);
			sim::RenderOptions bo = ro;
			bo.background = sim::Background::Cluttered;
			bo.distractors = 12;
			const cv::Mat bg_img = sim::render(bg_scene, bo, 99).image;
			{
				const auto b = detect::detect(bg_img, sc.camera, LandmarkGeometry(), opt);
				printf(
					"background counts comp %d rois %d quads %d fitted %d | seg %.0f comp %.0f edg "
					"%.0f sub %.0f code %.0f total %.0f us\n",
					b.counts.components, b.counts.rois, b.counts.quads, b.counts.fitted,
					b.timings.segmentation_us, b.timings.components_us, b.timings.edgels_us,
					b.timings.subpixel_us, b.timings.code_us, b.timings.total_us);
			}
			const auto a1 =
				timeIt([&] { cv::aruco::detectMarkers(r.image, dict, corners, ids, params); }, 30);
			const auto c1 =
				timeIt([&] { detect::detect(r.image, sc.camera, LandmarkGeometry(), opt); }, 300);
			const auto a0 =
				timeIt([&] { cv::aruco::detectMarkers(bg_img, dict, corners, ids, params); }, 30);
			const auto c0 =
				timeIt([&] { detect::detect(bg_img, sc.camera, LandmarkGeometry(), opt); }, 300);
			printf(
				"landmark frame: aruco min %.0f med %.0f us, codemark min %.0f med %.0f us, "
				"ratio(min) %.3f ratio(med) %.3f\n",
				a1.first, a1.second, c1.first, c1.second, c1.first / a1.first,
				c1.second / a1.second);
			printf(
				"background frame: aruco min %.0f med %.0f us, codemark min %.0f med %.0f us, "
				"ratio(min) %.3f ratio(med) %.3f\n",
				a0.first, a0.second, c0.first, c0.second, c0.first / a0.first,
				c0.second / a0.second);
		}
		if (trial == 0 && *dbg) cv::imwrite(std::string(dbg) + "/input.png", r.image);
	}
	std::sort(times.begin(), times.end());
	printf(
		"d=%.2f ang=%.0f gain=%.2f noise=%.1f blur=%.1f jpeg=%d: found %d/%d mean err %.4f max "
		"%.4f median %.0f us\n",
		dist, ang * 180 / M_PI, gain, noise, blur, jpeg, found, n,
		found ? err_sum / (4 * found) : -1, err_max, times.empty() ? 0 : times[times.size() / 2]);
}
