// Consistency of the pose covariance that the pipeline reports for codemark's
// own detector (the shipped calibration realistic, calibrated by
// codemark-bench-pose-calib on other renders and seeds, see
// docs/benchmarks/pose.md): over 320 noisy renders at random level-camera
// poses (half of them at the landmark's height) at 0.5-4 m and view angles
// up to 60 deg (the calibration's range and the filters' limit,
// filters::StepperOptions::max_view_angle_deg: beyond it the vertical frames
// are 1-2 px, the range is biased short and C_P does not hold), the mean
// NEES of the camera's pose in the landmark frame must lie in the 95%
// chi-square band, for both pose paths, over the sightings whose predicted
// phi2 sigma is at most 2 deg (the accuracy targeted for phi2; beyond it x,
// y = l2 (cos, sin)(phi1 + phi2) are too curved over the phi2 uncertainty
// for a Gaussian C_R, even to second order, and accuracy-map's summary shows
// how the NEES grows there). At least 200 such sightings are required.
#include <mrpt/math/distributions.h>
#include <codemark/detect/detector.h>
#include <codemark/landmark/truth.h>
#include <codemark/pipeline/pipeline.h>
#include <codemark/sim/dataset.h>
#include <codemark/sim/render.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

using namespace codemark;

namespace
{
// 95% band of the mean of n chi-square(3) variables: chi2(3n) / n.
std::pair<double, double> neesBand(int n)
{
	const auto k = static_cast<unsigned>(3 * n);
	return {mrpt::math::chi2inv(0.025, k) / n, mrpt::math::chi2inv(0.975, k) / n};
}

struct NeesResult
{
	double mean[2] = {0, 0};  // ClosedForm, General6Dof
	int used[2] = {0, 0};
	int detected = 0, visible = 0;
};

// The renders, detections and NEES of both paths, computed once.
const NeesResult& neesOnRenders()
{
	static const NeesResult result = []
	{
		NeesResult out;
		sim::Scene scene = sim::singleLandmarkScene();
		const MapLandmark& lm = scene.map.landmarks[0];
		// The calibration's conditions: textured wall, light gradient, noise 2,
		// blur 0.8 px.
		const sim::RenderOptions ro = sim::DatasetOptions::realisticRender();
		const LandmarkGeometry g = lm.geometry();
		const detect::DetectorOptions dopt;
		pose::PoseOptions cf = pipeline::calibratedPoseOptions("realistic"), gen = cf;
		cf.method = pose::PoseMethod::ClosedForm;
		gen.method = pose::PoseMethod::General6Dof;

		std::mt19937_64 rng(20261122);	// not a calibration seed
		std::uniform_real_distribution<double> U(0, 1);
		const int renders = 320;
		double sum[2] = {0, 0};
		int used[2] = {0, 0}, detected = 0, visible = 0;
		for (int i = 0; i < renders; ++i)
		{
			const double r0 = 0.5, r1 = 4.0;
			const double d = std::sqrt(r0 * r0 + U(rng) * (r1 * r1 - r0 * r0));
			const double a = (2 * U(rng) - 1) * 60 * M_PI / 180;
			// Half of the views level with the landmark's centre, as the
			// calibration's renders (--level-fraction 0.5) and the
			// simulated datasets' robot camera: the top and bottom edges
			// then lie along pixel rows.
			const double bearing = (2 * U(rng) - 1) * 0.35, height = (2 * U(rng) - 1) * 0.5;
			const bool level = U(rng) < 0.5;
			scene.world_T_camera =
				sim::levelCameraLookingAt(lm, d, a, level ? 0.0 : height, bearing);
			const sim::Render img = sim::render(scene, ro, 5000 + i);
			if (!img.truth[0].fully_visible) continue;
			++visible;
			const SightingTruth truth = sightingTruth(img.truth[0].landmark_T_camera);
			for (const auto& dl : detect::detect(img.image, scene.camera, g, dopt).landmarks)
			{
				if (dl.detection.id != lm.id) continue;
				++detected;
				int k = 0;
				for (const pose::PoseOptions* o : {&cf, &gen})
				{
					const pose::Measurement m = pose::measure(dl.detection, scene.camera, g, *o);
					if (std::sqrt(m.C_L(2, 2)) <= 2 * M_PI / 180)
					{
						Eigen::Vector3d e = m.pose_in_landmark - truth.pose_in_landmark;
						e[2] = wrapToPi(e[2]);
						sum[k] += e.dot(m.C_R.ldlt().solve(e));
						++used[k];
					}
					++k;
				}
				break;
			}
		}
		for (int k = 0; k < 2; ++k)
		{
			out.used[k] = used[k];
			out.mean[k] = used[k] ? sum[k] / used[k] : 0;
		}
		out.detected = detected;
		out.visible = visible;
		return out;
	}();
	return result;
}

void checkNees(int k)
{
	const NeesResult& r = neesOnRenders();
	EXPECT_GE(r.detected, 0.95 * r.visible);
	const auto [lo, hi] = neesBand(std::max(1, r.used[k]));
	std::printf(
		"[ NEES ] %s: mean %.3f over %d sightings (%d detected), 95%% band [%.3f, %.3f]\n",
		k ? "General6Dof" : "ClosedForm", r.mean[k], r.used[k], r.detected, lo, hi);
	ASSERT_GE(r.used[k], 200) << "too few sightings with a predicted phi2 sigma <= 2 deg";
	EXPECT_GT(r.mean[k], lo);
	EXPECT_LT(r.mean[k], hi);
}
}  // namespace

