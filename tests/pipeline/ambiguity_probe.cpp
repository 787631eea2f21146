// Ad-hoc probe (not a test): renders of one cell of the accuracy map, the
// measurement of both paths, and the closed form refined from the mirrored
// view angle, to see the two-fold ambiguity of a far, near-frontal sighting
// (docs/benchmarks/pose.md, "Folding the mirror image").
//   pose_ambiguity_probe [DISTANCE_M [VIEW_ANGLE_DEG [RENDERS [REALISTIC]]]]
// prints one line a render and the mean NEES of both paths; FOLD=1 turns
// PoseOptions::fold_ambiguity on. KAPPA_RUN=1 draws 0.5-5 m and view angles
// up to 70 deg instead and prints the mean chi2 at the optimum of each path
// (1 and 2 degrees of freedom): C_P's scale along P's redundant direction.
#include <codemark/detect/detector.h>
#include <codemark/landmark/truth.h>
#include <codemark/pipeline/pipeline.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pose/general.h>
#include <codemark/landmark/primary.h>
#include <codemark/sim/dataset.h>
#include <codemark/sim/render.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

using namespace codemark;

int main(int argc, char** argv)
{
	const double dist = argc > 1 ? atof(argv[1]) : 4.53;
	const double ang = (argc > 2 ? atof(argv[2]) : 6.34) * M_PI / 180;
	const int renders = argc > 3 ? atoi(argv[3]) : 80;
	const int realistic = argc > 4 ? atoi(argv[4]) : 0;
	sim::Scene scene = sim::singleLandmarkScene();
	const MapLandmark& lm = scene.map.landmarks[0];
	sim::RenderOptions ro =
		realistic ? sim::DatasetOptions::realisticRender() : sim::RenderOptions();
	ro.noise_sigma = 2;
	ro.blur_sigma_px = 0.8;
	const LandmarkGeometry g = lm.geometry();
	pose::PoseOptions cf = realistic ? pipeline::calibratedPoseOptions("realistic")
									 : pipeline::calibratedPoseOptions("plain");
	if (std::getenv("FOLD")) cf.fold_ambiguity = true;
	pose::PoseOptions gen = cf;
	gen.method = pose::PoseMethod::General6Dof;
	std::mt19937_64 rng(7);
	std::uniform_real_distribution<double> U(-1, 1);
	double sum_cf = 0, sum_gen = 0;
	int n = 0;
	const bool kappa = std::getenv("KAPPA_RUN") != nullptr;
	double sum_c = 0, sum_g = 0;
	int nk = 0;
	for (int i = 0; i < renders; ++i)
	{
		const double h = 0.2 * U(rng), b = 0.15 * U(rng);
		const double dd = kappa ? 0.5 + 4.5 * (0.5 + 0.5 * U(rng)) : dist;
		const double aa = kappa ? 70 * M_PI / 180 * U(rng) : ang;
		scene.world_T_camera = sim::levelCameraLookingAt(lm, dd, aa, h, b);
		const sim::Render img = sim::render(scene, ro, 100 + i);
		const SightingTruth t = sightingTruth(img.truth[0].landmark_T_camera);
		const auto det = detect::detect(img.image, scene.camera, g, detect::DetectorOptions());
		if (det.landmarks.size() != 1) continue;
		const auto& d = det.landmarks[0].detection;
		const pose::Measurement m = pose::measure(d, scene.camera, g, cf);
		const pose::Measurement mg = pose::measure(d, scene.camera, g, gen);
		// Mirrored start.
		double lambda = 0;
		const Eigen::Vector4d P = primaryMeasurement(d.corners, scene.camera, &lambda);
		Eigen::Vector3d L0 = m.L;
		L0[2] = -2 * m.L[1] - m.L[2];
		Eigen::Matrix3d C2;
		const Eigen::Vector3d L2 =
			pose::refineLandmarkOnPrimary(P, m.C_P, lambda, g.innerHalf(), L0, &C2);
		const Eigen::Matrix4d W = m.C_P.inverse();
		const auto cost = [&](const Eigen::Vector3d& L)
		{
			const Eigen::Vector4d r = P - pose::primaryFromLandmark(L, lambda, g.innerHalf());
			return r.dot(W * r);
		};
		const auto nees = [&](const pose::Measurement& mm)
		{
			Eigen::Vector3d e = mm.pose_in_landmark - t.pose_in_landmark;
			e[2] = wrapToPi(e[2]);
			return e.dot(mm.C_R.ldlt().solve(e));
		};
		if (kappa)
		{
			pose::PoseOptions g1 = gen, c1 = cf;
			g1.fold_ambiguity = c1.fold_ambiguity = false;
			const auto gp = pose::solveGeneralPose(
				d.corners, scene.camera, g,
				pose::cornerCovarianceFromPrimary(
					d.corners, scene.camera, m.C_P, gen.corner_midpoint_ratio,
					gen.corner_tilt_ratio));
			sum_c += cost(pose::measure(d, scene.camera, g, c1).L);
			sum_g += gp.solutions[0].chi2;
			++nk;
			continue;
		}
		const Eigen::Vector4d Pt = primaryMeasurement(img.truth[0].corners_px, scene.camera);
		const double ncf = nees(m), ngen = nees(mg);
		sum_cf += ncf;
		sum_gen += ngen;
		++n;
		std::printf(
			"%3d h %+.2f b %+.3f | phi2 true %+6.2f cf %+6.2f (s %.2f, c %.2f w2 %.2f) mirror "
			"%+6.2f (s "
			"%.2f, c %.2f) gen %+6.2f w2 %.2f | NEES cf %8.1f gen %8.1f | dP %+.3f %+.3f %+.3f "
			"%+.3f\n",
			i, h, b, t.L[2] * 180 / M_PI, m.L[2] * 180 / M_PI, std::sqrt(m.C_L(2, 2)) * 180 / M_PI,
			cost(m.L), m.second_mode_weight, L2[2] * 180 / M_PI, std::sqrt(C2(2, 2)) * 180 / M_PI,
			cost(L2), mg.L[2] * 180 / M_PI, mg.second_mode_weight, ncf, ngen, P[0] - Pt[0],
			P[1] - Pt[1], P[2] - Pt[2], P[3] - Pt[3]);
	}
	if (kappa)
		std::printf(
			"mean chi2: cf %.3f (1 dof), general %.3f (2 dof) over %d\n", sum_c / nk, sum_g / nk,
			nk);
	std::printf("mean NEES cf %.2f gen %.2f over %d\n", sum_cf / n, sum_gen / n, n);
}
