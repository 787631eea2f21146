#include <codemark/landmark/primary.h>
#include <codemark/pose/closed_form.h>
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

void PoseOptions::validate() const
{
	if (!(sigma_px > 0) || !std::isfinite(sigma_px))
	{
		std::ostringstream s;
		s << "pose options: sigma_px must be finite and > 0, got " << sigma_px;
		throw std::invalid_argument(s.str());
	}
	if (!(sigma_y_px >= 0) || !std::isfinite(sigma_y_px))
		throw std::invalid_argument("pose options: sigma_y_px must be finite and >= 0 (0: sigma_px)");
	if (!(min_sigma_px > 0) || !std::isfinite(min_sigma_px))
		throw std::invalid_argument("pose options: min_sigma_px must be finite and > 0");
	if (lm_max_iterations < 1)
		throw std::invalid_argument("pose options: lm_max_iterations must be >= 1");
}

void PoseOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	method = poseMethodFromString(c.read_string(s, "method", toString(method)));
	MRPT_LOAD_CONFIG_VAR(sigma_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(sigma_y_px, double, c, s);
	sigma_source = sigmaSourceFromString(c.read_string(s, "sigma_source", toString(sigma_source)));
	MRPT_LOAD_CONFIG_VAR(min_sigma_px, double, c, s);
	MRPT_LOAD_CONFIG_VAR(lm_max_iterations, int, c, s);
	validate();
}

void PoseOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	c.write(s, "method", toString(method), -1, -1, "ClosedForm (paper, level camera) | General6Dof (PnP)");
	c.write(s, "sigma_px", sigma_px, -1, -1, "std. dev. of x1, x2 (and y1, y2 unless sigma_y_px) [px]");
	c.write(s, "sigma_y_px", sigma_y_px, -1, -1, "std. dev. of y1, y2 [px]; 0: sigma_px");
	c.write(s, "sigma_source", toString(sigma_source), -1, -1, "Fixed (sigma_px) | Detector (its corner_sigma_px)");
	c.write(s, "min_sigma_px", min_sigma_px, -1, -1, "Detector: floor of the sigma of a component of P [px]");
	c.write(s, "lm_max_iterations", lm_max_iterations, -1, -1, "General6Dof: LM iterations per refinement");
}

Measurement measure(
	const std::array<Eigen::Vector2d, 4>& corners, const CameraModel& camera,
	const LandmarkGeometry& geometry, const PoseOptions& options)
{
	options.validate();
	Measurement m;
	m.method = options.method;
	double lambda = 0;
	m.P = primaryMeasurement(corners, camera, &lambda);
	m.C_P = primaryCovariance(options.sigma_px, options.sigmaY());
	if (options.method == PoseMethod::ClosedForm)
	{
		Eigen::Matrix<double, 3, 4> J_P;
		Eigen::Matrix3d J_L;
		m.L = landmarkFromPrimary(m.P, lambda, geometry.innerHalf(), &J_P);
		m.C_L = J_P * m.C_P * J_P.transpose();
		m.pose_in_landmark = poseFromLandmark(m.L, &J_L);
		m.C_R = J_L * m.C_L * J_L.transpose();
		return m;
	}
	// Each corner coordinate carries sqrt(2) sigma when each component of P
	// (a mean or half-difference of two corners) carries sigma; the general
	// path takes one isotropic corner sigma: the RMS of the two.
	const double sigma_corner = std::sqrt(options.sigma_px * options.sigma_px + options.sigmaY() * options.sigmaY());
	const GeneralPose g = solveGeneralPose(
		corners, camera, geometry, sigma_corner, options.lm_max_iterations);
	m.L = g.L;
	m.C_L = g.C_L;
	m.pose_in_landmark = g.pose_in_landmark;
	m.C_R = g.C_R;
	m.landmark_T_camera = g.solutions[0].landmark_T_camera;
	m.reprojection_rms_px = g.solutions[0].rms_px;
	m.ambiguity_ratio = g.ambiguity_ratio;
	return m;
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
	}
	return measure(detection.corners, camera, geometry, o);
}

}  // namespace codemark::pose
