// Monte Carlo check of first-order propagation: P perturbed with C_P at the
// default sigma; empirical covariance and mean of L and of the pose against
// the predicted ones, at grid positions where first order holds.
#include <codemark/landmark/primary.h>
#include <codemark/landmark/truth.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pose/measurement.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <iostream>
#include <random>

#include "common.h"

using namespace codemark;
using namespace codemark::pose;
using codemark::test::cameraAt;
using codemark::test::projectCorners;

namespace
{
struct Stats
{
	Eigen::Vector3d mean = Eigen::Vector3d::Zero();	 // of the deviation from the noise-free value
	Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
};

Stats stats(const std::vector<Eigen::Vector3d>& dev)
{
	Stats s;
	const double N = static_cast<double>(dev.size());
	for (const auto& d : dev) s.mean += d / N;
	for (const auto& d : dev) s.cov += (d - s.mean) * (d - s.mean).transpose() / (N - 1);
	return s;
}

// Second-order bias of f(P) under P ~ N(P0, C_P), C_P diagonal:
// (1/2) sum_k C_P(k,k) d2f/dP_k^2, by central second differences.
template <typename F>
Eigen::Vector3d secondOrderBias(const F& f, const Eigen::Vector4d& P0, const Eigen::Matrix4d& C_P)
{
	Eigen::Vector3d b = Eigen::Vector3d::Zero();
	const Eigen::Vector3d f0 = f(P0);
	for (int k = 0; k < 4; ++k)
	{
		const double h = 1e-3;
		Eigen::Vector4d a = P0, c = P0;
		a[k] += h;
		c[k] -= h;
		Eigen::Vector3d d2 = (f(a) - f0) + (f(c) - f0);
		d2[2] = wrapToPi(f(a)[2] - f0[2]) + wrapToPi(f(c)[2] - f0[2]);
		b += 0.5 * C_P(k, k) * d2 / (h * h);
	}
	return b;
}

double relFrobenius(const Eigen::Matrix3d& emp, const Eigen::Matrix3d& pred)
{
	return (emp - pred).norm() / pred.norm();
}

// N samples of P = m0.P + sigma N(0, I) through \a estimate (P -> L): the
// statistics of the deviations of L and of the pose from the noise-free m0.
template <typename F>
std::pair<Stats, Stats> sampleDeviations(
	const Measurement& m0, double sigma, int N, std::mt19937& rng,
	std::normal_distribution<double>& n01, const F& estimate)
{
	std::vector<Eigen::Vector3d> dL, dR;
	for (int i = 0; i < N; ++i)
	{
		Eigen::Vector4d P = m0.P;
		for (int k = 0; k < 4; ++k) P[k] += sigma * n01(rng);
		const Eigen::Vector3d L = estimate(P);
		Eigen::Vector3d a = L - m0.L, b = poseFromLandmark(L) - m0.pose_in_landmark;
		b[2] = wrapToPi(b[2]);
		dL.push_back(a);
		dR.push_back(b);
	}
	return {stats(dL), stats(dR)};
}
}  // namespace

TEST(MonteCarlo, FirstOrderCovarianceAndMeanOnTheGrid)
{
	const CameraModel cam;
	const LandmarkGeometry g;
	const double sigma = kDefaultSigmaPx;
	const int N = 10000;
	std::mt19937 rng(2026);
	std::normal_distribution<double> n01(0, 1);
	int cells = 0;
	for (const double d : {0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0})
		for (const double deg : {0.0, 20.0, 40.0, 60.0})
		{
			const auto corners = projectCorners(cameraAt(d, deg * M_PI / 180), cam, g);
			PoseOptions opt;
			opt.sigma_px = sigma;
			opt.refine_on_primary = false;	// the paper's formulas and C_L = J_P C_P J_P^T
			const Measurement m0 = measure(corners, cam, g, opt);
			// Only where first order holds: predicted phi2 sigma under 5 deg,
			// and where the detector can see the landmark (reference square
			// at least 30 px tall, VisibilityOptions::min_size_px): at 5 m and
			// 60 deg (25.6 px, phi2 sigma 4.95 deg) the covariances are off
			// by 19-20%.
			if (std::sqrt(m0.C_L(2, 2)) * 180 / M_PI >= 5.0) continue;
			if (2 * std::min(m0.P[1], m0.P[3]) < 30.0) continue;
			++cells;
			const auto [sL, sR] = sampleDeviations(
				m0, sigma, N, rng, n01,
				[&](const Eigen::Vector4d& P)
				{ return landmarkFromPrimary(P, cam.fx(), g.innerHalf()); });
			const double eL = relFrobenius(sL.cov, m0.C_L), eR = relFrobenius(sR.cov, m0.C_R);
			EXPECT_LT(eL, 0.10) << "C_L at d " << d << " angle " << deg;
			EXPECT_LT(eR, 0.10) << "C_R at d " << d << " angle " << deg;
			// The mean: the closed form is non-linear, so the mean deviation
			// carries the second-order bias (1/2) tr(H C_P), which beyond
			// 1 m is larger than sigma/sqrt(N) (up to ~100x at 3 m, frontal:
			// E[cos(phi1 + phi2)] < 1 shortens x). The documented allowance:
			// the mean minus that predicted bias lies within 3 sigma/sqrt(N),
			// plus 5% of the bias for the higher orders (measured: the
			// residual reaches 3.6 sigma/sqrt(N) at 3 m frontal, where the
			// bias is 113 sigma/sqrt(N); printed below).
			const auto fL = [&](const Eigen::Vector4d& P)
			{ return landmarkFromPrimary(P, cam.fx(), g.innerHalf()); };
			const auto fR = [&](const Eigen::Vector4d& P) { return poseFromLandmark(fL(P)); };
			const Eigen::Vector3d bL = secondOrderBias(fL, m0.P, m0.C_P);
			const Eigen::Vector3d bR = secondOrderBias(fR, m0.P, m0.C_P);
			double worst = 0, worst_raw = 0;
			for (int k = 0; k < 3; ++k)
			{
				const double seL = std::sqrt(m0.C_L(k, k) / N), seR = std::sqrt(m0.C_R(k, k) / N);
				EXPECT_LT(std::abs(sL.mean[k] - bL[k]), 3 * seL + 0.05 * std::abs(bL[k]))
					<< "L[" << k << "] d " << d << " angle " << deg;
				EXPECT_LT(std::abs(sR.mean[k] - bR[k]), 3 * seR + 0.05 * std::abs(bR[k]))
					<< "pose[" << k << "] d " << d << " angle " << deg;
				worst = std::max(
					{worst, std::abs(sL.mean[k] - bL[k]) / seL,
					 std::abs(sR.mean[k] - bR[k]) / seR});
				worst_raw =
					std::max({worst_raw, std::abs(sL.mean[k]) / seL, std::abs(sR.mean[k]) / seR});
			}
			std::cout << "[ MC ] d=" << d << " angle=" << deg
					  << " deg: sigma_phi2=" << std::sqrt(m0.C_L(2, 2)) * 180 / M_PI
					  << " deg, sigma_xy=" << std::sqrt(m0.C_R(0, 0) + m0.C_R(1, 1)) * 1000
					  << " mm, covL err " << eL << ", covR err " << eR
					  << ", |mean|/(sigma/sqrt N) max " << worst_raw
					  << ", after the 2nd-order bias " << worst << "\n";
		}
	EXPECT_GE(cells, 20);
}

