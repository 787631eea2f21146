// The normalised innovation squared of one sighting, shared by every filter.
#include <codemark/filters/localizer.h>

#include <mrpt/math/distributions.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <iomanip>
#include <set>
#include <sstream>
#include <cmath>
#include <limits>

namespace codemark::filters
{
Innovation makeInnovation(
	const Eigen::VectorXd& nu, const Eigen::MatrixXd& S, double gate, const Eigen::MatrixXd* R)
{
	Innovation in;
	in.dof = static_cast<int>(nu.size());
	const Eigen::LLT<Eigen::MatrixXd> llt(S);
	if (llt.info() != Eigen::Success || !nu.allFinite())
	{
		in.nis = std::numeric_limits<double>::infinity();
		in.log_det_s = 0;
		in.gated = true;
		return in;
	}
	in.nis = nu.dot(llt.solve(nu));
	const Eigen::VectorXd d = llt.matrixL().toDenseMatrix().diagonal();
	in.log_det_s = 2.0 * d.array().log().sum();
	in.gated = !(in.nis <= gate);
	if (R) in.sighting_share = llt.solve(*R).trace() / double(in.dof);
	for (int i = 0; i < std::min(in.dof, 3); ++i)
	{
		in.component_nis[i] = nu[i] * nu[i] / S(i, i);
		if (R) in.component_share[i] = (*R)(i, i) / S(i, i);
	}
	return in;
}
InnovationSummary summariseInnovations(const std::vector<const std::vector<Innovation>*>& steps)
{
	InnovationSummary r;
	double sum = 0, dof = 0, share = 0, visit_nis = 0, visit_dof = 0, other_nis = 0, other_dof = 0;
	long shared = 0;
	// Per component: sums and counts of its NIS and of its sighting share.
	std::array<double, 3> c_nis{}, c_share{};
	std::array<long, 3> n_nis{}, n_share{};
	std::set<int> before;
	for (const auto* step : steps)
	{
		std::set<int> now;
		for (const auto& in : *step)
		{
			++r.tested;
			r.gated += in.gated ? 1 : 0;
			now.insert(in.id);
			if (!std::isfinite(in.nis))
			{
				r.neg_log_likelihood = std::numeric_limits<double>::infinity();
				continue;
			}
			++r.count;
			sum += in.nis;
			dof += in.dof;
			r.neg_log_likelihood += 0.5 * (in.log_det_s + in.nis);
			if (std::isfinite(in.sighting_share)) share += in.sighting_share, ++shared;
			for (size_t i = 0; i < 3; ++i)
			{
				if (std::isfinite(in.component_nis[i])) c_nis[i] += in.component_nis[i], ++n_nis[i];
				if (std::isfinite(in.component_share[i]))
					c_share[i] += in.component_share[i], ++n_share[i];
			}
			// Visits and the others compare the sightings inside the gate: one
			// beyond it is an outlier the filters reject (counted in gated),
			// and one such NIS would outweigh a run's visits.
			if (in.gated) continue;
			if (!before.count(in.id))
				++r.visits, visit_nis += in.nis, visit_dof += in.dof;
			else
				other_nis += in.nis, other_dof += in.dof;
		}
		before = std::move(now);
	}
	if (r.count == 0) return r;
	r.nis_mean = sum / double(r.count);
	r.nis_dof = dof / double(r.count);
	if (shared) r.sighting_share = share / double(shared);
	for (size_t i = 0; i < 3; ++i)
	{
		if (n_nis[i]) r.component_nis[i] = c_nis[i] / double(n_nis[i]);
		if (n_share[i]) r.component_share[i] = c_share[i] / double(n_share[i]);
	}
	r.visit_ratio = visit_dof > 0 ? visit_nis / visit_dof : 0.0;
	r.other_ratio = other_dof > 0 ? other_nis / other_dof : 0.0;
	// Under "the visits' NIS have the others' scale", visit_nis / other_ratio
	// is chi-square with visit_dof degrees of freedom.
	r.persistent_errors = r.visits >= 3 && r.other_ratio > 0 &&
						  visit_nis / r.other_ratio > mrpt::math::chi2inv(0.99, visit_dof);
	return r;
}

namespace
{
// "consistent" when \a k lies in the band, else how far off a covariance
// is: "too small by about Kx" (k > the band) or "too large by about (1/k)x",
// with 2 significant digits.
std::string bandVerdict(double k)
{
	if (k >= kNisConsistentLow && k <= kNisConsistentHigh) return "consistent";
	std::ostringstream o;
	o << std::setprecision(2);
	if (k > kNisConsistentHigh)
		o << "too small by about " << k << "x";
	else
		o << "too large by about " << (k > 0 ? 1.0 / k : 1e9) << "x";
	return o.str();
}
}  // namespace

std::string nisVerdict(double nis_mean, double nis_dof, long count)
{
	if (count <= 0 || !(nis_dof > 0)) return "no sightings tested";
	const std::string v = bandVerdict(nis_mean / nis_dof);
	return v == "consistent" ? v : "covariances " + v;
}

PredictionCheck predictionCheck(const InnovationSummary& s, const std::array<const char*, 3>& names)
{
	PredictionCheck c;
	double sum = 0;
	int n = 0;
	for (size_t i = 0; i < 3; ++i)
	{
		const double k = s.component_nis[i], share = s.component_share[i];
		if (!std::isfinite(k) || !(share < kPredictionComponentShare)) continue;
		c.components += std::string(n ? " and " : "") + names[i];
		sum += k;
		++n;
	}
	if (n == 0) return c;
	c.ratio = sum / n;
	c.verdict = bandVerdict(c.ratio);
	return c;
}

bool converged(const Eigen::Matrix3d& cov, double std_xy_m, double std_yaw_rad)
{
	const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov.topLeftCorner<2, 2>());
	const double std_xy = std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()));
	const double std_yaw = std::sqrt(std::max(0.0, cov(2, 2)));
	return std_xy < std_xy_m && std_yaw < std_yaw_rad;
}

}  // namespace codemark::filters
