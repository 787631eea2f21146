// The normalised innovation squared and the verdict on a run's innovations.
#include <codemark/eval/localization.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <random>

using namespace codemark::filters;
using namespace codemark::eval;

TEST(Innovation, NisAndLogDetMatchTheirDefinitions)
{
	Eigen::Matrix3d A;
	A << 2, 0.3, -0.1, 0.3, 1, 0.2, -0.1, 0.2, 0.5;
	const Eigen::Matrix3d S = A * A.transpose();
	const Eigen::Vector3d nu(0.4, -1.2, 0.7);
	const Eigen::MatrixXd R = 0.25 * S;
	const Innovation in = makeInnovation(nu, S, 16.27, &R);
	EXPECT_NEAR(in.nis, nu.dot(S.inverse() * nu), 1e-12);
	EXPECT_NEAR(in.log_det_s, std::log(S.determinant()), 1e-12);
	EXPECT_EQ(in.dof, 3);
	EXPECT_NEAR(in.sighting_share, 0.25, 1e-12);
	EXPECT_EQ(in.gated, in.nis > 16.27);
	EXPECT_TRUE(makeInnovation(10 * nu, S, 1.0).gated);
	EXPECT_TRUE(std::isnan(makeInnovation(nu, S, 16.27).sighting_share));
	for (int i = 0; i < 3; ++i)
	{
		EXPECT_NEAR(in.component_nis[i], nu[i] * nu[i] / S(i, i), 1e-12) << i;
		EXPECT_NEAR(in.component_share[i], 0.25, 1e-12) << i;
	}
	// A range-bearing sighting has two components; no R, no shares.
	const Innovation rb = makeInnovation(Eigen::Vector2d(nu[0], nu[1]), S.topLeftCorner<2, 2>(), 9);
	EXPECT_NEAR(rb.component_nis[1], nu[1] * nu[1] / S(1, 1), 1e-12);
	EXPECT_TRUE(std::isnan(rb.component_nis[2]));
	EXPECT_TRUE(std::isnan(rb.component_share[0]));
}

TEST(Innovation, NotPositiveDefiniteIsGatedWithInfiniteNis)
{
	const Eigen::Matrix2d S = Eigen::Vector2d(1.0, -1.0).asDiagonal();
	const Innovation in = makeInnovation(Eigen::Vector2d(0.1, 0.1), S, 1e9);
	EXPECT_TRUE(std::isinf(in.nis));
	EXPECT_TRUE(in.gated);
	EXPECT_EQ(in.dof, 2);
}

// Innovations drawn from the S they are normalised by: mean NIS ~ dof and a
// consistent verdict; the same innovations judged against S / 9 and S * 9
// say "too small" and "too large" by about 9.
TEST(Innovation, VerdictOfDrawnInnovations)
{
	std::mt19937 rng(5);
	std::normal_distribution<double> g;
	Eigen::Matrix3d A;
	A << 0.02, 0, 0, 0.001, 0.003, 0, 0.002, -0.001, 0.01;
	const Eigen::Matrix3d S = A * A.transpose();
	for (const double k : {1.0, 1.0 / 9.0, 9.0})
	{
		LocalizeSummary s;
		for (int i = 0; i < 2000; ++i)
		{
			PathRow r;
			const Eigen::Vector3d nu = A * Eigen::Vector3d(g(rng), g(rng), g(rng));
			r.stats.innovations.push_back(makeInnovation(nu, k * S, 16.27));
			s.rows.push_back(r);
		}
		summariseInnovations(s);
		EXPECT_EQ(s.nis_count, 2000);
		EXPECT_NEAR(s.nis_dof, 3.0, 1e-12);
		EXPECT_NEAR(s.nis_mean / s.nis_dof, 1.0 / k, 0.1 / k) << k;
		// Each component alone says the same.
		for (size_t i = 0; i < 3; ++i)
			EXPECT_NEAR(s.nis_component_mean[i], 1.0 / k, 0.1 / k) << k << " component " << i;
		if (k == 1.0)
		{
			EXPECT_EQ(s.nis_verdict, "consistent");
			EXPECT_LT(s.gated_fraction, 0.01);
		}
		else if (k < 1)
			EXPECT_EQ(s.nis_verdict.rfind("covariances too small by about ", 0), 0u)
				<< s.nis_verdict;
		else
			EXPECT_EQ(s.nis_verdict.rfind("covariances too large by about ", 0), 0u)
				<< s.nis_verdict;
	}
}

