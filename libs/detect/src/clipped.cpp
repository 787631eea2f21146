// Stage 7, sides whose green fill clips: the clipped samples restored from
// an edge model fitted with the clip.
//
// Written by hand: OpenCV has no censored (Tobit) fit, and a general
// least-squares solver (cv::LMSolver) cannot take the one-sided terms of
// the clipped samples or the bounds on the levels.
#include "stages.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace codemark::detect
{
namespace
{
constexpr double kSqrt2 = 1.4142135623730951;
constexpr double kInvSqrt2Pi = 0.3989422804014327;
constexpr int kChannels = 3;
constexpr int kG = 1;  // BGR
// Parameters of a side: its inner edge's across coordinate as a quadratic
// in the normalised along coordinate (a lens bends a line a little), the
// blur, the black frame's width (linear along the side: perspective), and
// the levels outside the frame and in it (the black frame and the white
// margin are neutral, black ink and white paper equal in B, G and R after
// white balance, which a thin frame needs: its own samples barely reach the
// black level), and per channel the fill's (which is not neutral); last,
// the light's relative slope along the side (every level times 1 + kGain
// tau: a light gradient, under which a top edge clips at one end only; a
// slope across the side trades off with the outer edge's levels on thin
// frames and is left out).
constexpr int kE0 = 0, kSigma = 3, kW0 = 4, kW1 = 5, kOutside = 6, kFrame = 7, kFill = 8;
constexpr int kGain = kFill + kChannels;
constexpr int kParams = kGain + 1;
using Vec = Eigen::Matrix<double, kParams, 1>;
using Mat = Eigen::Matrix<double, kParams, kParams>;
int fillOf(int c) { return kFill + c; }

/** Below this frame width [px] the frame's samples never reach its black
 * level, and the levels, the blur and the two edges trade off: no model. */
constexpr double kMinFramePx = 3.5;
/** Frames narrower than this [px] have their outer edge in the model: its
 * blur reaches the inner edge's samples (and, at gains above 1.1, the white
 * margin clips too). */
constexpr double kOuterModelPx = 7;
/** The other edges' blur reaches about this far [px]. */
constexpr double kClearPx = 2.2;
/** A sharp edge (little blur beyond the pixel) has one mixed sample per
 * profile: once it clips, where the edge lies within that pixel is
 * ambiguous and the model is not used. */
constexpr double kMinSigmaPx = 0.4;
/** Largest blur [px] and level [grey levels, before the clip] accepted. */
constexpr double kMaxSigmaPx = 2.0;
constexpr double kMaxLevel = 4 * 255;
/** The fit's residual noise may exceed the frame's by this factor plus
 * this floor [grey levels] (the model's own shape error, quantisation). */
constexpr double kMisfitFactor = 1.5;
constexpr double kMisfitFloor = 1.5;
/** Largest standard deviation of the side's fitted offset accepted [px]. */
constexpr double kMaxOffsetSdPx = 0.05;
/** Smallest contrast of R + B between the frame and the fill that gives G's
 * fill level from the channels' ratio [grey levels], at least this many
 * pixels' worth of step, and the largest predicted G of those pixels. */
constexpr double kMinRbStep = 12;
constexpr double kMinRatioSamples = 20;
constexpr double kUnclippedG = 240;
/** Clipped samples of a band whose tail terms fitFillLevel() evaluates. */
constexpr size_t kMaxClippedTerms = 160;
/** imputeClippedSide()'s fit stops when a step moves the edge and the
 * blur by less than this [px]. */
constexpr double kSettledPx = 1e-3;
/** Profiles of a side used by the side's fit, evenly spread. */
constexpr size_t kMaxProfiles = 20;

double Phi(double u) { return 0.5 * std::erfc(-u / kSqrt2); }
double phi(double u) { return kInvSqrt2Pi * std::exp(-0.5 * u * u); }

/** normalCdfPdf()'s table: Phi, phi and phi' = -z phi every 1/32 over
 * [-8.5, 8.5], built when the library loads (a function-local static
 * would test its guard at every call of that inner-loop function). */
constexpr double kCdfEnd = 8.5, kCdfPerUnit = 32, kCdfH = 1 / kCdfPerUnit;
constexpr int kCdfNodes = static_cast<int>(2 * kCdfEnd * kCdfPerUnit) + 1;
struct CdfNode
{
	double P, f, df;
};
const std::array<CdfNode, kCdfNodes> kCdfTable = []
{
	std::array<CdfNode, kCdfNodes> t{};
	for (int k = 0; k < kCdfNodes; ++k)
	{
		const double u = -kCdfEnd + k * kCdfH;
		t[k] = {Phi(u), phi(u), -u * phi(u)};
	}
	return t;
}();

/** The standard normal's CDF \a P and density \a f at \a z by cubic
 * Hermite interpolation in kCdfTable: |error| < 5e-9 in either, with no
 * exponential or division. Written by hand: std::erfc beside std::exp cost
 * several times as much, and pixelSteps() is where the thin-frame and
 * step-peak fits spend most of their time. Beyond |z| = 8.5 the tails are
 * 0 and 1 to 1e-17. */
inline void normalCdfPdf(double z, double& P, double& f)
{
	if (!(std::abs(z) < kCdfEnd))
	{
		P = z > 0 ? 1.0 : 0.0;
		f = 0;
		return;
	}
	const double u = (z + kCdfEnd) * kCdfPerUnit;
	const int k = std::min(static_cast<int>(u), kCdfNodes - 2);
	const double s = u - k, r = 1 - s;
	const double h00 = (1 + 2 * s) * r * r, h01 = s * s * (3 - 2 * s);
	const double h10 = kCdfH * s * r * r, h11 = -kCdfH * s * s * r;
	const CdfNode &a = kCdfTable[k], &b = kCdfTable[k + 1];
	P = h00 * a.P + h01 * b.P + h10 * a.f + h11 * b.f;
	f = h00 * a.f + h01 * b.f + h10 * a.df + h11 * b.df;
}
/** normalCdfPdf() where the CDF is needed to a relative accuracy (its
 * logarithm, a ratio to it): the table's absolute error (< 5e-9) is a
 * relative one under 2e-5 above z = -3.5; further out, erfc's. */
inline void normalCdfPdfRelative(double z, double& P, double& f)
{
	if (z > -3.5)
		normalCdfPdf(z, P, f);
	else
	{
		P = Phi(z);
		f = phi(z);
	}
}

/** -log Phi(z) and its first two derivatives with respect to z (through
 * the inverse Mills ratio), stable far in the lower tail. */
void censoredTerm(double z, double& nll, double& d1, double& d2)
{
	if (z < -30)
	{
		// Phi(z) ~ phi(z) / -z.
		nll = 0.5 * z * z + std::log(-z) + 0.5 * std::log(2 * M_PI);
		d1 = z;
		d2 = 1;
		return;
	}
	double P, f;
	normalCdfPdfRelative(z, P, f);
	const double lambda = f / P;
	nll = -std::log(P);
	d1 = -lambda;
	d2 = lambda * (z + lambda);
}

/** Negative log-likelihood of one sample \a v (0..255) given the model
 * value \a m and the pixel noise \a sn, and its first (\a a) and
 * Gauss-Newton second (\a h) derivatives with respect to m. A sample at 255
 * (0) says only that the sensor's input was at least 254.5 (at most 0.5): a
 * censored (Tobit) term. Residuals beyond kHuber noise sigmas count
 * linearly (a spot on the sheet, another edge). */
double sampleTerm(int v, double m, double sn, double& a, double& h)
{
	constexpr double kHuber = 3;
	double nll = 0, d1 = 0, d2 = 0;
	if (v >= 255 || v <= 0)
	{
		const double sign = v >= 255 ? 1 : -1;
		censoredTerm(sign * (m - (v >= 255 ? 254.5 : 0.5)) / sn, nll, d1, d2);
		a = sign * d1 / sn;
		h = d2 / (sn * sn);
		return nll;
	}
	const double r = (m - v) / sn;
	const double w = std::abs(r) <= kHuber ? 1.0 : kHuber / std::abs(r);
	a = w * r / sn;
	h = w / (sn * sn);
	return w == 1.0 ? 0.5 * r * r : kHuber * (std::abs(r) - 0.5 * kHuber);
}

struct Window
{
	int j;	//!< profile
	int i0, i1;	 //!< sample range, inclusive
	double tau;	 //!< normalised along coordinate
};

/** The model of one side's profiles. */
struct SideModel
{
	const ClippedSideProfiles& s;
	bool outer;	 //!< the frame's outer edge is modelled
	double tmid = 0, thalf = 1;

	double tau(int j) const { return (s.along[j] - tmid) / thalf; }
	/** Profile index of the across coordinate c in profile j, and back. */
	double indexOf(int j, double c) const { return s.inward * (c - s.base[j]); }
	double acrossOf(int j, double e) const { return s.base[j] + s.inward * e; }
	static double edgeAt(const Vec& p, double t) { return p[0] + p[1] * t + p[2] * t * t; }
	static double widthAt(const Vec& p, double t) { return p[kW0] + p[kW1] * t; }
	static double lightAt(const Vec& p, double t) { return 1 + p[kGain] * t; }
	int sample(int j, int i, int c) const { return s.sample(j, i, c); }

	/** Model value of channel c at sample i of a profile whose inner edge is
	 * at index e and whose frame is w wide; with the Jacobian row (the inner
	 * edge's index position in J[kE0]) when J is given. */
	double value(const Vec& p, int c, int i, double e, double w, Vec* J) const
	{
		const double sigma = p[kSigma];
		return value(
			p, c, pixelStep(i - e, sigma),
			outer ? pixelStep(i - (e - w), sigma) : PixelStep{1, 0, 0}, J);
	}
	/** The same from the inner and outer edges' steps at the sample (the
	 * same in every channel). */
	static double value(const Vec& p, int c, const PixelStep& in, const PixelStep& out, Vec* J)
	{
		const double W = p[kOutside], lo = p[kFrame], hi = p[fillOf(c)];
		if (J)
		{
			J->setZero();
			(*J)[kE0] = -(hi - lo) * in.d_x - (lo - W) * out.d_x;
			(*J)[kSigma] = (lo - W) * out.d_sigma + (hi - lo) * in.d_sigma;
			(*J)[kW0] = (lo - W) * out.d_x;
			(*J)[kOutside] = 1 - out.value;
			(*J)[kFrame] = out.value - in.value;
			(*J)[fillOf(c)] = in.value;
		}
		return W + (lo - W) * out.value + (hi - lo) * in.value;
	}
};

/** z with Phi(z) = q, 0 < q < 1 (Newton from the logistic guess). */
double inverseNormalCdf(double q)
{
	double z = std::log(q / (1 - q)) / 1.7;
	for (int it = 0; it < 8; ++it) z -= (Phi(z) - q) / std::max(1e-300, phi(z));
	return z;
}

/** A level constant over the band, from where the clip cuts its samples'
 * distribution and their unclipped median (a censored normal; robust to the
 * few samples of the neighbouring edges' blur, or a JPEG's ringing, that
 * the band holds). */
std::optional<FillLevel> constantFill(const ClippedFill& f, int m, int i0, int i1)
{
	if (f.unclipped < 10 || f.clipped < 10) return std::nullopt;
	// 254.5 is the (1 - p_c) quantile of a censored normal, the unclipped
	// median the (1 - p_c) / 2 one.
	const double p_c = f.fraction();
	int median = 0;
	for (int seen = 0; median < 255; ++median)
		if ((seen += f.histogram[median]) * 2 > f.unclipped) break;
	const double z_c = inverseNormalCdf(1 - p_c), z_m = inverseNormalCdf(0.5 * (1 - p_c));
	const double sigma = (254.5 - median) / (z_c - z_m);
	if (!(sigma > 0.1) || !std::isfinite(sigma)) return std::nullopt;
	FillLevel l;
	l.beta = Eigen::Vector3d(254.5 - sigma * z_c, 0, 0);
	l.sigma = sigma;
	l.profiles = m;
	l.i0 = i0;
	l.i1 = i1;
	return l;
}

/** The clipped fraction of each quarter of the side and of each half across
 * it agrees with the band's within 3 binomial sigmas: a level flat enough
 * for constantFill(), decided without the regression (about 0.5 ms a side;
 * a fill at about the top without a light gradient, the common case, does
 * not need it). */
bool clippedEvenly(const std::vector<int>& g_profiles, int n, int m, int i0, int i1, double p)
{
	std::array<int, 6> n_part{}, c_part{};	// 4 quarters along, 2 halves across
	const int i_mid = (i0 + i1) / 2;
	for (int j = 0; j < m; ++j)
		for (int i = i0; i <= i1; ++i)
		{
			const bool cl = g_profiles[j * n + i] >= 255;
			const int q = std::min(3, 4 * j / m), h = 4 + (i > i_mid);
			++n_part[q];
			++n_part[h];
			c_part[q] += cl;
			c_part[h] += cl;
		}
	for (int k = 0; k < 6; ++k)
		if (n_part[k] > 0 && std::abs(double(c_part[k]) / n_part[k] - p) >
								 3 * std::sqrt(std::max(1e-4, p * (1 - p)) / n_part[k]))
			return false;
	return true;
}
}  // namespace

namespace
{
/** The pixel between the boundaries z_m and z_p (in sigmas, with Phi and
 * phi there): the integral of Phi is z Phi(z) + phi(z). */
PixelStep stepBetween(
	double sigma, double zm, double Pm, double fm, double zp, double Pp, double fp)
{
	return {sigma * (zp * Pp + fp - zm * Pm - fm), Pp - Pm, fp - fm};
}
}  // namespace

void pixelSteps(double x0, double sigma, int count, PixelStep* out)
{
	// Sample i covers [x0 + i - 1/2, x0 + i + 1/2]: neighbours share a
	// boundary, so count + 1 evaluations of Phi and phi serve all.
	double zm = (x0 - 0.5) / sigma, Pm, fm;
	normalCdfPdf(zm, Pm, fm);
	for (int i = 0; i < count; ++i)
	{
		const double zp = (x0 + i + 0.5) / sigma;
		double Pp, fp;
		normalCdfPdf(zp, Pp, fp);
		out[i] = stepBetween(sigma, zm, Pm, fm, zp, Pp, fp);
		zm = zp;
		Pm = Pp;
		fm = fp;
	}
}

void pixelStepsAt(const double* x, int count, double sigma, PixelStep* out)
{
	const double inv_sigma = 1 / sigma;
	for (int i = 0; i < count; ++i)
	{
		const double zm = (x[i] - 0.5) * inv_sigma, zp = (x[i] + 0.5) * inv_sigma;
		double Pm, fm, Pp, fp;
		normalCdfPdf(zm, Pm, fm);
		normalCdfPdf(zp, Pp, fp);
		out[i] = stepBetween(sigma, zm, Pm, fm, zp, Pp, fp);
	}
}

PixelStep pixelStep(double x, double sigma)
{
	PixelStep s;
	pixelSteps(x, sigma, 1, &s);
	return s;
}

int steepestRise(const int* v, int lo, int hi)
{
	int k = lo;
	for (int i = lo + 1; i <= hi; ++i)
		if (v[i + 1] - v[i - 1] > v[k + 1] - v[k - 1]) k = i;
	return k;
}

ClippedFill clippedFill(const std::vector<int>& g_profiles, int n, int i0, int i1)
{
	ClippedFill f;
	i0 = std::max(0, i0);
	i1 = std::min(n - 1, i1);
	if (i1 < i0) return f;
	for (size_t k = 0; k + n <= g_profiles.size(); k += n)
		for (int i = i0; i <= i1; ++i)
		{
			const int v = g_profiles[k + i];
			if (v >= 255)
				++f.clipped;
			else
			{
				++f.unclipped;
				++f.histogram[std::max(0, v)];
			}
		}
	return f;
}

Eigen::Vector3d FillLevel::design(int j, int i) const
{
	const double s = profiles > 1 ? 2.0 * j / (profiles - 1) - 1 : 0;
	const double t = i1 > i0 ? 2.0 * (std::clamp(i, i0, i1) - i0) / (i1 - i0) - 1 : 0;
	return {1, s, t};
}

bool FillLevel::aboveClip() const
{
	double top = -1e300;
	for (const int j : {0, profiles - 1})
		for (const int i : {i0, i1}) top = std::max(top, design(j, i).dot(beta));
	return top > 254.5 + std::max(sigma, 0.02 * 254.5);
}

std::optional<FillLevel> fitFillLevel(
	const std::vector<int>& g_profiles, int n, int i0, int i1, const ClippedFill& fill)
{
	i0 = std::max(0, i0);
	i1 = std::min(n - 1, i1);
	const int m = static_cast<int>(g_profiles.size()) / n;
	if (i1 < i0 || m < 2) return std::nullopt;
	if (clippedEvenly(g_profiles, n, m, i0, i1, fill.fraction()))
		return constantFill(fill, m, i0, i1);
	// Censored (Tobit) regression of the band's samples on (1, along,
	// across), both normalised to [-1, 1]: a light gradient makes the
	// fill's level vary along a side (a top edge clipped at one end only)
	// and across it, where one level for the whole band imputed 0.03-0.15
	// px errors (gradient 0.3 across the image within 2 m). Olsen's
	// parametrisation (gamma = beta / sigma, tau = 1 / sigma) makes the
	// log-likelihood concave: Newton with step halving.
	constexpr double c = 254.5;
	FillLevel level;
	level.profiles = m;
	level.i0 = i0;
	level.i1 = i1;
	// The unclipped samples enter the likelihood through their sums alone
	// (A, bv, svv); the clipped ones each through the normal's tail at their
	// own design point.
	Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
	Eigen::Vector3d bv = Eigen::Vector3d::Zero();
	double svv = 0;
	std::vector<Eigen::Vector3d> x_clipped;
	int unclipped = 0;
	for (int j = 0; j < m; ++j)
		for (int i = i0; i <= i1; ++i)
		{
			const int v = g_profiles[j * n + i];
			const Eigen::Vector3d x = level.design(j, i);
			if (v >= 255)
			{
				x_clipped.push_back(x);
				continue;
			}
			++unclipped;
			A += x * x.transpose();
			bv += v * x;
			svv += double(v) * v;
		}
	if (unclipped < 10 || x_clipped.size() < 10) return std::nullopt;
	// Each clipped sample costs a tail probability per evaluation: at most
	// kMaxClippedTerms of them, evenly spread over the band, stand for all
	// (weighted). The level's error grows by at most sqrt(n / kept) in the
	// tail's share of the information, hundredths of a grey level, a
	// thousandth of a pixel on the imputed edges.
	double w_clipped = 1;
	if (x_clipped.size() > kMaxClippedTerms)
	{
		std::vector<Eigen::Vector3d> kept(kMaxClippedTerms);
		for (size_t k = 0; k < kMaxClippedTerms; ++k)
			kept[k] = x_clipped[k * x_clipped.size() / kMaxClippedTerms];
		w_clipped = double(x_clipped.size()) / kMaxClippedTerms;
		x_clipped = std::move(kept);
	}
	// Start: least squares on the unclipped samples.
	Eigen::Vector3d beta = (A + 1e-9 * Eigen::Matrix3d::Identity()).ldlt().solve(bv);
	// Its residual sum of squares from the sums: sum (v - x.beta)^2.
	const double ss = std::max(0.0, svv - 2 * beta.dot(bv) + beta.dot(A * beta));
	const double sigma0 = std::max(0.5, std::sqrt(ss / unclipped));
	Eigen::Vector4d th;	 // gamma (3), tau
	th << beta / sigma0, 1 / sigma0;
	const auto logLik = [&](const Eigen::Vector4d& t, Eigen::Vector4d* g, Eigen::Matrix4d* H)
	{
		const Eigen::Vector3d gamma = t.head<3>();
		const double tau = t[3];
		// Unclipped: r = tau v - x.gamma, log-likelihood log(tau) - r^2 / 2
		// each; dr/d(gamma, tau) = (-x, v).
		const Eigen::Vector3d A_gamma = A * gamma;
		const double bv_gamma = bv.dot(gamma);
		double ll = unclipped * std::log(tau) -
					0.5 * (tau * tau * svv - 2 * tau * bv_gamma + gamma.dot(A_gamma));
		if (g)
		{
			g->head<3>() = tau * bv - A_gamma;
			(*g)[3] = unclipped / tau - (tau * svv - bv_gamma);
		}
		if (H)
		{
			H->topLeftCorner<3, 3>() = -A;
			H->topRightCorner<3, 1>() = bv;
			H->bottomLeftCorner<1, 3>() = bv.transpose();
			(*H)(3, 3) = -svv - unclipped / (tau * tau);
		}
		for (const Eigen::Vector3d& x : x_clipped)
		{
			// log(1 - Phi(z)) = log Phi(-z): censoredTerm at -z.
			const double z = tau * c - x.dot(gamma);
			double nll, d1, d2;
			censoredTerm(-z, nll, d1, d2);
			ll -= w_clipped * nll;
			Eigen::Vector4d dz;	 // dz/d(gamma, tau)
			dz << -x, c;
			// d/dz (-nll(-z)) = d1, d2/dz2 = -d2.
			if (g) *g += (w_clipped * d1) * dz;
			if (H) *H -= (w_clipped * d2) * dz * dz.transpose();
		}
		return ll;
	};
	// Newton with step halving; each candidate's derivatives come with its
	// likelihood (a full step is nearly always taken: one pass a step).
	Eigen::Vector4d g;
	Eigen::Matrix4d H;
	double ll = logLik(th, &g, &H);
	bool converged = false;
	for (int it = 0; it < 30 && !converged; ++it)
	{
		const Eigen::Vector4d step = (-H).ldlt().solve(g);
		if (!step.allFinite()) return std::nullopt;
		double scale = 1;
		for (; scale > 1e-4; scale *= 0.5)
		{
			const Eigen::Vector4d cand = th + scale * step;
			if (!(cand[3] > 0)) continue;
			Eigen::Vector4d gc;
			Eigen::Matrix4d Hc;
			const double lc = logLik(cand, &gc, &Hc);
			if (lc >= ll)
			{
				converged = lc - ll < 1e-9 * std::max(1.0, std::abs(ll));
				th = cand;
				ll = lc;
				g = gc;
				H = Hc;
				break;
			}
		}
		if (scale <= 1e-4) converged = true;  // no ascent left: at the maximum
	}
	level.sigma = 1 / th[3];
	level.beta = th.head<3>() * level.sigma;
	if (!(level.sigma > 0.1 && level.sigma < 50) || !level.beta.allFinite()) return std::nullopt;
	// A level constant to within the noise after all: the constant model's
	// robust estimate (a regression's least squares would take the band's
	// few samples of neighbouring blur, or a JPEG's ringing, at face value).
	if (std::abs(level.beta[1]) + std::abs(level.beta[2]) < level.sigma)
		return constantFill(fill, m, i0, i1);
	return level;
}

void imputeFillLevel(std::vector<int>& g_profiles, int n, const FillLevel& level)
{
	// Every sample at the top gets E[v | v >= 254.5] of its place's fill
	// (the white margin, the frame and the code cells lie far below it when
	// the fill is about at the top).
	constexpr double c = 254.5;
	const int m = static_cast<int>(g_profiles.size()) / n;
	const auto expected = [&](double mu)
	{
		const double z = (c - mu) / level.sigma;
		double tail, f;
		normalCdfPdfRelative(-z, tail, f);
		const double e =
			tail > 1e-12 ? mu + level.sigma * f / tail : c + level.sigma / std::max(1.0, z);
		return static_cast<int>(std::lround(std::max(c, e)));
	};
	// A flat level (the common case) has one expectation for every sample.
	const bool flat = level.beta[1] == 0 && level.beta[2] == 0;
	const int flat_value = flat ? expected(level.beta[0]) : 0;
	for (int j = 0; j < m; ++j)
		for (int i = 0; i < n; ++i)
		{
			int& v = g_profiles[j * n + i];
			if (v < 255) continue;
			v = flat ? flat_value : expected(level.design(j, i).dot(level.beta));
		}
}

bool ChannelFillLevel::consistentWithTop() const
{
	return !std::isfinite(se) || std::abs(level - 254.5) <= std::max(2 * se, 0.005 * 254.5);
}

bool ChannelFillLevel::atTop() const { return se <= 0.01 * 254.5 && consistentWithTop(); }

std::optional<ChannelFillLevel> fillLevelFromChannels(
	const std::vector<int>& g_profiles, const std::vector<int>& rb_profiles, int n, int lo, int hi,
	int i0, int i1)
{
	const int m = static_cast<int>(g_profiles.size()) / n;
	lo = std::max(lo, 3);
	hi = std::min(hi, n - 4);
	i0 = std::max(0, i0);
	i1 = std::min(n - 1, i1);
	if (m < 2 || lo > hi || i1 < i0 || rb_profiles.size() != g_profiles.size()) return std::nullopt;
	// Each profile's steepest G rise; the frame's levels two samples
	// outwards of it, the fill's B + R over the band (medians: robust to a
	// neighbouring edge's blur).
	std::vector<int> peak(m);
	std::vector<double> g_frame, rb_frame, rb_fill;
	for (int j = 0; j < m; ++j)
	{
		const int* g = g_profiles.data() + size_t(j) * n;
		const int* rb = rb_profiles.data() + size_t(j) * n;
		const int k = steepestRise(g, lo, hi);
		peak[j] = k;
		g_frame.push_back(g[k - 2]);
		rb_frame.push_back(-rb[k - 2]);
		for (int i = i0; i <= i1; ++i) rb_fill.push_back(-rb[i]);
	}
	const double G0 = medianOf(g_frame), RB0 = medianOf(rb_frame), RB1 = medianOf(rb_fill);
	constexpr double kMinStep = 12;
	const double step = RB0 - RB1;
	if (step < kMinStep) return std::nullopt;
	std::vector<std::pair<double, double>> pts;	 // (f, G - G_frame)
	std::map<int, double> f_of_level;  // sum of f per B + R level
	for (int j = 0; j < m; ++j)
	{
		const int* g = g_profiles.data() + size_t(j) * n;
		const int* rb = rb_profiles.data() + size_t(j) * n;
		for (int i = peak[j] - 1; i <= peak[j] + 2; ++i)
		{
			const double f = (RB0 + rb[i]) / step;
			if (f < 0.05 || f > 0.95 || g[i] > 250) continue;
			pts.emplace_back(f, g[i] - G0);
			f_of_level[-rb[i]] += f;
		}
	}
	// An edge within a few hundredths of a pixel boundary all along has no
	// mixed pixels: it says nothing of the level.
	if (pts.size() < 10)
		return ChannelFillLevel{
			std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
			step};
	// Least squares through the origin. Noise-free, the transition pixels
	// of a side aligned with the pixel grid share one f, whose rounding
	// (B and R rounded alike: up to 1 level of their sum) no residual
	// shows: pixels of one B + R level share their rounding error, which is
	// independent between levels.
	double sff = 0, sfg = 0, coherent = 0;
	for (const auto& [f, dg] : pts)
	{
		sff += f * f;
		sfg += f * dg;
	}
	for (const auto& [rb_level, f_sum] : f_of_level) coherent += f_sum * f_sum;
	const double slope = sfg / sff;
	double ss = 0;
	for (const auto& [f, dg] : pts) ss += (dg - slope * f) * (dg - slope * f);
	const double se_noise = std::sqrt(ss / double(pts.size() - 1) / sff);
	const double se_rounding =
		std::abs(slope) * (1 / std::sqrt(3.0)) / step * std::sqrt(coherent) / sff;
	ChannelFillLevel out;
	out.level = G0 + slope;
	out.se = std::hypot(se_noise, se_rounding);
	out.rb_step = step;
	return out;
}

bool imputeClippedSide(
	const ClippedSideProfiles& s, const std::vector<std::optional<double>>& initial,
	double frame_px, double fill_px, double noise, std::vector<int>& g_profiles)
{
	const int np = static_cast<int>(s.along.size());
	if (np == 0 || static_cast<int>(initial.size()) != np || s.n < 5 ||
		g_profiles.size() != size_t(np) * s.n || frame_px < kMinFramePx)
		return false;
	// All of the fill clips: G's fill level would come from the shape of
	// the few unclipped samples of its edge, which a model's shape error
	// (about 1% of the step) moves by several percent. B and R (unclipped)
	// join the fit, and give that level through their ratio below.
	SideModel M{s, frame_px < kOuterModelPx};
	const auto [tmin, tmax] = std::minmax_element(s.along.begin(), s.along.end());
	M.tmid = 0.5 * (*tmin + *tmax);
	M.thalf = std::max(1.0, 0.5 * (*tmax - *tmin));

	// The initial edge as a robust quadratic in tau.
	std::vector<int> use;
	for (int j = 0; j < np; ++j)
		if (initial[j]) use.push_back(j);
	if (use.size() < 8) return false;
	Vec p = Vec::Zero();
	for (int it = 0; it < 3; ++it)
	{
		Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
		Eigen::Vector3d b = Eigen::Vector3d::Zero();
		for (const int j : use)
		{
			const double t = M.tau(j);
			const Eigen::Vector3d x(1, t, t * t);
			A += x * x.transpose();
			b += x * M.acrossOf(j, *initial[j]);
		}
		p.head<3>() = A.ldlt().solve(b);
		std::vector<int> kept;
		for (const int j : use)
			if (std::abs(M.acrossOf(j, *initial[j]) - SideModel::edgeAt(p, M.tau(j))) < 1.0)
				kept.push_back(j);
		if (kept.size() < 8) return false;
		use.swap(kept);
	}
	const double e0_initial = p[kE0];
	p[kW0] = frame_px;

	// The samples: from just outside the frame (outer edge modelled) or a
	// few into it (clear of its outer edge's blur), to a few into the fill
	// (clear of the code board).
	const auto windowOf = [&](int j, double e, double w) -> std::optional<Window>
	{
		const int fe = static_cast<int>(std::floor(e)), ce = static_cast<int>(std::ceil(e));
		const int i0 =
			M.outer ? static_cast<int>(std::ceil(e - w + 0.5))
					: std::clamp(
						  static_cast<int>(std::ceil(e - (frame_px - kClearPx))), fe - 4, fe - 1);
		const int i1 =
			std::clamp(static_cast<int>(std::floor(e + fill_px - kClearPx)), ce + 1, ce + 4);
		if (i0 < 0 || i1 >= s.n) return std::nullopt;
		return Window{j, i0, i1, M.tau(j)};
	};
	std::vector<Window> windows;
	const size_t stride = (use.size() + kMaxProfiles - 1) / kMaxProfiles;
	for (size_t k = 0; k < use.size(); k += stride)
	{
		const int j = use[k];
		if (const auto w = windowOf(j, M.indexOf(j, SideModel::edgeAt(p, M.tau(j))), frame_px))
			windows.push_back(*w);
	}
	if (windows.size() < 6) return false;

	// Initial levels: outside from the window's first sample, the frame's
	// from its middle (outer edge modelled) or first sample, the fill's
	// from the window's last; a clipped fill lies somewhere above the top.
	for (int c = 0; c < kChannels; ++c)
	{
		double W = 0, lo = 0, hi = 0;
		for (const Window& w : windows)
		{
			const double e = M.indexOf(w.j, SideModel::edgeAt(p, w.tau));
			W += M.sample(w.j, w.i0, c);
			lo +=
				M.outer
					? M.sample(
						  w.j, std::max(w.i0, static_cast<int>(std::lround(e - 0.5 * frame_px))), c)
					: M.sample(w.j, w.i0, c);
			hi += M.sample(w.j, w.i1, c);
		}
		const double k = 1.0 / windows.size();
		p[kOutside] += W * k / kChannels;
		p[kFrame] += lo * k / kChannels;
		p[fillOf(c)] = hi * k >= 254 ? 300 : hi * k;
	}
	p[kSigma] = 0.8;

	// Parameters the data cannot move: without the outer edge, its width
	// and the outside levels.
	std::vector<int> fixed;
	if (!M.outer) fixed = {kW0, kW1, kOutside};
	// The Gauss-Newton Hessian is the product of the stacked weighted
	// Jacobian rows, formed in one blocked rank-k update: a rank-1 update
	// per sample and channel costs several times more.
	int rows_max = 0;
	for (const Window& w : windows) rows_max += (w.i1 - w.i0 + 1) * kChannels;
	Eigen::Matrix<double, Eigen::Dynamic, kParams> rows(rows_max, kParams);
	// The side's negative log-likelihood, its gradient and Gauss-Newton
	// Hessian; sn the pixel noise; the sum of squares of the unclipped
	// residuals through ss, nss.
	const auto evaluate = [&](const Vec& q, double sn, Vec* g, Mat* H, double* ss, int* nss)
	{
		double nll = 0;
		if (g) g->setZero();
		if (H) H->setZero();
		int nrows = 0;
		Vec J;
		const double sigma = q[kSigma];
		for (const Window& w : windows)
		{
			const double e = M.indexOf(w.j, SideModel::edgeAt(q, w.tau));
			const double width = SideModel::widthAt(q, w.tau);
			for (int i = w.i0; i <= w.i1; ++i)
			{
				const PixelStep in = pixelStep(i - e, sigma);
				const PixelStep out =
					M.outer ? pixelStep(i - (e - width), sigma) : PixelStep{1, 0, 0};
				const double light = SideModel::lightAt(q, w.tau);
				for (int c = 0; c < kChannels; ++c)
				{
					const double m0 = SideModel::value(q, c, in, out, g ? &J : nullptr);
					const double m = light * m0;
					const int v = M.sample(w.j, i, c);
					double a = 0, h = 0;
					nll += sampleTerm(v, m, sn, a, h);
					if (ss && v > 0 && v < 255)
					{
						*ss += (m - v) * (m - v);
						++*nss;
					}
					if (!g) continue;
					// The edge's index moves with its across coordinate by
					// the inward sign, the coefficients by powers of tau.
					J *= light;
					J[kGain] = w.tau * m0;
					const double de = J[kE0] * s.inward;
					J[0] = de;
					J[1] = de * w.tau;
					J[2] = de * w.tau * w.tau;
					J[kW1] = J[kW0] * w.tau;
					*g += a * J;
					rows.row(nrows++) = std::sqrt(h) * J.transpose();  // h >= 0 (sampleTerm())
				}
			}
		}
		if (H)
		{
			H->selfadjointView<Eigen::Lower>().rankUpdate(rows.topRows(nrows).transpose());
			*H = H->selfadjointView<Eigen::Lower>();
		}
		return nll;
	};
	// Held parameters (fixed ones, levels at their bound of zero pushed
	// further down) leave the step: projected Levenberg-Marquardt.
	const auto hold = [&](const Vec& q, const Vec& g, Mat& A, Vec& gg)
	{
		gg = g;
		const auto freeze = [&](int k)
		{
			A.row(k).setZero();
			A.col(k).setZero();
			A(k, k) = 1;
			gg[k] = 0;
		};
		for (const int k : fixed) freeze(k);
		for (int k = kOutside; k < kGain; ++k)
			if (q[k] <= 0 && g[k] > 0) freeze(k);
	};
	const auto solve = [&](Vec q, double sn, int iterations)
	{
		double mu = 1e-3;
		Vec g, gg, g_c;
		Mat H, H_c;
		double nll = evaluate(q, sn, &g, &H, nullptr, nullptr);
		for (int it = 0; it < iterations && mu < 1e6; ++it)
		{
			Mat A = H;
			A.diagonal() += mu * H.diagonal().cwiseMax(1e-9);
			hold(q, g, A, gg);
			const Vec step = -A.ldlt().solve(gg);
			if (!step.allFinite()) break;
			Vec cand = q + step;
			cand[kSigma] = std::clamp(cand[kSigma], 0.2, 4.0);
			cand[kW0] = std::max(0.5, cand[kW0]);
			// Light is never negative: a fill at the sensor's floor (R and B
			// of a pure green) must not drift below it.
			for (int k = kOutside; k < kGain; ++k) cand[k] = std::max(0.0, cand[k]);
			cand[kGain] = std::clamp(cand[kGain], -0.5, 0.5);
			const double nll_c = evaluate(cand, sn, &g_c, &H_c, nullptr, nullptr);
			if (nll_c < nll)
			{
				// Done when the step taken (a clamped blur takes less than
				// its proposal) moves the edge and the blur by under
				// kSettledPx. The Huber weights make the iteration converge
				// linearly, at about 0.7 a step on an encoded camera's
				// edges: the edge then lies within about 2 kSettledPx of
				// the optimum, where a tighter test costs a dozen
				// iterations more.
				const Vec taken = cand - q;
				q = cand;
				nll = nll_c;
				g = g_c;
				H = H_c;
				mu = std::max(1e-7, mu * 0.3);
				if (std::abs(taken[kE0]) < kSettledPx && std::abs(taken[kSigma]) < kSettledPx)
					break;
			}
			else
				mu *= 10;
		}
		return q;
	};
	// Fit with a nominal noise, estimate the noise from the unclipped
	// residuals, and refine with it.
	constexpr double kNominalNoise = 2.0;
	p = solve(p, kNominalNoise, 20);
	double ss = 0;
	int nss = 0;
	evaluate(p, kNominalNoise, nullptr, nullptr, &ss, &nss);
	const double sn = nss > 10 ? std::clamp(std::sqrt(ss / nss), 0.5, 20.0) : kNominalNoise;
	// The fit must explain the samples to about the sensor's noise where
	// the caller could measure it (0: not measured): a JPEG's subsampled
	// chroma, a gamma curve or a spot on the sheet make the samples disagree
	// with the model, which is then not used (decided here, before the
	// refinements below, which do not change sn).
	if (noise > 0 && sn > kMisfitFactor * std::max(0.5, noise) + kMisfitFloor) return false;
	p = solve(p, sn, 5);
	// The clip leaves G's fill level to the shape of the few unclipped
	// samples of its edge, where the model's shape error (about 1% of the
	// step) moves it by several percent. R and B see the same optics at the
	// same pixels, unclipped: where they have contrast, each pixel of the
	// inner edge gives its share F of the step, and G's step is the ratio
	// of sums of (G - frame level) and F over the unclipped ones (chosen by
	// the model's values, not the noisy samples). Then fit again with it.
	{
		const double lo_rb = 2 * p[kFrame];
		const double step_rb = lo_rb - p[fillOf(0)] - p[fillOf(2)];
		double num = 0, den = 0;
		if (step_rb >= kMinRbStep)
			for (const Window& w : windows)
			{
				const double e = M.indexOf(w.j, SideModel::edgeAt(p, w.tau));
				const double width = SideModel::widthAt(p, w.tau);
				for (int i = std::max(w.i0, static_cast<int>(std::ceil(e - 1.5))); i <= w.i1; ++i)
				{
					const double light = SideModel::lightAt(p, w.tau);
					const PixelStep in = pixelStep(i - e, p[kSigma]);
					const PixelStep out =
						M.outer ? pixelStep(i - (e - width), p[kSigma]) : PixelStep{1, 0, 0};
					if (in.value < 0.1 || in.value > 0.9 ||
						light * SideModel::value(p, kG, in, out, nullptr) > kUnclippedG)
						continue;
					// Samples over the light: the levels at tau = 0.
					num += M.sample(w.j, i, kG) / light - p[kFrame];
					den += (lo_rb - (M.sample(w.j, i, 0) + M.sample(w.j, i, 2)) / light) / step_rb;
				}
			}
		if (den > kMinRatioSamples * 0.5)
		{
			p[fillOf(kG)] = p[kFrame] + num / den;
			fixed.push_back(fillOf(kG));
			p = solve(p, sn, 10);
		}
	}
	if (!p.allFinite() || std::abs(p[kE0] - e0_initial) > 1.5 || p[kSigma] < kMinSigmaPx ||
		p[kSigma] > kMaxSigmaPx || p[kOutside] > kMaxLevel || p[fillOf(kG)] > kMaxLevel)
		return false;
	{
		Vec g, gg;
		Mat H;
		evaluate(p, sn, &g, &H, nullptr, nullptr);
		hold(p, g, H, gg);
		const double var = H.inverse()(kE0, kE0);
		if (!(var >= 0) || std::sqrt(var) > kMaxOffsetSdPx) return false;
	}

	// Each profile's clipped G samples on the fill side (and, with the outer
	// edge modelled, outside the frame) replaced by their expectation given
	// the side's model and the clip: E[v | v >= 254.5] = m + sn lambda(z).
	// The side's curve places the edge in each profile: a profile's own fit
	// would move it by its noise only, where the clipped samples' model
	// values vary little with it.
	for (int j = 0; j < np; ++j)
	{
		const double t = M.tau(j);
		const double width = SideModel::widthAt(p, t);
		const double e = M.indexOf(j, SideModel::edgeAt(p, t));
		int* g = g_profiles.data() + size_t(j) * s.n;
		for (int i = 0; i < s.n; ++i)
		{
			if (g[i] < 255) continue;
			const bool fill_side = i >= std::floor(e);
			const bool outside = M.outer && i <= std::ceil(e - width);
			if (!fill_side && !outside) continue;
			const double m = SideModel::lightAt(p, t) * M.value(p, kG, i, e, width, nullptr);
			double nll = 0, d1 = 0, d2 = 0;
			censoredTerm((m - 254.5) / sn, nll, d1, d2);
			g[i] = static_cast<int>(std::lround(m - sn * d1));	// d1 = -lambda(z)
		}
	}
	return true;
}

}  // namespace codemark::detect
