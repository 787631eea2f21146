// Consistency of the reported C_R: NEES of the pose over many sightings with
// independent Gaussian corner noise (no detector), both paths. Each corner
// coordinate carries sqrt(2) sigma_px, so each component of P carries sigma_px.
#include <codemark/landmark/truth.h>
#include <codemark/pose/consistency.h>
#include <codemark/pose/measurement.h>
#include <mrpt/math/distributions.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>

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
		// 95% band of the mean of N chi-square(3) variables: chi2(3N) / N.
		const auto k = static_cast<unsigned>(3 * N);
		const double lo = mrpt::math::chi2inv(0.025, k) / N;
		const double hi = mrpt::math::chi2inv(0.975, k) / N;
		EXPECT_GT(mean, lo) << toString(method);
		EXPECT_LT(mean, hi) << toString(method);
		std::cout << "[ NEES ] " << toString(method) << ": mean " << mean << " over " << N
				  << " sightings, 95% band [" << lo << ", " << hi << "]\n";
	}
}

TEST(Consistency, StudentTQuantileMatchesTables)
{
	// Two-sided 95% points of Student's t (any statistics table).
	const std::pair<double, double> table[] = {{3, 3.182446},  {5, 2.570582},  {10, 2.228139},
											   {30, 2.042272}, {55, 2.004045}, {1e6, 1.959966}};
	for (const auto& [nu, t] : table)
	{
		EXPECT_NEAR(studentTQuantile(0.975, nu), t, (nu < 10 ? 2e-3 : 5e-5) * t) << nu;
		EXPECT_NEAR(studentTQuantile(0.025, nu), -t, (nu < 10 ? 2e-3 : 5e-5) * t) << nu;
	}
	EXPECT_THROW(studentTQuantile(1.0, 5), std::invalid_argument);
	EXPECT_THROW(studentTQuantile(0.5, 0), std::invalid_argument);
}

// Sightings in clusters that share a systematic error, as the accuracy map's
// renders of one cell share its geometry: each cluster's error is a common
// bias b ~ N(0, s_b^2 I3) plus its own noise ~ N(0, (1 - s_b^2) I3), so each
// NEES has mean 3 whatever s_b. The clusters-as-units interval must cover 3
// in about 95% of surveys, with or without the bias; the chi-square band of
// independent sightings only without it.
TEST(Consistency, ClusteredMeanIntervalCoversWhereTheChiSquareBandDoesNot)
{
	std::mt19937 rng(5);
	std::normal_distribution<double> n01(0, 1);
	const int surveys = 400, G = 40, per = 10;
	for (const double bias_var : {0.0, 0.8})
	{
		int covered = 0, band_covered = 0;
		double deff = 0;
		for (int s = 0; s < surveys; ++s)
		{
			std::vector<NeesCluster> clusters(G);
			for (auto& c : clusters)
			{
				Eigen::Vector3d b;
				for (int k = 0; k < 3; ++k) b[k] = std::sqrt(bias_var) * n01(rng);
				for (int i = 0; i < per; ++i)
				{
					Eigen::Vector3d e = b;
					for (int k = 0; k < 3; ++k) e[k] += std::sqrt(1 - bias_var) * n01(rng);
					c.sum += e.squaredNorm();
					++c.count;
				}
			}
			const ClusteredMean m = clusteredMean(clusters, 3);
			ASSERT_EQ(m.count, G * per);
			ASSERT_EQ(m.clusters, G);
			covered += m.low <= 3 && 3 <= m.high;
			const double N = G * per;
			band_covered += mrpt::math::chi2inv(0.025, 3 * N) / N <= m.mean &&
							m.mean <= mrpt::math::chi2inv(0.975, 3 * N) / N;
			deff += m.design_effect / surveys;
		}
		const double cover = double(covered) / surveys, band = double(band_covered) / surveys;
		std::printf(
			"[ NEES ] bias variance %.1f: interval covers 3 in %.3f, chi-square band %.3f, design "
			"effect %.2f\n",
			bias_var, cover, band, deff);
		EXPECT_GT(cover, 0.91) << "bias variance " << bias_var;
		EXPECT_LT(cover, 0.985) << "bias variance " << bias_var;
		if (bias_var == 0)
		{
			EXPECT_GT(band, 0.91);
			EXPECT_NEAR(deff, 1.0, 0.15);
		}
		else
		{
			// Var of a cluster's mean NEES grows with per * bias_var^2: the
			// band is far too narrow.
			EXPECT_LT(band, 0.6) << "deff " << deff;
			EXPECT_GT(deff, 3.0);
		}
	}
}

TEST(Consistency, ClusteredMeanEdgeCases)
{
	EXPECT_EQ(clusteredMean({}, 3).count, 0);
	const ClusteredMean one = clusteredMean({{9.0, 3}, {0.0, 0}}, 3);
	EXPECT_DOUBLE_EQ(one.mean, 3.0);
	EXPECT_EQ(one.clusters, 1);
	EXPECT_TRUE(std::isinf(one.standard_error));
	// Two clusters of equal means: no spread.
	const ClusteredMean two = clusteredMean({{6.0, 2}, {9.0, 3}}, 3);
	EXPECT_DOUBLE_EQ(two.mean, 3.0);
	EXPECT_NEAR(two.standard_error, 0.0, 1e-12);
	EXPECT_THROW(clusteredMean({}, 0), std::invalid_argument);
}