TEST(Innovation, VerdictBandAndWording)
{
	EXPECT_EQ(nisVerdict(3.0, 3.0, 10), "consistent");
	EXPECT_EQ(nisVerdict(1.5, 3.0, 10), "consistent");
	EXPECT_EQ(nisVerdict(6.0, 3.0, 10), "consistent");
	EXPECT_EQ(nisVerdict(24.0, 3.0, 10), "covariances too small by about 8x");
	EXPECT_EQ(nisVerdict(0.75, 3.0, 10), "covariances too large by about 4x");
	EXPECT_EQ(nisVerdict(0.0, 0.0, 0), "no sightings tested");
}

// A component the sightings barely inform (here the bearing: its
// measurement variance 1e-4 of the prediction's) reads the prediction's
// scale whatever the sightings' covariance; the others are not counted.
TEST(Innovation, PredictionCheckReadsTheComponentsTheSightingsBarelyInform)
{
	std::mt19937 rng(7);
	std::normal_distribution<double> g;
	const Eigen::Vector3d P(1e-6, 1e-4, 1e-6), R(1e-4, 1e-8, 1e-4);
	for (const double q : {1.0, 1.0 / 9.0, 9.0})
	{
		LocalizeSummary s;
		s.method = "ekf";
		for (int i = 0; i < 2000; ++i)
		{
			PathRow r;
			// The prediction's true spread is q times the one the filter has.
			const Eigen::Vector3d sd = (q * P + R).cwiseSqrt();
			const Eigen::Vector3d nu(sd[0] * g(rng), sd[1] * g(rng), sd[2] * g(rng));
			const Eigen::MatrixXd Rm = R.asDiagonal().toDenseMatrix();
			r.stats.innovations.push_back(
				makeInnovation(nu, Eigen::Matrix3d((P + R).asDiagonal()), 1e9, &Rm));
			s.rows.push_back(r);
		}
		summariseInnovations(s);
		EXPECT_EQ(s.prediction.components, "bearing");
		EXPECT_NEAR(s.prediction.ratio, q, 0.1 * q) << q;
		if (q == 1.0)
			EXPECT_EQ(s.prediction.verdict, "consistent");
		else if (q > 1)
			EXPECT_EQ(s.prediction.verdict.rfind("too small by about ", 0), 0u)
				<< s.prediction.verdict;
		else
			EXPECT_EQ(s.prediction.verdict.rfind("too large by about ", 0), 0u)
				<< s.prediction.verdict;
		EXPECT_EQ(s.prediction.off(), q != 1.0) << q;
		const auto j = nlohmann::json::parse(summaryJson(s));
		EXPECT_EQ(j.at("prediction_check").at("components"), "bearing");
		EXPECT_EQ(j.at("prediction_check").at("verdict"), s.prediction.verdict);
	}
	// Without a component under the share, or without shares: no check.
	InnovationSummary n;
	n.component_nis = {1.0, 0.2, 1.0};
	n.component_share = {0.5, 0.2, 0.9};
	EXPECT_TRUE(predictionCheck(n, kInnovationComponents).verdict.empty());
	n.component_share = Innovation::nanComponents();
	EXPECT_TRUE(predictionCheck(n, kInnovationComponents).verdict.empty());
	EXPECT_FALSE(predictionCheck(n, kInnovationComponents).off());
	LocalizeSummary none;
	none.method = "ekf";
	EXPECT_TRUE(nlohmann::json::parse(summaryJson(none)).at("prediction_check").is_null());
}

