// Stage 7: sub-pixel edge points, line fits, corners.
#include "edge_models.h"
#include "stages.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

namespace codemark::detect
{
namespace
{
/** The fill band counts as clipped throughout at this fraction of its
 * samples at 255, and needs this many samples to say. */
constexpr double kAllClippedFraction = 0.9;
constexpr int kMinFillSamples = 20;
/** A sensor quieter than this [grey levels] (centreCellNoise() reads 0:
 * most neighbouring pixels equal) can hold a fill at exactly its top. */
constexpr double kQuietNoise = 0.5;
/** G's own rounding on an edge of the spec's contrast (230 levels) [px]. */
constexpr double kGRoundingPx = 0.5 / 230;
/** thinFrameOffset() on frames at least this wide [px], the blur it shares
 * from frames at least this wide. */
constexpr double kMinThinModelPx = 2.0;
constexpr double kMinBlurFramePx = 2.5;
/** Seed of the derivative peak's variance [px^2] for the outer-edge lobe
 * model when the three samples give none: a Gaussian edge blur of about
 * 0.6 px plus the central difference's 2-px box (4/12 px^2). */
constexpr double kLobeSeedVarPx2 = 0.7;

/** The peak of three samples a, b, c at -1, 0, 1 (b the largest): a
 * Gaussian through them (log-parabola), or a parabola where the logarithm
 * is undefined. Returns the offset and, for the Gaussian, its variance
 * through \a var (0 otherwise). */
double peakOffset(double a, double b, double c, double& var)
{
	var = 0;
	if (a > 0 && c > 0 && b > 0)
	{
		const double la = std::log(a), lb = std::log(b), lc = std::log(c);
		const double den = la - 2 * lb + lc;
		if (den < 0)
		{
			var = -1 / den;
			return std::clamp(0.5 * (la - lc) / den, -0.5, 0.5);
		}
	}
	const double den = a - 2.0 * b + c;
	return den < 0 ? std::clamp(0.5 * (a - c) / den, -0.5, 0.5) : 0.0;
}

/** The derivative peak of three samples \a d at peak - 1, peak, peak + 1
 * refined with the exact response of a pixel-integrated Gaussian step:
 * the central difference at sample k of a step of height A at e, blurred
 * by sigma, is A (S(k + 1 - e) - S(k - 1 - e)), S = pixelStep().value. The
 * three samples fix e, sigma and A (damped Newton from the log-parabola's
 * \a e0 and \a var0). The log-parabola's Gaussian is that response only
 * for a wide blur: on a sharp edge (three samples f, 1, 1 - f of the step)
 * it errs by up to 0.07 px with the edge's phase in its pixel. Returns
 * \a e0 where the fit fails. Written by hand: it runs once per profile,
 * where cv::LMSolver's set-up would cost more than the fit. */
double stepPeak(const std::array<double, 3>& d, int peak, double e0, double var0)
{
	// Variance of the central difference of the step: the blur's, the
	// pixel's (1/12) and the difference's 2-px box (1/3).
	constexpr double kSamplingVar = 1.0 / 12 + 1.0 / 3;
	constexpr double kMinSigma = 0.01, kMaxSigma = 3;
	Eigen::Vector3d q(
		e0,
		std::clamp(
			var0 > kSamplingVar ? std::sqrt(var0 - kSamplingVar) : 0.5, kMinSigma, kMaxSigma),
		0);
	// The height A (q[2]) at 0: set from the peak sample at the first call.
	const auto model = [&](Eigen::Vector3d& x, Eigen::Matrix3d* J)
	{
		// The three differences use the step at five samples, peak - 2 ..
		// peak + 2.
		std::array<PixelStep, 5> st;
		pixelSteps(peak - 2 - x[0], x[1], 5, st.data());
		if (x[2] == 0 && st[3].value > st[1].value) x[2] = d[1] / (st[3].value - st[1].value);
		Eigen::Vector3d r;
		for (int i = 0; i < 3; ++i)
		{
			const PixelStep &sp = st[i + 2], &sm = st[i];
			r[i] = x[2] * (sp.value - sm.value) - d[i];
			if (J)
				J->row(i) << x[2] * (sm.d_x - sp.d_x), x[2] * (sp.d_sigma - sm.d_sigma),
					sp.value - sm.value;
		}
		return r;
	};
	Eigen::Matrix3d J;
	Eigen::Vector3d r = model(q, &J);
	if (q[2] <= 0) return e0;
	double cost = r.squaredNorm(), mu = 1e-3;
	const double tol = 1e-12 * d[1] * d[1];
	for (int it = 0; it < 20 && cost > tol && mu < 1e8; ++it)
	{
		Eigen::Matrix3d A = J.transpose() * J;
		A.diagonal() += mu * A.diagonal().cwiseMax(1e-12);
		// Eigen's closed-form 3x3 inverse (cofactors): the damped matrix is
		// positive definite, and the inverse costs a fraction of an LDLT
		// here, where this fit runs once per profile.
		const Eigen::Vector3d step = -(A.inverse() * (J.transpose() * r));
		if (!step.allFinite()) break;
		Eigen::Vector3d cand = q + step;
		cand[0] = std::clamp(cand[0], peak - 1.0, peak + 1.0);
		cand[1] = std::clamp(cand[1], kMinSigma, kMaxSigma);
		cand[2] = std::max(cand[2], 1e-9);
		Eigen::Matrix3d Jc;
		const Eigen::Vector3d rc = model(cand, &Jc);
		if (rc.squaredNorm() < cost)
		{
			// The step taken: a blur held at its bound (a sharp edge in
			// linear light) proposes steps it cannot take.
			const Eigen::Vector3d taken = cand - q;
			q = cand;
			r = rc;
			J = Jc;
			cost = rc.squaredNorm();
			mu = std::max(1e-9, mu * 0.3);
			if (std::abs(taken[0]) < 1e-4 && std::abs(taken[1]) < 1e-3) break;
		}
		else
			mu *= 10;
	}
	return std::abs(q[0] - e0) <= 0.5 ? q[0] : e0;
}
}  // namespace

std::optional<double> locateRisingEdge(
	const int* v, int n, int lo, int hi, double min_rise, const SubpixelParams& p, EdgeMode mode,
	double neighbour_px)
{
	lo = std::max(lo, 1);
	hi = std::min(hi, n - 2);
	if (lo > hi) return std::nullopt;
	// Central difference, twice the slope [grey levels / px].
	auto d = [&](int k) { return v[k + 1] - v[k - 1]; };
	const int peak = steepestRise(v, lo, hi);
	const int dp = d(peak);
	if (dp < 2 * min_rise) return std::nullopt;
	const bool at_peak = mode == EdgeMode::Peak || mode == EdgeMode::PeakGaussian;
	const bool monotone = mode == EdgeMode::IsolatedCentroid;
	if (at_peak)
	{
		// The derivative's peak: a Gaussian (log-parabola) through the three
		// samples around it.
		const int km = peak - 1 >= 1 ? peak - 1 : peak, kp = peak + 1 <= n - 2 ? peak + 1 : peak;
		double var = 0;
		double e = peak + peakOffset(d(km), dp, d(kp), var);
		// The three samples last fitted (with the lobe removed).
		std::array<double, 3> fitted{double(d(km)), double(dp), double(d(kp))};
		// A falling edge neighbour_px before this one (the frame's outer
		// edge) adds a negative lobe whose tail tilts the three samples and
		// pulls the peak away from it, by up to half a pixel when the frame
		// is 1.6 px wide. Remove a Gaussian model of that lobe (its width
		// that of the peak, its height from the samples at the neighbour,
		// less this peak's tail there) and fit again, a few times.
		const int ko = static_cast<int>(std::lround(e - neighbour_px));
		// A lobe strong enough to make the outer neighbour sample negative
		// (a frame under ~1.8 px against a bright wall) leaves the
		// log-parabola without a width, precisely where the pull is largest
		// (0.3-0.5 px at 5 m and 60 deg): seed the lobe model with a typical
		// width instead; its iterations re-estimate the width from the
		// corrected samples (the result moves by < 0.005 px for seeds of 0.5
		// to 0.9 px^2).
		// A negative neighbour_px puts that edge after this one (the quiet
		// margin's outer edge, read from the frame outwards).
		const bool before = neighbour_px > 0;
		if (neighbour_px != 0 && var <= 0) var = kLobeSeedVarPx2;
		if (neighbour_px != 0 && var > 0 && ko >= 1 && ko <= n - 2 &&
			(before ? ko < peak : ko > peak))
		{
			int lowest = d(ko);
			for (int k = before ? std::max(1, ko - 1) : std::max(peak + 1, ko - 1);
				 k <= (before ? std::min(ko + 1, peak - 1) : std::min(ko + 1, n - 2)); ++k)
				lowest = std::min(lowest, d(k));
			if (lowest < 0)
			{
				double amp = dp;
				for (int it = 0; it < 4 && var > 0; ++it)
				{
					const double o = e - neighbour_px;
					const double g = [&]
					{ return std::exp(-neighbour_px * neighbour_px / (2 * var)); }();
					const double B = -lowest + amp * g;
					const auto lobe = [&](int k)
					{ return B * std::exp(-(k - o) * (k - o) / (2 * var)); };
					const double a = d(km) + lobe(km), b = dp + lobe(peak), c = d(kp) + lobe(kp);
					double v2 = 0;
					const double off = peakOffset(a, b, c, v2);
					if (v2 <= 0) break;
					const bool settled = std::abs(peak + off - e) < 1e-4;
					e = peak + off;
					var = v2;
					amp = b;
					fitted = {a, b, c};
					if (settled) break;
				}
			}
		}
		return km < peak && kp > peak && mode == EdgeMode::Peak ? stepPeak(fitted, peak, e, var)
																: e;
	}
	// The response of a blurred step: sum the derivative while it stays
	// positive and above a fraction of the peak; its centroid is the edge
	// (exact for any symmetric point-spread function, box or Gaussian).
	const double floor_v = p.response_floor * dp;
	double s0 = dp, s1 = double(dp) * peak;
	for (int k = peak - 1; k >= std::max(1, peak - p.reach_px); --k)
	{
		const int dk = d(k);
		if (dk <= floor_v || (monotone && dk > d(k + 1))) break;
		s0 += dk;
		s1 += double(dk) * k;
	}
	for (int k = peak + 1; k <= std::min(n - 2, peak + p.reach_px); ++k)
	{
		const int dk = d(k);
		if (dk <= floor_v || (monotone && dk > d(k - 1))) break;
		s0 += dk;
		s1 += double(dk) * k;
	}
	return s1 / s0;
}

std::optional<double> correctLevelRounding(
	const std::vector<int>& g_profiles, int n, const std::vector<int>& along,
	const std::vector<int>& origin, int half, int inward, std::vector<std::optional<double>>& edges)
{
	constexpr int kMinSharp = 10;
	constexpr double kMinSharpShare = 0.8;
	constexpr int kMinContrast = 20;
	struct Sharp
	{
		size_t j;
		int m, v;
		double f = 0;  //!< (v - L) / (H - L), once L and H are known
	};
	std::vector<Sharp> sharp;
	int with_edge = 0, L = -1, H = -1;
	for (size_t j = 0; j < edges.size(); ++j)
	{
		if (!edges[j]) continue;
		++with_edge;
		const int m = static_cast<int>(std::lround(*edges[j]));
		if (m < 2 || m + 2 >= n) continue;
		const int* v = g_profiles.data() + j * n;
		if (v[m - 2] != v[m - 1] || v[m + 1] != v[m + 2] || v[m] < v[m - 1] || v[m] > v[m + 1])
			continue;
		if (L < 0)
		{
			L = v[m - 1];
			H = v[m + 1];
		}
		if (v[m - 1] != L || v[m + 1] != H) return std::nullopt;  // two levels: not one rounding
		sharp.push_back({j, m, v[m]});
	}
	const int count = static_cast<int>(sharp.size());
	if (count < kMinSharp || count < kMinSharpShare * with_edge || H - L < kMinContrast)
		return std::nullopt;
	const double A = H - L;
	// Unknowns: the line's intercept and slope (along centred) and c.
	// Weights in grey levels: a mixed sample's rounding has variance 1/12,
	// c's prior (the difference of two uniform roundings) 1/6.
	double mean_s = 0;
	for (const auto& k : sharp) mean_s += along[k.j];
	mean_s /= count;
	Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
	Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
	for (auto& k : sharp)
	{
		k.f = (k.v - L) / A;
		// The sharp edge's own estimate: the pixel's boundary less f, at
		// across coordinate origin + inward (edge - half).
		const double c = origin[k.j] + inward * (k.m + 0.5 - k.f - half);
		const Eigen::Vector3d phi(1, along[k.j] - mean_s, -inward * k.f / A);
		M += phi * phi.transpose();
		rhs += phi * c;
	}
	M *= 12 * A * A;
	rhs *= 12 * A * A;
	M(2, 2) += 6;
	const double c_level = std::clamp(M.ldlt().solve(rhs)[2], -1.0, 1.0);
	for (const auto& k : sharp) edges[k.j] = k.m + 0.5 - k.f + k.f * c_level / A;
	return c_level;
}

std::optional<double> thinFrameOffset(
	const std::vector<int>& g_profiles, int n, const std::vector<std::optional<double>>& edges,
	double frame_px, double fixed_sigma, double* sigma_out)
{
	constexpr double kBin = 0.25, kInside = 3.0, kBeyond = 4.0;
	const double x0 = -(frame_px + kBeyond);
	const int bins = static_cast<int>(std::ceil((kInside - x0) / kBin));
	std::vector<double> sum(bins, 0.0), sum_x(bins, 0.0);
	std::vector<int> count(bins, 0);
	int used = 0;
	for (size_t j = 0; j < edges.size(); ++j)
	{
		if (!edges[j]) continue;
		++used;
		const int* v = g_profiles.data() + j * n;
		const double e = *edges[j];
		const int i0 = std::max(0, static_cast<int>(std::ceil(e + x0))),
				  i1 = std::min(n - 1, static_cast<int>(std::floor(e + kInside)));
		for (int i = i0; i <= i1; ++i)
		{
			const int b = static_cast<int>((i - e - x0) / kBin);
			if (b < 0 || b >= bins) continue;
			sum[b] += v[i];
			sum_x[b] += i - e;
			++count[b];
		}
	}
	if (used < 8) return std::nullopt;
	struct Bin
	{
		double x, v, w;
	};
	std::vector<Bin> data;
	for (int b = 0; b < bins; ++b)
		if (count[b] > 0)
			data.push_back({sum_x[b] / count[b], sum[b] / count[b], double(count[b])});
	// Without a blur to hold, the profiles' phases must spread over the
	// pixel (a side slanting across the grid); one phase gives a sample a
	// pixel, too few for the blur as well.
	if (data.size() < (fixed_sigma > 0 ? 9u : 16u)) return std::nullopt;
	// p: W, M, K, G, sigma, margin width, inner offset; the frame width is
	// frame_px.
	using Vec7 = Eigen::Matrix<double, 7, 1>;
	using Mat7 = Eigen::Matrix<double, 7, 7>;
	const auto levelOver = [&](double lo, double hi, bool take_max, bool take_min)
	{
		double acc = 0, w = 0, best = take_max ? -1e9 : 1e9;
		for (const Bin& d : data)
			if (d.x >= lo && d.x <= hi)
			{
				acc += d.v * d.w;
				w += d.w;
				best = take_max ? std::max(best, d.v) : std::min(best, d.v);
			}
		if (w == 0) return std::optional<double>();
		return std::optional<double>(take_max || take_min ? best : acc / w);
	};
	const auto K0 = levelOver(-frame_px, 0, false, true);
	const auto G0 = levelOver(1.5, kInside, false, false);
	const auto M0 = levelOver(-frame_px - 3, -frame_px + 0.5, true, false);
	if (!K0 || !G0 || !M0) return std::nullopt;
	const auto W0 = levelOver(x0, -frame_px - 3, false, false);
	Vec7 q;
	q << W0.value_or(*M0), *M0, *K0, *G0, fixed_sigma > 0 ? fixed_sigma : 0.8, 1.0, 0.0;
	// Bounds of the blur, the margin's width and the offset (t[4..6]).
	const double lo_bound[3] = {0.2, 0.25 * frame_px, -1.0}, hi_bound[3] = {2.5, kBeyond, 1.0};
	const auto clampParams = [&](Vec7& t)
	{
		t[4] = fixed_sigma > 0 ? fixed_sigma : std::clamp(t[4], lo_bound[0], hi_bound[0]);
		// The sheet's white above the frame's black, the fill above it too.
		t[1] = std::max(t[1], t[2] + 10);
		t[3] = std::max(t[3], t[2] + 10);
		t[5] = std::clamp(t[5], lo_bound[1], hi_bound[1]);
		t[6] = std::clamp(t[6], lo_bound[2], hi_bound[2]);
	};
	// The model's cost at \a t; where it is below \a accept, also its
	// Gauss-Newton Hessian and gradient (a rejected step needs only the
	// cost: the bins' pixel steps and residuals are kept in between).
	std::vector<std::array<PixelStep, 3>> steps(data.size());
	std::vector<double> res(data.size());
	const auto residuals = [&](const Vec7& t, double accept, Mat7& JtJ, Vec7& Jtr)
	{
		const double W = t[0], M = t[1], K = t[2], G = t[3];
		double cost = 0;
		for (size_t b = 0; b < data.size(); ++b)
		{
			// The frame's and the margin's edges move with the inner one.
			const double x = data[b].x - t[6];
			const double at[3] = {x + frame_px + t[5], x + frame_px, x};
			pixelStepsAt(at, 3, t[4], steps[b].data());
			const PixelStep &s1 = steps[b][0], &s2 = steps[b][1], &s3 = steps[b][2];
			const double r = res[b] =
				W + (M - W) * s1.value + (K - M) * s2.value + (G - K) * s3.value - data[b].v;
			cost += data[b].w * r * r;
		}
		if (!(cost < accept)) return cost;
		JtJ.setZero();
		Jtr.setZero();
		for (size_t b = 0; b < data.size(); ++b)
		{
			const PixelStep &s1 = steps[b][0], &s2 = steps[b][1], &s3 = steps[b][2];
			Vec7 J;
			J << 1 - s1.value, s1.value - s2.value, s2.value - s3.value, s3.value,
				fixed_sigma > 0
					? 0.0
					: (M - W) * s1.d_sigma + (K - M) * s2.d_sigma + (G - K) * s3.d_sigma,
				(M - W) * s1.d_x, -((M - W) * s1.d_x + (K - M) * s2.d_x + (G - K) * s3.d_x);
			// The upper triangle only (mirrored below): half the products
			// of the outer product, in this fit's inner loop.
			const Vec7 wJ = data[b].w * J;
			for (int c = 0; c < 7; ++c)
				for (int rw = 0; rw <= c; ++rw) JtJ(rw, c) += wJ[rw] * J[c];
			Jtr += res[b] * wJ;
		}
		for (int c = 0; c < 7; ++c)
			for (int rw = c + 1; rw < 7; ++rw) JtJ(rw, c) = JtJ(c, rw);
		return cost;
	};
	Mat7 H;
	Vec7 g;
	double cost = residuals(q, std::numeric_limits<double>::infinity(), H, g), mu = 1e-3;
	bool converged = false;
	// Box bounds of the blur, the margin and the offset: a parameter at its
	// bound whose gradient points out of the box stays there for the step
	// (projected Newton). Clamping the full step instead left the others'
	// step wrong for as long as the margin sat on its bound (a narrow
	// margin): the fit then zigzagged to the iteration limit.
	for (int it = 0; it < 40 && !converged; ++it)
	{
		Mat7 A = H;
		A.diagonal() += mu * H.diagonal().cwiseMax(1e-9);
		Vec7 g_free = g;
		for (int k = 4; k < 7; ++k)
			if ((q[k] <= lo_bound[k - 4] && g[k] > 0) || (q[k] >= hi_bound[k - 4] && g[k] < 0))
			{
				A.row(k).setZero();
				A.col(k).setZero();
				A(k, k) = 1;
				g_free[k] = 0;
			}
		Vec7 cand = q - A.ldlt().solve(g_free);
		if (!cand.allFinite()) return std::nullopt;
		clampParams(cand);
		Mat7 Hc;
		Vec7 gc;
		const double cc = residuals(cand, cost, Hc, gc);
		if (cc < cost)
		{
			converged = std::abs(cand[6] - q[6]) < 1e-4 && cost - cc < 1e-8 * cost;
			q = cand;
			cost = cc;
			H = Hc;
			g = gc;
			mu = std::max(1e-9, mu * 0.3);
		}
		else
		{
			mu *= 10;
			converged = mu > 1e6;
		}
	}
	if (std::abs(q[6]) > 0.5) return std::nullopt;
	// The offset's standard error (the bins' residual variance), and the
	// offset shrunk by it: d^2 / (d^2 + se^2) of it, so that sides whose
	// profiles show no shift (a wide margin, a frame over 4 px) keep their
	// edges rather than take the fit's noise. A held blur leaves the
	// inverse through a unit diagonal.
	Mat7 Hf = H;
	if (fixed_sigma > 0)
	{
		Hf.row(4).setZero();
		Hf.col(4).setZero();
		Hf(4, 4) = 1;
	}
	const double dof = std::max(1.0, double(data.size()) - (fixed_sigma > 0 ? 6 : 7));
	const double var = (cost / dof) * Hf.inverse()(6, 6);
	if (!(var >= 0)) return std::nullopt;
	if (sigma_out) *sigma_out = q[4];
	const double d2 = q[6] * q[6];
	return q[6] * d2 / (d2 + var);
}

namespace
{
bool fitTls(const std::vector<Eigen::Vector2d>& pts, const std::vector<char>& keep, LineFit& f)
{
	Eigen::Vector2d mean = Eigen::Vector2d::Zero();
	int n = 0;
	for (size_t i = 0; i < pts.size(); ++i)
		if (keep[i])
		{
			mean += pts[i];
			++n;
		}
	if (n < 2) return false;
	mean /= n;
	Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
	for (size_t i = 0; i < pts.size(); ++i)
		if (keep[i])
		{
			const Eigen::Vector2d e = pts[i] - mean;
			cov += e * e.transpose();
		}
	Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
	f.normal = es.eigenvectors().col(0);
	f.c = -f.normal.dot(mean);
	f.support = n;
	return true;
}
}  // namespace

std::optional<LineFit> fitLine(
	std::vector<Eigen::Vector2d> pts, const SubpixelParams& p,
	const std::optional<EdgeResponse>& response)
{
	LineFit f;
	std::vector<char> keep(pts.size(), 1);
	if (static_cast<int>(pts.size()) < std::max(2, p.min_support)) return std::nullopt;
	if (!fitTls(pts, keep, f)) return std::nullopt;
	std::vector<double> r(pts.size());
	for (int it = 0; it < 3; ++it)
	{
		std::vector<double> absr;
		absr.reserve(pts.size());
		for (size_t i = 0; i < pts.size(); ++i)
		{
			r[i] = std::abs(f.normal.dot(pts[i]) + f.c);
			if (keep[i]) absr.push_back(r[i]);
		}
		const double sigma = 1.4826 * medianOf(absr);
		const double limit = std::max(p.outlier_sigmas * sigma, p.min_outlier_px);
		bool changed = false;
		for (size_t i = 0; i < pts.size(); ++i)
		{
			const char k = r[i] <= limit;
			changed |= k != keep[i];
			keep[i] = k;
		}
		if (!changed) break;
		if (!fitTls(pts, keep, f) || f.support < p.min_support) return std::nullopt;
	}
	double ss = 0;
	for (size_t i = 0; i < pts.size(); ++i)
		if (keep[i])
		{
			const double e = f.normal.dot(pts[i]) + f.c;
			ss += e * e;
		}
	f.rms_px = std::sqrt(ss / f.support);
	// The profiles' slope is along their axis; along the normal it is
	// steeper by 1 / |the normal's component on that axis|.
	double max_rms = p.max_rms_px;
	if (response && response->slope > 0)
		max_rms = std::max(
			max_rms, p.max_rms_grey * std::abs(f.normal[response->across]) / response->slope);
	if (f.support < p.min_support || f.rms_px > max_rms) return std::nullopt;
	f.points = std::move(pts);
	return f;
}

namespace
{
/** A thin side (read by the Peak locator in G) kept for
 * applyThinFrameModel(): its profiles and edges. */
struct ThinSide
{
	std::vector<int> g;
	std::vector<std::optional<double>> edges;
	int n, inward, across;
};

/** The thin sides' model of the print (thinFrameOffset()) applied to
 * \a out's lines: the frame's width across each from the refined square's
 * homography (the ratio of the sides' lengths goes as the depth, a
 * foreshortened width as its square), one blur for the landmark, fitted
 * first on sides whose frames are wide enough to show it. */
void applyThinFrameModel(
	RefinedQuad& out, const std::array<std::optional<ThinSide>, 4>& thin, const CameraModel& cam,
	double frame_ratio)
{
	Quad refined;
	for (int k = 0; k < 4; ++k)
	{
		const auto c = cornerOfSides(out.sides, k);
		if (!c) return;
		refined[k] = *c;
	}
	// The lines, and so these corners, are in ideal pixels.
	const FaceMap toPixel{faceToImage(refined), cam, false};
	std::vector<double> sigmas;
	std::array<double, 4> offsets{};
	std::array<bool, 4> done{};
	for (const bool hold : {false, true})
	{
		double sigma = 0;
		if (hold)
		{
			if (sigmas.empty()) break;
			sigma = medianOf(sigmas);
		}
		for (int side = 0; side < 4; ++side)
		{
			if (!thin[side] || done[side]) continue;
			const ThinSide& t = *thin[side];
			const Eigen::Vector2d &f0 = kFaceCorners[side], &f1 = kFaceCorners[(side + 1) % 4];
			const Eigen::Vector2d in = 0.5 * (f0 + f1), outer = in + frame_ratio * (f0 + f1);
			const double width = std::abs(toPixel(outer)(t.across) - toPixel(in)(t.across));
			// Under 2 px the frame never reaches its black: the model cannot
			// tell it from the margin (the fit's levels and blur wander), and
			// the peak model's edges stay.
			if (width < kMinThinModelPx) continue;
			double fitted_sigma = 0;
			if (const auto d = thinFrameOffset(t.g, t.n, t.edges, width, sigma, &fitted_sigma))
			{
				offsets[side] = *d;
				done[side] = true;
				if (!hold && width >= kMinBlurFramePx) sigmas.push_back(fitted_sigma);
			}
		}
	}
	// Each edge moves by the offset along its profile: the line by as much
	// across (undistorted and raw pixels differ by the distortion's scale
	// there, a few percent of a small shift).
	for (int side = 0; side < 4; ++side)
		if (done[side])
		{
			LineFit& l = out.sides[side];
			l.c -= l.normal(thin[side]->across) * thin[side]->inward * offsets[side];
		}
}
}  // namespace

std::optional<RefinedQuad> refineQuadrangle(
	const cv::Mat& bgr, const Quad& coarse, const CameraModel& cam, double min_rise,
	double frame_ratio, const SubpixelParams& p, double fill_ratio, const SubpixelModels& models)
{
	RefinedQuad out;
	// The sensor's noise in the centre cell, read once when a side clips.
	bool noise_read = false;
	std::optional<double> noise;
	const auto sensorNoise = [&]
	{
		if (!noise_read) noise = centreCellNoise(bgr, coarse, codeCellRatio(fill_ratio));
		noise_read = true;
		return noise;
	};
	// The G fill level of each side that clips throughout, from its
	// unclipped channels (fillLevelFromChannels()); undecided: consistent
	// with the top but inconclusive.
	std::array<std::optional<ChannelFillLevel>, 4> channel_level;
	std::array<bool, 4> undecided{}, channels_agree{};
	std::array<std::optional<ThinSide>, 4> thin;
	const auto refineSide = [&](int side, bool retry) -> bool
	{
		SideProfiles prof = readSideProfiles(bgr, coarse, side, frame_ratio, fill_ratio, p);
		const int n = prof.n;
		// A side is saturated when most of its profiles' fill sides average
		// above saturation_level (noise around a fill of exactly 255 does
		// not count), clipped when most reach 255 within two samples of
		// their steepest rise: the locator policy reads both. One locator
		// per side: mixing them would split the points into two
		// populations.
		SideProperties props = measureSide(prof);
		// Where G clips, restore the clipped samples before the edges are
		// read (imputeFillLevel(), imputeClippedSide()): the clip cuts the
		// bright half of the response. The fill band from the coarse line
		// (within about a pixel of the edge): beyond the edge's blur, short
		// of the code board.
		const int band0 = prof.half + 3,
				  band1 = prof.half + static_cast<int>(std::floor(prof.fill_px - 3));
		const ClippedFill band = clippedFill(prof.g, n, band0, band1);
		bool clips = models.clipping && band.count() >= kMinFillSamples &&
					 band.fraction() > p.clipped_fraction;
		bool all_clipped = clips && band.fraction() >= kAllClippedFraction;
		// A band at 255 throughout need not lie above the clip: a noise-free
		// fill at exactly the sensor's top reads 255 everywhere with none of
		// its transitions clipped. There G's own edge is exact, while the
		// clip's estimators are not (R + B next to the G peak has 50 levels
		// of contrast: 0.02 px of rounding). The unclipped channels tell.
		// Only a quiet sensor (noise under half a grey level) does that: with
		// more, a fill at the top leaves part of its band unclipped, and one
		// at 255 throughout is above it, its noise clipped too.
		bool at_top = false;
		if (all_clipped && sensorNoise().value_or(kQuietNoise) < kQuietNoise)
		{
			auto& c = channel_level[side];
			if (!retry)
				c = fillLevelFromChannels(prof.g, prof.rb, n, prof.lo, prof.hi, band0, band1);
			at_top = c && (retry ? c->consistentWithTop() : c->atTop());
			undecided[side] = !at_top && c && c->consistentWithTop();
		}
		if (at_top) clips = all_clipped = props.saturated = false;
		// Part of the fill unclipped: only its noise clips, unless its level
		// is above the clip somewhere (the transitions clip too: the edge
		// model's case, below).
		std::optional<FillLevel> level;
		if (clips && !all_clipped) level = fitFillLevel(prof.g, n, band0, band1, band);
		const bool above_clip = level && level->aboveClip();
		all_clipped = all_clipped || above_clip;
		if (level && !above_clip)
		{
			imputeFillLevel(prof.g, n, *level);
			props.saturated = false;
		}
		SideProperties restored = props;
		restored.saturated = false;
		const auto locateAll = [&](const SideProperties& s) {
			return locateEdges(
				prof, *makeLocator(chooseLocator(s, p, models), min_rise, p, models));
		};
		const LocatorChoice choice = chooseLocator(props, p, models);
		const LocatorKind kind = choice.kind;
		std::vector<std::optional<double>> edges = locateAll(props);
		// Undecided (a side along the pixel grid, one rounding of R + B all
		// along): a fill above the top moves G's edges outwards only (its
		// clip cuts the bright half of their response), by up to a tenth of
		// a pixel. So where G's edges lie inwards of R + B's (less G's own
		// rounding) and within R + B's rounding of them, G errs less than
		// R + B whatever the level, and exactly nothing at the top.
		if (undecided[side] && !retry && kind == LocatorKind::Channels)
		{
			const auto g_edges = locateAll(restored);
			double sum = 0;
			int count = 0;
			for (size_t j = 0; j < edges.size(); ++j)
				if (g_edges[j] && edges[j])
				{
					sum += *g_edges[j] - *edges[j];
					++count;
				}
			const double rounding = channel_level[side]->rbRoundingPx();
			const double inwards = count > 0 ? sum / count : -1;
			channels_agree[side] = count >= 10 && inwards >= -kGRoundingPx && inwards <= rounding;
		}
		// All of the fill clipped: restore it from a model of the edge that
		// knows the clip, then read the edges again as on an unsaturated side.
		out.fill_clipped[side] = all_clipped || (!at_top && band.count() >= kMinFillSamples &&
												 band.fraction() >= kAllClippedFraction);
		if (all_clipped)
		{
			ClippedSideProfiles clip_side;
			clip_side.image = &bgr;
			clip_side.rows = prof.along == 1;
			clip_side.n = n;
			clip_side.inward = prof.inward;
			clip_side.along = prof.pos;
			for (const int c0 : prof.origin) clip_side.base.push_back(c0 - prof.inward * prof.half);
			if (imputeClippedSide(
					clip_side, edges, prof.frame_px, prof.fill_px, sensorNoise().value_or(0),
					prof.g))
				edges = locateAll(restored);
			// Refused (a JPEG's chroma, a sharp edge) where part of the fill
			// is unclipped: the fill's own model still restores its noise.
			else if (above_clip)
			{
				imputeFillLevel(prof.g, n, *level);
				edges = locateAll(restored);
			}
		}
		// A thin frame read in G by the peak: kept for its print model,
		// once all four lines give the frame's width.
		thin[side].reset();
		if (models.thin_frame && !all_clipped && kind == LocatorKind::Peak && !props.saturated)
			thin[side] = ThinSide{prof.g, edges, n, prof.inward, prof.across};
		// G read as it is (nothing imputed): on a noise-free sharp side, the
		// levels' rounding is one for all its edges, and G so corrected is
		// exact. Elsewhere the policy's channel: luma where it asks for it
		// and G is whole (a clip's restorations are of G).
		const bool rounded =
			models.level_rounding && !clips && !all_clipped &&
			correctLevelRounding(prof.g, n, prof.pos, prof.origin, prof.half, prof.inward, edges);
		out.channel[side] = EdgeChannel::Green;
		if (!rounded && !clips && choice.channel == EdgeChannel::Luma)
		{
			SideProfiles luma = prof;
			readLumaProfiles(bgr, luma);
			const auto luma_edges = locateEdges(luma, *makeLocator(choice, min_rise, p, models));
			// Luma where its edges are the sharper and its points make a
			// line (a dim, defocused side can be sharper in luma and still
			// too noisy for the fit's limits).
			if (lumaIsSharper(prof, edges, luma, luma_edges))
				if (auto f = fitLine(edgePoints(luma, luma_edges, cam), p))
				{
					out.sides[side] = std::move(*f);
					out.channel[side] = EdgeChannel::Luma;
					return true;
				}
		}
		// G is the reference read: the grey-level allowance of the fit's
		// limit is its own (luma above is taken only where it fits within
		// the pixel limit).
		auto f = fitLine(
			edgePoints(prof, edges, cam), p, EdgeResponse{edgeSlope(prof, edges), prof.across});
		if (!f) return false;
		out.sides[side] = std::move(*f);
		return true;
	};
	for (int side = 0; side < 4; ++side)
		if (!refineSide(side, false)) return std::nullopt;
	// A side along the pixel grid, noise-free, has one sample phase: its
	// own channel level cannot tell a fill at the top from one above it.
	// The fill is one sheet under one light: where another side is at the
	// top, so is this one if its own estimate agrees; so is one whose G and
	// R + B edges agree.
	const bool some_at_top = std::any_of(
		channel_level.begin(), channel_level.end(), [](const auto& c) { return c && c->atTop(); });
	for (int side = 0; side < 4; ++side)
		if (undecided[side] && (some_at_top || channels_agree[side]) && !refineSide(side, true))
			return std::nullopt;
	if (std::any_of(thin.begin(), thin.end(), [](const auto& t) { return t.has_value(); }))
		applyThinFrameModel(out, thin, cam, frame_ratio);
	if (!cornersFromSides(out, cam)) return std::nullopt;
	// The refinement must stay near the coarse corner.
	for (int k = 0; k < 4; ++k)
		if ((out.corners_raw[k] - coarse[k]).norm() > 3.0 + p.search_px) return std::nullopt;
	return out;
}

std::optional<Eigen::Vector2d> cornerOfSides(const std::array<LineFit, 4>& sides, int k)
{
	// Corner k = side k-1 x side k (TL = left x top, ...).
	const LineFit& l1 = sides[(k + 3) % 4];
	const LineFit& l2 = sides[k];
	const Eigen::Vector3d h = Eigen::Vector3d(l1.normal.x(), l1.normal.y(), l1.c)
								  .cross(Eigen::Vector3d(l2.normal.x(), l2.normal.y(), l2.c));
	if (std::abs(h.z()) < 1e-9) return std::nullopt;
	return Eigen::Vector2d(h.head<2>() / h.z());
}

bool cornersFromSides(RefinedQuad& q, const CameraModel& cam)
{
	for (int k = 0; k < 4; ++k)
	{
		const auto corner = cornerOfSides(q.sides, k);
		if (!corner) return false;
		q.corners_ideal[k] = *corner;
		if (cam.hasDistortion())
		{
			const Eigen::Vector2d xn(
				(q.corners_ideal[k].x() - cam.cx()) / cam.fx(),
				(q.corners_ideal[k].y() - cam.cy()) / cam.fy());
			q.corners_raw[k] = cam.distortNormalized(xn);
		}
		else
			q.corners_raw[k] = q.corners_ideal[k];
	}
	return true;
}

}  // namespace codemark::detect
