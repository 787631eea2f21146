#pragma once
// The tests' one numeric differentiation: central differences, against
// which every analytic Jacobian is checked.
#include <mrpt/math/wrap2pi.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <initializer_list>

namespace codemark::test
{
/** d f / d x at \a x by central differences: column k is (f(x + h e_k) -
 * f(x - h e_k)) / 2h with h = \a step max(1, |x_k|). The rows listed in \a
 * angle_rows are angles: their differences are wrapped to (-pi, pi]. */
template <typename F, typename Derived>
Eigen::MatrixXd numericJacobian(
	const F& f, const Eigen::MatrixBase<Derived>& x, double step = 1e-6,
	std::initializer_list<int> angle_rows = {})
{
	using Vec = typename Derived::PlainObject;
	const Vec x0 = x;
	Eigen::MatrixXd J;
	for (Eigen::Index k = 0; k < x0.size(); ++k)
	{
		const double h = step * std::max(1.0, std::abs(x0[k]));
		Vec a = x0, b = x0;
		a[k] += h;
		b[k] -= h;
		Eigen::VectorXd d = f(a) - f(b);
		for (const int r : angle_rows) d[r] = mrpt::math::wrapToPi(d[r]);
		if (J.size() == 0) J.resize(d.size(), x0.size());
		J.col(k) = d / (2 * h);
	}
	return J;
}
}  // namespace codemark::test
