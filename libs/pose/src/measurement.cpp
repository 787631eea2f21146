#include <codemark/landmark/primary.h>
#include <codemark/landmark/text.h>
#include <codemark/landmark/truth.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pose/ambiguity.h>
#include <codemark/pose/general.h>
#include <codemark/pose/measurement.h>
#include <mrpt/config/CConfigFileBase.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace codemark::pose
{
namespace
{
std::string lower(std::string s)
{
	std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
	return s;
}

/** The table under \a key, or \a current when the key is missing; a bad
 * table's error names its section and key. */
SigmaTable readSigmaTable(
	const mrpt::config::CConfigFileBase& c, const std::string& section, const std::string& key,
	const SigmaTable& current)
{
	try
	{
		return sigmaTableFromString(c.read_string(section, key, toString(current)));
	}
	catch (const std::invalid_argument& e)
	{
		throw std::invalid_argument("[" + section + "] " + key + ": " + e.what());
	}
}
}  // namespace

std::string toString(PoseMethod m)
{
	return m == PoseMethod::ClosedForm ? "ClosedForm" : "General6Dof";
}

std::string toString(SigmaSource s) { return s == SigmaSource::Fixed ? "Fixed" : "Detector"; }

SigmaSource sigmaSourceFromString(const std::string& name)
{
	const std::string n = lower(name);
	if (n == "fixed") return SigmaSource::Fixed;
	if (n == "detector") return SigmaSource::Detector;
	throw std::invalid_argument("unknown sigma source '" + name + "' (expected Fixed or Detector)");
}

PoseMethod poseMethodFromString(const std::string& name)
{
	const std::string n = lower(name);
	if (n == "closedform") return PoseMethod::ClosedForm;
	if (n == "general6dof") return PoseMethod::General6Dof;
	throw std::invalid_argument(
		"unknown pose method '" + name + "' (expected ClosedForm or General6Dof)");
}

double interpolateSigma(const SigmaTable& t, double size)
{
	if (size <= t.front().first) return t.front().second;
	if (size >= t.back().first) return t.back().second;
	const auto hi = std::upper_bound(
		t.begin(), t.end(), size, [](double s, const auto& e) { return s < e.first; });
	const auto lo = hi - 1;
	const double f = std::log(size / lo->first) / std::log(hi->first / lo->first);
	return std::exp((1 - f) * std::log(lo->second) + f * std::log(hi->second));
}

SigmaTable sigmaTableFromString(const std::string& text)
{
	SigmaTable t;
	std::istringstream in(text);
	std::string entry;
	while (in >> entry)
	{
		const auto colon = entry.find(':');
		const auto size =
			colon == std::string::npos ? std::nullopt : parseFiniteNumber(entry.substr(0, colon));
		const auto sigma = size ? parseFiniteNumber(entry.substr(colon + 1)) : std::nullopt;
		if (!size || !sigma || !(*size > 0) || !(*sigma > 0))
			throw std::invalid_argument(
				"sigma table: bad entry '" + entry + "' (expected size:sigma, both > 0 [px])");
		if (!t.empty() && !(*size > t.back().first))
			throw std::invalid_argument(
				"sigma table: sizes must increase, '" + entry + "' does not");
		t.emplace_back(*size, *sigma);
	}
	return t;
}

std::string toString(const SigmaTable& t)
{
	std::ostringstream s;
	for (size_t k = 0; k < t.size(); ++k) s << (k ? " " : "") << t[k].first << ":" << t[k].second;
	return s.str();
}

void PoseOptions::validate() const
{
	if (!(sigma_px > 0) || !std::isfinite(sigma_px))
	{
		std::ostringstream s;
		s << "pose options: sigma_px must be finite and > 0, got " << sigma_px;
		throw std::invalid_argument(s.str());
	}
	if (!(sigma_y_px >= 0) || !std::isfinite(sigma_y_px))
		throw std::invalid_argument(
			"pose options: sigma_y_px must be finite and >= 0 (0: sigma_px)");
	if (!(min_sigma_px > 0) || !std::isfinite(min_sigma_px))
		throw std::invalid_argument("pose options: min_sigma_px must be finite and > 0");
	if (!(growth_x_px >= 0) || !(growth_y_px >= 0) || !std::isfinite(growth_x_px) ||
		!std::isfinite(growth_y_px))
		throw std::invalid_argument(
			"pose options: growth_x_px, growth_y_px must be finite and >= 0");
	if (!(size_reference_px > 0) || !std::isfinite(size_reference_px) ||
		!std::isfinite(size_exponent_x) || !std::isfinite(size_exponent_y))
		throw std::invalid_argument(
			"pose options: size_reference_px must be > 0 and the exponents finite");
	for (const double r : {corr_x12, corr_y12, corr_growth_x12, corr_growth_y12})
		if (!(std::abs(r) < 1))
			throw std::invalid_argument(
				"pose options: the correlations corr_* must lie in (-1, 1)");
	if (!(clipped_side_correlation >= 0) || !(clipped_side_correlation < 1))
		throw std::invalid_argument("pose options: clipped_side_correlation must lie in [0, 1)");
	if (!(aligned_edge_ratio >= 0) || !std::isfinite(aligned_edge_ratio))
		throw std::invalid_argument("pose options: aligned_edge_ratio must be finite and >= 0");
	if (!(clipped_side_sigma_px >= 0) || !std::isfinite(clipped_side_sigma_px))
		throw std::invalid_argument("pose options: clipped_side_sigma_px must be finite and >= 0");
	if (!(corner_midpoint_ratio > 0) || !(corner_tilt_ratio > 0) ||
		!std::isfinite(corner_midpoint_ratio) || !std::isfinite(corner_tilt_ratio))
		throw std::invalid_argument(
			"pose options: corner_midpoint_ratio, corner_tilt_ratio must be finite and > 0");
	if (!(corner_tilt_noise_ratio >= 0) || !std::isfinite(corner_tilt_noise_ratio))
		throw std::invalid_argument(
			"pose options: corner_tilt_noise_ratio must be finite and >= 0");
	if (!(reference_noise_grey >= 0) || !std::isfinite(reference_noise_grey))
		throw std::invalid_argument("pose options: reference_noise_grey must be finite and >= 0");
	if (!(band_ratio_x >= 0) || !(band_ratio_y >= 0) || !std::isfinite(band_ratio_x) ||
		!std::isfinite(band_ratio_y))
		throw std::invalid_argument(
			"pose options: band_ratio_x, band_ratio_y must be finite and >= 0");
	for (const SigmaTable* t :
		 {&sigma_x_table, &sigma_y_table, &noise_sigma_x_table, &noise_sigma_y_table,
		  &corner_tilt_ratio_table, &band_floor_x_table, &band_floor_y_table})
		for (size_t k = 0; k < t->size(); ++k)
			if (!((*t)[k].first > 0) || !((*t)[k].second > 0) || !std::isfinite((*t)[k].second) ||
				(k > 0 && !((*t)[k].first > (*t)[k - 1].first)))
				throw std::invalid_argument(
					"pose options: sigma tables need sizes increasing and sigmas > 0");
	if (lm_max_iterations < 1)
		throw std::invalid_argument("pose options: lm_max_iterations must be >= 1");
}

void PoseOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	// MRPT's readers take "0.05px" as 0.05 and "abc" as 0: check the numbers first.
	requireIniNumbers(
		c, s,
		{"sigma_px", "sigma_y_px", "growth_x_px", "growth_y_px", "size_exponent_x",
		 "size_exponent_y", "size_reference_px", "corr_x12", "corr_y12", "corr_growth_x12",
		 "corr_growth_y12", "clipped_side_sigma_px", "clipped_side_correlation",
		 "aligned_edge_ratio", "corner_midpoint_ratio", "corner_tilt_ratio",
		 "corner_tilt_noise_ratio", "min_sigma_px", "reference_noise_grey"});
	requireIniNumbers(c, s, {"band_ratio_x", "band_ratio_y"});
	requireIniNumbers(c, s, {"lm_max_iterations"}, true);
	requireIniBooleans(
		c, s, {"second_order_pose_covariance", "refine_on_primary", "fold_ambiguity"});
	method = poseMethodFromString(c.read_string(s, "method", toString(method)));
	MRPT_LOAD_CONFIG_VAR(sigma_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(sigma_y_px, double, c, s);
	sigma_source = sigmaSourceFromString(c.read_string(s, "sigma_source", toString(sigma_source)));
	MRPT_LOAD_CONFIG_VAR(growth_x_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(growth_y_px, double, c, s);
	sigma_x_table = readSigmaTable(c, s, "sigma_x_table", sigma_x_table);
	sigma_y_table = readSigmaTable(c, s, "sigma_y_table", sigma_y_table);
	MRPT_LOAD_CONFIG_VAR(reference_noise_grey, double, c, s);
	noise_sigma_x_table = readSigmaTable(c, s, "noise_sigma_x_table", noise_sigma_x_table);
	noise_sigma_y_table = readSigmaTable(c, s, "noise_sigma_y_table", noise_sigma_y_table);
	corner_tilt_ratio_table =
		readSigmaTable(c, s, "corner_tilt_ratio_table", corner_tilt_ratio_table);
	MRPT_LOAD_CONFIG_VAR(band_ratio_x, double, c, s);
	MRPT_LOAD_CONFIG_VAR(band_ratio_y, double, c, s);
	band_floor_x_table = readSigmaTable(c, s, "band_floor_x_table", band_floor_x_table);
	band_floor_y_table = readSigmaTable(c, s, "band_floor_y_table", band_floor_y_table);
	MRPT_LOAD_CONFIG_VAR(size_exponent_x, double, c, s);
	MRPT_LOAD_CONFIG_VAR(size_exponent_y, double, c, s);
	MRPT_LOAD_CONFIG_VAR(size_reference_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(corr_x12, double, c, s);
	MRPT_LOAD_CONFIG_VAR(corr_y12, double, c, s);
	MRPT_LOAD_CONFIG_VAR(corr_growth_x12, double, c, s);
	MRPT_LOAD_CONFIG_VAR(corr_growth_y12, double, c, s);
	MRPT_LOAD_CONFIG_VAR(clipped_side_sigma_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(clipped_side_correlation, double, c, s);
	MRPT_LOAD_CONFIG_VAR(aligned_edge_ratio, double, c, s);
	MRPT_LOAD_CONFIG_VAR(corner_midpoint_ratio, double, c, s);
	MRPT_LOAD_CONFIG_VAR(corner_tilt_ratio, double, c, s);
	MRPT_LOAD_CONFIG_VAR(corner_tilt_noise_ratio, double, c, s);
	MRPT_LOAD_CONFIG_VAR(second_order_pose_covariance, bool, c, s);
	MRPT_LOAD_CONFIG_VAR(refine_on_primary, bool, c, s);
	MRPT_LOAD_CONFIG_VAR(fold_ambiguity, bool, c, s);
	MRPT_LOAD_CONFIG_VAR(min_sigma_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(lm_max_iterations, int, c, s);
	validate();
}

void PoseOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	c.write(
		s, "method", toString(method), -1, -1,
		"ClosedForm (paper, level camera) | General6Dof (PnP)");
	c.write(
		s, "sigma_px", sigma_px, -1, -1, "std. dev. of x1, x2 (and y1, y2 unless sigma_y_px) [px]");
	c.write(s, "sigma_y_px", sigma_y_px, -1, -1, "std. dev. of y1, y2 [px]; 0: sigma_px");
	c.write(
		s, "sigma_source", toString(sigma_source), -1, -1,
		"Fixed (sigma_px) | Detector (its corner_sigma_px)");
	c.write(
		s, "growth_x_px", growth_x_px, -1, -1,
		"growth of sigma(x1, x2) for small landmarks [px]; 0: constant");
	c.write(
		s, "growth_y_px", growth_y_px, -1, -1,
		"growth of sigma(y1, y2) for small landmarks [px]; 0: constant");
	c.write(
		s, "sigma_x_table", toString(sigma_x_table), -1, -1,
		"size:sigma pairs [px] of x1, x2 against x2 - x1; replace sigma_px and growth_x_px");
	c.write(
		s, "sigma_y_table", toString(sigma_y_table), -1, -1,
		"size:sigma pairs [px] of y1, y2 against y1 + y2; replace sigma_y_px and growth_y_px");
	c.write(
		s, "reference_noise_grey", reference_noise_grey, -1, -1,
		"image noise the sigmas were measured at [grey levels]; 0: C_P ignores the image noise");
	c.write(
		s, "noise_sigma_x_table", toString(noise_sigma_x_table), -1, -1,
		"size:sigma pairs [px], the noise-driven part of sigma(x1, x2) at reference_noise_grey");
	c.write(
		s, "noise_sigma_y_table", toString(noise_sigma_y_table), -1, -1,
		"size:sigma pairs [px], the noise-driven part of sigma(y1, y2) at reference_noise_grey");
	c.write(
		s, "band_ratio_x", band_ratio_x, -1, -1,
		"sigma(x1, x2) over the scatter of the landmark's green bands; 0: off");
	c.write(
		s, "band_ratio_y", band_ratio_y, -1, -1,
		"sigma(y1, y2) over the scatter of the landmark's green bands; 0: off");
	c.write(
		s, "band_floor_x_table", toString(band_floor_x_table), -1, -1,
		"size:sigma pairs [px] added to the band term of x1, x2 against x2 - x1");
	c.write(
		s, "band_floor_y_table", toString(band_floor_y_table), -1, -1,
		"size:sigma pairs [px] added to the band term of y1, y2 against y1 + y2");
	c.write(
		s, "size_exponent_x", size_exponent_x, -1, -1,
		"sigma_x = sqrt(sigma_px^2 + (growth_x_px (ref / (x2 - x1))^exp)^2)");
	c.write(
		s, "size_exponent_y", size_exponent_y, -1, -1,
		"sigma_y = sqrt(sigma_y_px^2 + (growth_y_px (ref / (y1 + y2))^exp)^2)");
	c.write(s, "size_reference_px", size_reference_px, -1, -1, "ref of the growth terms [px]");
	c.write(
		s, "corr_x12", corr_x12, -1, -1, "correlation of the errors of x1 and x2, constant part");
	c.write(s, "corr_growth_x12", corr_growth_x12, -1, -1, "the same, size-dependent part");
	c.write(
		s, "corr_y12", corr_y12, -1, -1, "correlation of the errors of y1 and y2, constant part");
	c.write(s, "corr_growth_y12", corr_growth_y12, -1, -1, "the same, size-dependent part");
	c.write(
		s, "clipped_side_sigma_px", clipped_side_sigma_px, -1, -1,
		"std. dev. added to a side whose fill clips throughout [px]; 0: off");
	c.write(
		s, "clipped_side_correlation", clipped_side_correlation, -1, -1,
		"correlation of two clipped sides' outward shifts (0..1)");
	c.write(
		s, "aligned_edge_ratio", aligned_edge_ratio, -1, -1,
		"extra sigma of a top/bottom edge along a pixel row, over sigma(y_i); 0: off");
	c.write(
		s, "corner_midpoint_ratio", corner_midpoint_ratio, -1, -1,
		"General6Dof: sigma of an edge's midpoint height over sigma(y_i)");
	c.write(
		s, "corner_tilt_ratio", corner_tilt_ratio, -1, -1,
		"General6Dof: sigma of an edge's tilt over sigma(x_i)");
	c.write(
		s, "corner_tilt_ratio_table", toString(corner_tilt_ratio_table), -1, -1,
		"General6Dof: size:ratio pairs against y1 + y2 [px]; replace corner_tilt_ratio");
	c.write(
		s, "corner_tilt_noise_ratio", corner_tilt_noise_ratio, -1, -1,
		"General6Dof: the same for the part that grows with the image noise; 0: the same ratio");
	c.write(
		s, "second_order_pose_covariance", second_order_pose_covariance, -1, -1,
		"ClosedForm: C_R to second order in C_L");
	c.write(
		s, "refine_on_primary", refine_on_primary, -1, -1,
		"closed form: refine L by weighted least squares on P with C_P");
	c.write(
		s, "fold_ambiguity", fold_ambiguity, -1, -1,
		"weigh the mirror-image solution and fold it into C_L, C_R");
	c.write(
		s, "min_sigma_px", min_sigma_px, -1, -1,
		"Detector: floor of the sigma of a component of P [px]");
	c.write(
		s, "lm_max_iterations", lm_max_iterations, -1, -1,
		"General6Dof: LM iterations per refinement");
}

double PoseOptions::noiseScale(bool x, double size_px, double var, double image_noise_grey) const
{
	const SigmaTable& t = x ? noise_sigma_x_table : noise_sigma_y_table;
	if (!(reference_noise_grey > 0) || !(image_noise_grey > 0) || t.empty() || !(var > 0)) return 1;
	// Not below the reference: the calibration does not reach quieter
	// images, where the detector's error need not fall (on the accuracy
	// map within 2 m its range error at noise 1 is 1.5x that at noise 2).
	const double r = std::max(1.0, image_noise_grey / reference_noise_grey);
	const double share = std::min(1.0, std::pow(interpolateSigma(t, size_px), 2) / var);
	return 1 + (r * r - 1) * share;
}

double PoseOptions::cornerTiltRatio(double height_px) const
{
	return corner_tilt_ratio_table.empty() ? corner_tilt_ratio
										   : interpolateSigma(corner_tilt_ratio_table, height_px);
}

Eigen::Matrix4d PoseOptions::primaryCovariance(
	const Eigen::Vector4d& P, double image_noise_grey, double band_se_px) const
{
	// Apparent sizes, floored at 1 px so that a degenerate P gives a large
	// but finite covariance.
	const double w = std::max(1.0, std::abs(P[2] - P[0])), h = std::max(1.0, P[1] + P[3]);
	const double gx = growth_x_px * std::pow(size_reference_px / w, size_exponent_x);
	const double gy = growth_y_px * std::pow(size_reference_px / h, size_exponent_y);
	const double fx2 = sigma_px * sigma_px, fy2 = sigmaY() * sigmaY();
	const double vx = fx2 + gx * gx, vy = fy2 + gy * gy;
	Eigen::Matrix4d C = Eigen::Vector4d(vx, vy, vx, vy).asDiagonal();
	C(0, 2) = C(2, 0) = corr_x12 * fx2 + corr_growth_x12 * gx * gx;
	C(1, 3) = C(3, 1) = corr_y12 * fy2 + corr_growth_y12 * gy * gy;
	// One axis's block (i = 0: x1, x2; 1: y1, y2) as variance v with
	// correlation r between the two edges.
	const auto setAxis = [&C](int i, double v, double r)
	{
		C(i, i) = C(i + 2, i + 2) = v;
		C(i, i + 2) = C(i + 2, i) = r * v;
	};
	if (!sigma_x_table.empty())
		setAxis(0, std::pow(interpolateSigma(sigma_x_table, w), 2), corr_growth_x12);
	if (!sigma_y_table.empty())
		setAxis(1, std::pow(interpolateSigma(sigma_y_table, h), 2), corr_growth_y12);
	// The scatter model (band_ratio_x), per axis.
	const auto band = [&](double ratio, const SigmaTable& floor, double size)
	{
		const double f = floor.empty() ? 0.0 : interpolateSigma(floor, size);
		return ratio * ratio * band_se_px * band_se_px + f * f;
	};
	const bool band_x = band_ratio_x > 0 && band_se_px > 0,
			   band_y = band_ratio_y > 0 && band_se_px > 0;
	if (band_x) setAxis(0, band(band_ratio_x, band_floor_x_table, w), corr_growth_x12);
	if (band_y) setAxis(1, band(band_ratio_y, band_floor_y_table, h), corr_growth_y12);
	// Each axis's block scaled as a whole keeps its correlation and stays
	// positive definite.
	const double kx = band_x ? 1.0 : noiseScale(true, w, C(0, 0), image_noise_grey);
	const double ky = band_y ? 1.0 : noiseScale(false, h, C(1, 1), image_noise_grey);
	for (const int i : {0, 2})
		for (const int j : {0, 2})
		{
			C(i, j) *= kx;
			C(i + 1, j + 1) *= ky;
		}
	return C;
}

Eigen::Matrix4d PoseOptions::clippedSidesCovariance(const std::array<bool, 4>& clipped) const
{
	// P's change per unit outward shift of each side (top, right, bottom,
	// left): a top or bottom shift d lengthens both vertical edges by d,
	// each half-length by d / 2.
	Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
	A(1, 0) = A(3, 0) = 0.5;  // top
	A(2, 1) = 1;  // right: x2
	A(1, 2) = A(3, 2) = 0.5;  // bottom
	A(0, 3) = -1;  // left: x1
	const double v = clipped_side_sigma_px * clipped_side_sigma_px;
	Eigen::Matrix4d S = Eigen::Matrix4d::Zero();  // the clipped sides' shifts
	for (int a = 0; a < 4; ++a)
		for (int b = 0; b < 4; ++b)
			if (clipped[a] && clipped[b]) S(a, b) = a == b ? v : clipped_side_correlation * v;
	return A * S * A.transpose();
}

Eigen::Matrix4d PoseOptions::alignedEdgesCovariance(
	const Eigen::Vector4d& P, double top_rows, double bottom_rows, double band_se_px) const
{
	Eigen::Matrix4d C = Eigen::Matrix4d::Zero();
	if (aligned_edge_ratio <= 0) return C;
	// sigma_y(h)^2 of the y model (the diagonal holds no correlation).
	const double vy = primaryCovariance(P, 0, band_se_px)(1, 1);
	const auto weight = [](double rows) { return std::max(0.0, 1 - std::abs(rows)); };
	// Each aligned edge's shift d moves y1 and y2 by d / 2.
	const double h = 0.25 * aligned_edge_ratio * aligned_edge_ratio * vy *
					 (weight(top_rows) + weight(bottom_rows));
	C(1, 1) = C(3, 3) = C(1, 3) = C(3, 1) = h;
	return C;
}

namespace
{
Measurement measureWith(
	const std::array<Eigen::Vector2d, 4>& corners, const CameraModel& camera,
	const LandmarkGeometry& geometry, const PoseOptions& options,
	const std::array<bool, 4>& clipped, double image_noise_grey, double band_se_px)
{
	options.validate();
	Measurement m;
	m.method = options.method;
	double lambda = 0;
	m.P = primaryMeasurement(corners, camera, &lambda);
	const Eigen::Matrix4d C_primary = options.primaryCovariance(m.P, image_noise_grey, band_se_px);
	m.C_P = C_primary + options.clippedSidesCovariance(clipped);
	if (options.aligned_edge_ratio > 0)
	{
		// Rows between the ends of the top (TL, TR) and bottom (BL, BR) edges.
		std::array<Eigen::Vector2d, 4> ideal;
		for (int k = 0; k < 4; ++k) ideal[k] = camera.undistortPixel(corners[k]);
		m.C_P += options.alignedEdgesCovariance(
			m.P, ideal[1].y() - ideal[0].y(), ideal[2].y() - ideal[3].y(), band_se_px);
	}
	const auto poseCovariance = [&](const Eigen::Vector3d& L, const Eigen::Matrix3d& C_L,
									const Eigen::Matrix3d& first_order) {
		return options.second_order_pose_covariance ? poseCovarianceSecondOrder(L, C_L)
													: first_order;
	};
	const auto fold = [&](const MeasurementMode& a, const MeasurementMode& b)
	{
		// Optima closer than a tenth of the local sigma of phi2 are one
		// (both starts reached the same valley floor).
		const double dphi2 = std::abs(wrapToPi(b.L[2] - a.L[2]));
		if (!(dphi2 > 0.1 * std::sqrt(std::min(a.C_L(2, 2), b.C_L(2, 2))))) return;
		const MeasurementMode k = foldModes(a, b, &m.second_mode_weight);
		m.second_mode_L = b.L;
		m.L = k.L;
		m.C_L = k.C_L;
		m.pose_in_landmark = k.pose_in_landmark;
		m.C_R = k.C_R;
	};
	if (options.method == PoseMethod::ClosedForm)
	{
		Eigen::Matrix<double, 3, 4> J_P;
		Eigen::Matrix3d J_L;
		const bool refine = options.refine_on_primary;
		const double h = geometry.innerHalf();
		m.L = landmarkFromPrimary(m.P, lambda, h, refine ? nullptr : &J_P);
		if (refine)
			m.L = refineLandmarkOnPrimary(m.P, m.C_P, lambda, h, m.L, &m.C_L);
		else
			m.C_L = J_P * m.C_P * J_P.transpose();
		m.pose_in_landmark = poseFromLandmark(m.L, &J_L);
		m.C_R = poseCovariance(m.L, m.C_L, J_L * m.C_L * J_L.transpose());
		if (refine && options.fold_ambiguity)
		{
			const auto closedFormMode = [&](const Eigen::Vector3d& L, const Eigen::Matrix3d& C_L)
			{
				MeasurementMode mode;
				mode.L = L;
				mode.C_L = C_L;
				Eigen::Matrix3d J;
				mode.pose_in_landmark = poseFromLandmark(L, &J);
				mode.C_R = poseCovariance(L, C_L, J * C_L * J.transpose());
				const Eigen::Vector4d r = m.P - primaryFromLandmark(L, lambda, h);
				mode.chi2 = r.dot(m.C_P.ldlt().solve(r));
				mode.log_det_cov = std::log(C_L.determinant());
				return mode;
			};
			// The mirror image about the line of sight: view angle phi1 + phi2
			// -> -(phi1 + phi2), refined in its own right.
			Eigen::Vector3d L0 = m.L;
			L0[2] = wrapToPi(-2 * m.L[1] - m.L[2]);
			Eigen::Matrix3d C_mirror;
			try
			{
				const Eigen::Vector3d L_mirror =
					refineLandmarkOnPrimary(m.P, m.C_P, lambda, h, L0, &C_mirror);
				if (C_mirror.allFinite() && C_mirror.determinant() > 0)
				{
					// The better fit is kept (foldModes()).
					const MeasurementMode a = closedFormMode(m.L, m.C_L),
										  b = closedFormMode(L_mirror, C_mirror);
					if (a.chi2 <= b.chi2)
						fold(a, b);
					else
						fold(b, a);
				}
			}
			catch (const std::invalid_argument&)
			{
				// The mirror start put an edge behind the camera: no second optimum.
			}
		}
		return m;
	}
	// The general path takes the corner covariance whose image in P is C_P
	// (cornerCovarianceFromPrimary()): the edges' correlations included. One
	// isotropic corner sigma cannot carry them (a common shift of x1 and x2
	// is far less certain than their difference, which range and phi2 use):
	// matched to C_P's determinant it made the general path overconfident
	// from 2 to 5 m on the accuracy map (mean NEES 3.95 against [2.80,
	// 3.21]), matched to its diagonal conservative on the realistic renders
	// of test_pose_nees.cpp (2.66 against [2.72, 3.29]).
	// The tilt ratio at this sighting's apparent height (corner_tilt_ratio_table).
	const double tilt_ratio = options.cornerTiltRatio(m.P[1] + m.P[3]);
	// The tilts' own share of the noise's growth (corner_tilt_noise_ratio).
	Eigen::Vector2d tilt_extra = Eigen::Vector2d::Zero();
	if (options.corner_tilt_noise_ratio > 0 && image_noise_grey > 0)
	{
		const Eigen::Matrix4d grown = C_primary - options.primaryCovariance(m.P, 0, band_se_px);
		const double k2 = options.corner_tilt_noise_ratio * options.corner_tilt_noise_ratio -
						  tilt_ratio * tilt_ratio;
		tilt_extra = k2 * Eigen::Vector2d(grown(0, 0), grown(2, 2));
	}
	const GeneralPose g = solveGeneralPose(
		corners, camera, geometry,
		cornerCovarianceFromPrimary(
			corners, camera, m.C_P, options.corner_midpoint_ratio, tilt_ratio, tilt_extra),
		options.lm_max_iterations);
	// The planar pose is poseFromLandmark(L) on this path too: the same
	// curvature beyond 2 m (poseCovarianceSecondOrder()).
	const auto generalMode = [&](const PnPSolution& s)
	{
		MeasurementMode mode;
		mode.L = s.L;
		mode.C_L = s.C_L;
		mode.pose_in_landmark = s.pose_in_landmark;
		mode.C_R = poseCovariance(s.L, s.C_L, s.C_R);
		mode.chi2 = s.chi2;
		mode.log_det_cov = s.log_det_cov;
		return mode;
	};
	const MeasurementMode best = generalMode(g.solutions[0]);
	m.L = best.L;
	m.C_L = best.C_L;
	m.pose_in_landmark = best.pose_in_landmark;
	m.C_R = best.C_R;
	m.landmark_T_camera = g.solutions[0].landmark_T_camera;
	m.reprojection_rms_px = g.solutions[0].rms_px;
	m.ambiguity_ratio = g.ambiguity_ratio;
	if (options.fold_ambiguity && g.solutions.size() > 1 &&
		std::isfinite(g.solutions[1].log_det_cov) && std::isfinite(best.log_det_cov))
	{
		PnPSolution other = g.solutions[1];
		reducePnPSolution(other);
		const MeasurementMode second = generalMode(other);
		// IPPE's better solution (the lower RMS reprojection error) is kept.
		fold(best, second);
	}
	return m;
}
}  // namespace

Measurement measure(
	const std::array<Eigen::Vector2d, 4>& corners, const CameraModel& camera,
	const LandmarkGeometry& geometry, const PoseOptions& options)
{
	return measureWith(corners, camera, geometry, options, {{false, false, false, false}}, 0, 0);
}

Measurement measure(
	const Detection& detection, const CameraModel& camera, const LandmarkGeometry& geometry,
	const PoseOptions& options)
{
	PoseOptions o = options;
	if (o.sigma_source == SigmaSource::Detector && detection.quality.corner_sigma_px > 0)
	{
		o.sigma_px = std::max(o.min_sigma_px, detection.quality.corner_sigma_px / std::sqrt(2.0));
		o.sigma_y_px = 0;
		o.growth_x_px = o.growth_y_px = 0;
		o.corr_x12 = o.corr_y12 = 0;
		// The tables would override the detector's sigma.
		o.sigma_x_table.clear();
		o.sigma_y_table.clear();
		o.band_ratio_x = o.band_ratio_y = 0;
		// The detector's sigma already follows its image's noise.
		o.reference_noise_grey = 0;
	}
	return measureWith(
		detection.corners, camera, geometry, o, detection.quality.fill_clipped,
		detection.quality.image_noise_grey, detection.quality.edge_bend_se_px);
}

}  // namespace codemark::pose