// Infinite NIS count as gated and stay out of the mean.
TEST(Innovation, SummaryKeepsInfiniteNisOutOfTheMean)
{
	LocalizeSummary s;
	PathRow r;
	Innovation a;
	a.nis = 2;
	a.dof = 2;
	Innovation b;
	b.nis = std::numeric_limits<double>::infinity();
	b.gated = true;
	r.stats.innovations = {a, b};
	s.rows.push_back(r);
	summariseInnovations(s);
	EXPECT_EQ(s.nis_count, 1);
	EXPECT_DOUBLE_EQ(s.nis_mean, 2.0);
	EXPECT_DOUBLE_EQ(s.gated_fraction, 0.5);
	const std::string json = summaryJson(s);
	for (const char* key :
		 {"\"nis_mean\"", "\"nis_dof\"", "\"nis_count\"", "\"gated_fraction\"", "\"nis_verdict\""})
		EXPECT_NE(json.find(key), std::string::npos) << key;
}

// Twelve visits of three landmarks, ten steps of one sighting each and a
// step without sightings after each visit (which ends it), summarised;
// \a sighting(visit, k) gives the k-th sighting of a visit.
template <class Sighting>
InnovationSummary summariseVisits(Sighting sighting)
{
	std::vector<std::vector<Innovation>> steps;
	for (int visit = 0; visit < 12; ++visit)
	{
		for (int k = 0; k < 10; ++k)
		{
			Innovation in = sighting(visit, k);
			in.id = visit % 3;
			steps.push_back({in});
		}
		steps.emplace_back();
	}
	std::vector<const std::vector<Innovation>*> ptrs;
	ptrs.reserve(steps.size());
	for (const auto& s : steps) ptrs.push_back(&s);
	return summariseInnovations(ptrs);
}

// Visits: a landmark's first sighting after a step without it. Drawn NIS
// with the visits' scale 4x the others' flag persistent errors; the same
// scale does not (at the 1% level, over these seeds' draws).
TEST(Innovation, PersistentErrorsShowAtTheVisits)
{
	std::mt19937 rng(11);
	std::chi_squared_distribution<double> chi2(3.0);
	for (const double visit_scale : {1.0, 4.0})
	{
		const InnovationSummary r = summariseVisits(
			[&](int, int k)
			{
				Innovation in;
				in.nis = (k == 0 ? visit_scale : 1.0) * chi2(rng);
				return in;
			});
		EXPECT_EQ(r.visits, 12);
		EXPECT_EQ(r.count, 120);
		EXPECT_EQ(r.persistent_errors, visit_scale > 1) << visit_scale;
		EXPECT_NEAR(r.visit_ratio / r.other_ratio, visit_scale, 0.5 * visit_scale);
	}
}

// A visit whose first sighting lies beyond the gate (an outlier the filters
// reject) is left out of the comparison: three such sightings in twelve
// visits, each with a NIS of 60, would flag persistent errors on their own.
TEST(Innovation, SightingsBeyondTheGateStayOutOfTheVisits)
{
	for (const bool gated : {true, false})
	{
		std::mt19937 rng(11);
		std::chi_squared_distribution<double> chi2(3.0);
		const InnovationSummary r = summariseVisits(
			[&](int visit, int k)
			{
				Innovation in;
				in.nis = chi2(rng);
				if (k == 0 && visit % 4 == 0)
				{
					in.nis = 60;
					in.gated = gated;
				}
				return in;
			});
		EXPECT_EQ(r.count, 120);  // the mean NIS keeps every sighting
		EXPECT_EQ(r.gated, gated ? 3 : 0);
		EXPECT_EQ(r.visits, gated ? 9 : 12);
		EXPECT_EQ(r.persistent_errors, !gated) << gated;
	}
}
