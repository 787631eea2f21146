#pragma once
/** \file consistency.h
 * The mean NEES of sightings that come in clusters, and its interval.
 *
 * The chi-square band of a mean NEES, chi2inv(0.025 / 0.975, d N) / N,
 * holds for N independent sightings. The accuracy map's are not: the renders
 * of one cell share its geometry, and with it the detector's systematic
 * error there (a thin frame's bias, a pixel phase), so their errors move
 * together and the mean wanders far more than the band allows. With the
 * clusters as the independent units, the mean's standard error comes from
 * the spread of the clusters' sums (the cluster-robust,
 * "sandwich" variance of a ratio mean), and its interval from Student's t
 * with (clusters - 1) degrees of freedom.
 */
#include <vector>

namespace codemark::pose
{
/** One cluster: the sum of its sightings' NEES and how many there are. */
struct NeesCluster
{
	double sum = 0;
	int count = 0;
};

/** The pooled mean and its interval with clusters as the units. */
struct ClusteredMean
{
	double mean = 0;  //!< sum of the sums / sum of the counts
	int clusters = 0;  //!< clusters with at least one sighting
	int count = 0;	//!< sightings
	double standard_error = 0;	//!< of the mean, clusters as units (infinite below 2 clusters)
	double low = 0, high = 0;  //!< the two-sided interval at the given probability
	/** The mean's variance over the one of \a count independent chi-square
	 * draws of \a dof degrees of freedom (2 dof / count): how many times
	 * wider than the chi-square band the honest interval is, squared. */
	double design_effect = 0;
};

/** The mean of \a clusters' sightings and its two-sided \a probability
 * interval with the clusters as the independent units; \a dof the NEES's
 * degrees of freedom (for the design effect only). */
ClusteredMean clusteredMean(
	const std::vector<NeesCluster>& clusters, int dof, double probability = 0.95);

/** Student's t quantile: the \a p quantile of t with \a nu degrees of freedom
 * (Cornish-Fisher expansion about the normal; relative error under 2e-3
 * from nu = 3, under 2e-5 from nu = 10). */
double studentTQuantile(double p, double nu);

}  // namespace codemark::pose
