// Consistency of the reported C_R: NEES of the pose over many sightings with
// independent Gaussian corner noise (no detector), both paths. Each corner
// coordinate carries sqrt(2) sigma_px, so each component of P carries sigma_px.
#include <codemark/landmark/truth.h>
#include <codemark/pose/measurement.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "common.h"

using namespace codemark;
using namespace codemark::pose;

TEST(Consistency, MeanNeesInsideTheChiSquareBand)
{
	const CameraModel cam;
	const LandmarkGeometry g;
	std::mt19937 rng(77);
	std::uniform_real_distribution<double> d(0.5, 2.0), a(-1.0, 1.0), z(-0.3, 0.3), p1(-0.2, 0.2);
	const int N = 400;
	for (const PoseMethod method : {PoseMethod::ClosedForm, PoseMethod::General6Dof})
	{
		PoseOptions o;
		o.method = method;
		o.sigma_px = kDefaultSigmaPx;
		std::normal_distribution<double> n(0, std::sqrt(2.0) * o.sigma_px);
		double sum = 0;
		for (int i = 0; i < N; ++i)
		{
			const auto lTc = test::cameraAt(d(rng), a(rng), z(rng), p1(rng));
			auto corners = test::projectCorners(lTc, cam, g);
			for (auto& c : corners) c += Eigen::Vector2d(n(rng), n(rng));
			const Measurement m = measure(corners, cam, g, o);
			const SightingTruth t = sightingTruth(lTc);
			Eigen::Vector3d e = m.pose_in_landmark - t.pose_in_landmark;
			e[2] = wrapToPi(e[2]);
			sum += e.dot(m.C_R.ldlt().solve(e));
		}
		const double mean = sum / N;
		// 95% band of the mean of N chi-square(3) variables: chi2(3N) / N,
		// quantiles from the Wilson-Hilferty approximation.
		const double k = 3.0 * N, h = 2.0 / (9 * k), zq = 1.959963984540054;
		const double lo = k * std::pow(1 - h - zq * std::sqrt(h), 3) / N;
		const double hi = k * std::pow(1 - h + zq * std::sqrt(h), 3) / N;
		EXPECT_GT(mean, lo) << toString(method);
		EXPECT_LT(mean, hi) << toString(method);
		std::cout << "[ NEES ] " << toString(method) << ": mean " << mean << " over " << N
				  << " sightings, 95% band [" << lo << ", " << hi << "]\n";
	}
}