// The same for the closed form refined by weighted least squares on P (the
// default, PoseOptions::refine_on_primary): its C_L = (J^T C_P^-1 J)^-1 and
// C_R against the samples' covariance on the same grid cells, and its mean
// error against the predicted sigmas. It is much tighter than the paper's
// formulas alone where the foreshortened width carries phi2 (printed).
TEST(MonteCarlo, RefinedClosedFormCovarianceOnTheGrid)
{
	const CameraModel cam;
	const LandmarkGeometry g;
	const double sigma = kDefaultSigmaPx;
	const int N = 4000;
	std::mt19937 rng(2027);
	std::normal_distribution<double> n01(0, 1);
	int cells = 0;
	for (const double d : {0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0})
		for (const double deg : {0.0, 20.0, 40.0, 60.0})
		{
			const auto corners = projectCorners(cameraAt(d, deg * M_PI / 180), cam, g);
			PoseOptions opt;
			opt.sigma_px = sigma;
			const Measurement m0 = measure(corners, cam, g, opt);
			PoseOptions paper = opt;
			paper.refine_on_primary = false;
			const Measurement mp = measure(corners, cam, g, paper);
			// The paper's test's cells, where also the refined phi2 sigma is
			// under 2 deg: seen squarely from 3 m (3.6 deg), the width's
			// second-order change with phi2 already narrows the samples to
			// 2.6 deg (first order is then conservative, by 27%).
			if (std::sqrt(mp.C_L(2, 2)) * 180 / M_PI >= 5.0) continue;
			if (std::sqrt(m0.C_L(2, 2)) * 180 / M_PI >= 2.0) continue;
			if (2 * std::min(m0.P[1], m0.P[3]) < 30.0) continue;
			++cells;
			const auto [sL, sR] = sampleDeviations(
				m0, sigma, N, rng, n01,
				[&](const Eigen::Vector4d& P)
				{
					return refineLandmarkOnPrimary(
						P, m0.C_P, cam.fx(), g.innerHalf(),
						landmarkFromPrimary(P, cam.fx(), g.innerHalf()));
				});
			const double eL = relFrobenius(sL.cov, m0.C_L), eR = relFrobenius(sR.cov, m0.C_R);
			EXPECT_LT(eL, 0.10) << "C_L at d " << d << " angle " << deg;
			EXPECT_LT(eR, 0.10) << "C_R at d " << d << " angle " << deg;
			// A (second-order) bias well below the noise.
			for (int k = 0; k < 3; ++k)
				EXPECT_LT(std::abs(sL.mean[k]), 0.25 * std::sqrt(m0.C_L(k, k)))
					<< "L[" << k << "] d " << d << " angle " << deg;
			EXPECT_LE(m0.C_L(2, 2), mp.C_L(2, 2) * (1 + 1e-9)) << "d " << d << " angle " << deg;
			std::cout << "[ MC refined ] d=" << d << " angle=" << deg
					  << " deg: sigma_phi2=" << std::sqrt(m0.C_L(2, 2)) * 180 / M_PI
					  << " deg (paper's formulas " << std::sqrt(mp.C_L(2, 2)) * 180 / M_PI
					  << "), samples " << std::sqrt(sL.cov(2, 2)) * 180 / M_PI << ", covL err "
					  << eL << ", covR err " << eR << "\n";
		}
	EXPECT_GE(cells, 20);
}
