#include <codemark/pose/consistency.h>
#include <mrpt/math/distributions.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace codemark::pose
{
double studentTQuantile(double p, double nu)
{
	if (!(p > 0 && p < 1) || !(nu > 0))
		throw std::invalid_argument("studentTQuantile: needs 0 < p < 1 and nu > 0");
	// MRPT has the normal's quantile but not Student's: Abramowitz & Stegun
	// 26.7.5, four terms.
	const double z = mrpt::math::normalQuantile(p), z2 = z * z;
	const double g1 = (z2 + 1) * z / 4;
	const double g2 = ((5 * z2 + 16) * z2 + 3) * z / 96;
	const double g3 = (((3 * z2 + 19) * z2 + 17) * z2 - 15) * z / 384;
	const double g4 = ((((79 * z2 + 776) * z2 + 1482) * z2 - 1920) * z2 - 945) * z / 92160;
	return z + g1 / nu + g2 / (nu * nu) + g3 / (nu * nu * nu) + g4 / (nu * nu * nu * nu);
}

ClusteredMean clusteredMean(const std::vector<NeesCluster>& clusters, int dof, double probability)
{
	if (dof < 1 || !(probability > 0 && probability < 1))
		throw std::invalid_argument("clusteredMean: needs dof >= 1 and 0 < probability < 1");
	ClusteredMean r;
	double sum = 0;
	for (const NeesCluster& c : clusters)
		if (c.count > 0)
		{
			sum += c.sum;
			r.count += c.count;
			++r.clusters;
		}
	if (r.count == 0) return r;
	r.mean = sum / r.count;
	if (r.clusters < 2)
	{
		const double inf = std::numeric_limits<double>::infinity();
		r.standard_error = r.high = r.design_effect = inf;
		r.low = -inf;
		return r;
	}
	// Linearised variance of the ratio sum / count over clusters drawn
	// independently: sum_g (s_g - mean n_g)^2 / N^2, times G / (G - 1).
	double v = 0;
	for (const NeesCluster& c : clusters)
		if (c.count > 0) v += std::pow(c.sum - r.mean * c.count, 2);
	const double G = r.clusters, N = r.count;
	v *= G / (G - 1) / (N * N);
	r.standard_error = std::sqrt(v);
	const double t = studentTQuantile(0.5 + probability / 2, G - 1);
	r.low = r.mean - t * r.standard_error;
	r.high = r.mean + t * r.standard_error;
	r.design_effect = v / (2.0 * dof / N);
	return r;
}

}  // namespace codemark::pose