TEST(PoseNees, GeneralPathIsConsistentOnRenders) { checkNees(1); }

// The closed form with its weighted least-squares refinement on P (the
// pipeline's default, PoseOptions::refine_on_primary): 3.13 over 272
// sightings. The paper's formulas alone give 4.28 over 171 (overconfident,
// and phi2 under 2 deg in too few sightings): they waste one of P's four
// numbers, which C_L = J_P C_P J_P^T does not know.
TEST(PoseNees, ClosedFormIsConsistentOnRenders) { checkNees(0); }

// Noise-free renders (no noise, no blur), codemark's detector, both paths,
// within 2 m: L and the pose to 1e-3 (range and position relative to the
// range, angles in rad). Noise-free is not error-free: each mixed pixel of
// an edge is rounded, by up to half a grey level of the step's contrast,
// and an edge along the pixel grid keeps one rounding along its length.
// Two exposures: the spec's green at gain 1, whose G is exactly the
// sensor's top (noise-free, it reads 255 with nothing clipped; the detector
// must tell that from a fill above the clip), and gain 0.9, whose frame
// and fill (22.5 and 229.5) both round by half a level, the same in every
// profile: that tilts a side whose edge crosses a pixel boundary (phi2 off
// by 1.2e-3 rad at 2 m seen squarely, without
// detect::correctLevelRounding()). The exact-corner round trip to
// 1e-6 is tests/pose/test_sim.cpp.
TEST(PoseOnRenders, NoiseFreeRendersRecoverLAndPose)
{
	sim::Scene scene = sim::singleLandmarkScene();
	const MapLandmark& lm = scene.map.landmarks[0];
	const LandmarkGeometry g = lm.geometry();
	int n = 0;
	std::array<double, 5> worst{};
	for (const double gain : {1.0, 0.9})
	{
		sim::RenderOptions ro;	// all effects off
		ro.gain = gain;
		for (const double d : {0.7, 1.0, 1.5, 2.0})
			for (const double deg : {0.0, 20.0, -40.0, 60.0})
			{
				scene.world_T_camera =
					sim::levelCameraLookingAt(lm, d, deg * M_PI / 180, 0.05, 0.05);
				const sim::Render img = sim::render(scene, ro, 1);
				const SightingTruth t = sightingTruth(img.truth[0].landmark_T_camera);
				const auto det =
					detect::detect(img.image, scene.camera, g, detect::DetectorOptions());
				EXPECT_EQ(det.landmarks.size(), 1u) << d << " m " << deg << " deg";
				if (det.landmarks.size() != 1u) continue;
				++n;
				for (const auto method :
					 {pose::PoseMethod::ClosedForm, pose::PoseMethod::General6Dof})
				{
					pose::PoseOptions o;
					o.method = method;
					const pose::Measurement m =
						pose::measure(det.landmarks[0].detection, scene.camera, g, o);
					const std::string what = pose::toString(method) + " at gain " +
											 std::to_string(gain) + ", " + std::to_string(d) +
											 " m, " + std::to_string(deg) + " deg";
					EXPECT_NEAR(m.L[0], t.L[0], 1e-3 * t.L[0]) << what;
					EXPECT_NEAR(wrapToPi(m.L[1] - t.L[1]), 0, 1e-3) << what;
					const double e_phi2 = std::abs(wrapToPi(m.L[2] - t.L[2]));
					const double e_pos = std::hypot(
						m.pose_in_landmark[0] - t.pose_in_landmark[0],
						m.pose_in_landmark[1] - t.pose_in_landmark[1]);
					const double e_theta =
						std::abs(wrapToPi(m.pose_in_landmark[2] - t.pose_in_landmark[2]));
					EXPECT_LE(e_phi2, 1e-3) << what;
					EXPECT_LE(e_pos, 1e-3 * t.L[0]) << what;
					EXPECT_LE(e_theta, 1e-3) << what;
					worst[0] = std::max(worst[0], std::abs(m.L[0] - t.L[0]) / t.L[0]);
					worst[1] = std::max(worst[1], std::abs(wrapToPi(m.L[1] - t.L[1])));
					worst[2] = std::max(worst[2], e_phi2);
					worst[3] = std::max(worst[3], e_pos / t.L[0]);
					worst[4] = std::max(worst[4], e_theta);
				}
			}
	}
	EXPECT_EQ(n, 32);
	std::printf(
		"noise-free, worst of %d measurements: range %.1e (relative), bearing %.1e rad, phi2 "
		"%.1e rad, position %.1e of the range, heading %.1e rad\n",
		2 * n, worst[0], worst[1], worst[2], worst[3], worst[4]);
}
