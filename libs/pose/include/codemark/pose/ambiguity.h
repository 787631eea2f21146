#pragma once
/** \file ambiguity.h
 * The two-fold ambiguity of a small planar landmark, folded into the
 * reported covariance.
 *
 * Far and near-frontal, the corners hardly tell the landmark's orientation
 * phi2 from its mirror image about the line of sight (view angle
 * phi1 + phi2 -> -(phi1 + phi2)): both fit the corners, and a bias of a
 * few hundredths of a pixel decides which is the least-squares optimum (the
 * planar-pose ambiguity that IPPE returns as two solutions). The local,
 * first-order covariance of the chosen mode knows nothing of the other, so
 * when the wrong mode wins it can report phi2 tightly about a value many of
 * its own sigmas from the truth (see docs/benchmarks/pose.md). Here the two
 * modes are weighed by Laplace's approximation of their probability mass,
 * and the reported covariance is
 * the mean squared error about the best-fitting mode over both: the
 * smallest covariance that stays honest whichever mode is true.
 */
#include <Eigen/Core>

namespace codemark::pose
{
/** One local optimum of a sighting's likelihood, with its Gaussian (local)
 * approximation. */
struct MeasurementMode
{
	Eigen::Vector3d L = Eigen::Vector3d::Zero();  //!< [l2 phi1 phi2] at the mode
	Eigen::Matrix3d C_L = Eigen::Matrix3d::Zero();	//!< its local covariance
	Eigen::Vector3d pose_in_landmark = Eigen::Vector3d::Zero();	 //!< (x, y, theta) in L
	Eigen::Matrix3d C_R = Eigen::Matrix3d::Zero();	//!< its local covariance
	/** The data's squared Mahalanobis residual at the mode (P's against C_P
	 * on the closed form, the corners' against their covariance on the
	 * general path). */
	double chi2 = 0;
	/** log det of the covariance of the parameters solved for at the mode
	 * (L on the closed form, the 6-DoF pose on the general path): the
	 * width of the mode in Laplace's approximation of its mass. */
	double log_det_cov = 0;
};

/** The posterior probability of mode \a b when the data has modes \a a and
 * \a b only (flat prior; Laplace's approximation of each mode's mass,
 * exp(-chi2 / 2) sqrt(det cov)). 0.5 for two equal modes. */
double secondModeWeight(const MeasurementMode& a, const MeasurementMode& b);

/** \a b folded into \a a, the caller's best fit (measure(): the lower chi2
 * on the closed form, the lower RMS reprojection error on the general
 * path): \a a's L and pose, each covariance the mean squared error about
 * them over the two-mode mixture, (1 - w) C_a + w (C_b + d d^T), w = \a b's
 * probability (secondModeWeight(); above 0.5 when \a b fits almost as well
 * and is wider) and d the difference of the means (angles wrapped). \a
 * other_weight, if not null, receives w. chi2 and log_det_cov are \a a's. */
MeasurementMode foldModes(
	const MeasurementMode& a, const MeasurementMode& b, double* other_weight = nullptr);

}  // namespace codemark::pose
