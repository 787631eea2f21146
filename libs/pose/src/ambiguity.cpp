#include <codemark/landmark/truth.h>
#include <codemark/pose/ambiguity.h>

#include <cmath>

namespace codemark::pose
{
double secondModeWeight(const MeasurementMode& a, const MeasurementMode& b)
{
	// log(mass_a / mass_b) = -(chi2_a - chi2_b) / 2 + (logdet_a - logdet_b) / 2.
	const double log_ratio = 0.5 * ((b.chi2 - a.chi2) + (a.log_det_cov - b.log_det_cov));
	if (!std::isfinite(log_ratio)) return log_ratio > 0 || std::isnan(log_ratio) ? 0.0 : 1.0;
	return 1.0 / (1.0 + std::exp(log_ratio));
}

MeasurementMode foldModes(const MeasurementMode& a, const MeasurementMode& b, double* other_weight)
{
	// The caller's best fit is kept (on exact corners the truth): a wider
	// mode can hold more mass with a worse fit, and reporting it would move
	// the estimate off the data. The other's weight may then exceed one half.
	const double w = secondModeWeight(a, b);
	Eigen::Vector3d dL = b.L - a.L, dR = b.pose_in_landmark - a.pose_in_landmark;
	dL[1] = wrapToPi(dL[1]);
	dL[2] = wrapToPi(dL[2]);
	dR[2] = wrapToPi(dR[2]);
	MeasurementMode out = a;
	out.C_L = (1 - w) * a.C_L + w * (b.C_L + dL * dL.transpose());
	out.C_R = (1 - w) * a.C_R + w * (b.C_R + dR * dR.transpose());
	if (other_weight) *other_weight = w;
	return out;
}

}  // namespace codemark::pose
