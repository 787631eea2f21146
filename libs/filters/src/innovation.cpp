// The normalised innovation squared of one sighting, shared by every filter.
#include <codemark/filters/localizer.h>

#include <Eigen/Cholesky>
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
	return in;
}
}  // namespace codemark::filters
