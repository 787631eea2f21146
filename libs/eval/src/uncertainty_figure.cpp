// The paper's Fig. 3 drawn with OpenCV (uncertainty_figure.h).
#include <codemark/eval/uncertainty_figure.h>
#include <codemark/landmark/truth.h>
#include <mrpt/math/distributions.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace codemark::eval
{
using namespace codemark::pose;

namespace
{
std::string fmt(double v, int prec)
{
	std::ostringstream s;
	s << std::fixed << std::setprecision(prec) << v;
	return s.str();
}
}  // namespace

FigureScales drawUncertaintyFigure(
	const std::string& path, const CameraModel& camera, const FigureOptions& o)
{
	if (!(o.step_m > 0) || !(o.x_max_m >= o.x_min_m) || !(o.pixels_per_m > 0) || !(o.scale > 0))
		throw std::invalid_argument("drawUncertaintyFigure: invalid grid options");
	const LandmarkGeometry g = LandmarkGeometry::scaled(o.scale);
	const PoseOptions noise = o.noise ? *o.noise : constantNoise(o.sigma_px);

	struct Cell
	{
		double X, Y;
		SightingUncertainty u;
		bool usable;
	};
	std::vector<Cell> cells;
	double max_wedge = 0;
	std::vector<double> a95s;
	for (double X = o.x_min_m; X <= o.x_max_m + 1e-9; X += o.step_m)
		for (double Y = -o.y_max_m; Y <= o.y_max_m + 1e-9; Y += o.step_m)
		{
			const double angle = std::atan2(Y, X);
			if (std::abs(angle) > o.max_view_angle_deg * M_PI / 180 + 1e-9) continue;
			Cell c{X, Y, predictUncertainty(camera, g, noise, std::hypot(X, Y), angle), false};
			c.usable = c.u.in_image && c.u.size_px >= o.min_size_px;
			if (c.usable)
			{
				a95s.push_back(std::sqrt(mrpt::math::chi2inv(0.95, 2)) * c.u.sigma_position_m);
				max_wedge = std::max(max_wedge, 1.96 * c.u.sigma_heading_rad);
			}
			cells.push_back(c);
		}

	// Round down to 1-2-5 x 10^n.
	const auto round125 = [](double v)
	{
		const double p = std::pow(10.0, std::floor(std::log10(v)));
		const double f = v / p;
		return p * (f >= 5 ? 5 : f >= 2 ? 2 : 1);
	};
	// Ellipses: three quarters of them fit between grid points; the few
	// largest (seen squarely from afar, where phi2 is weakest) may overlap
	// their neighbours rather than shrink every other ellipse to a dot.
	double a95 = 0;
	if (!a95s.empty())
	{
		const auto q = a95s.begin() + static_cast<std::ptrdiff_t>(0.75 * (a95s.size() - 1));
		std::nth_element(a95s.begin(), q, a95s.end());
		a95 = *q;
	}
	double mag = o.magnification;
	if (!(mag > 0)) mag = round125(a95 > 0 ? 0.45 * o.step_m / a95 : 1.0);
	double hmag = o.heading_magnification;
	if (!(hmag > 0))
		hmag = std::max(1.0, round125(max_wedge > 0 ? (20 * M_PI / 180) / max_wedge : 1.0));

	const double ppm = o.pixels_per_m;
	const int header = 86;
	const int W = static_cast<int>(std::lround((2 * o.y_max_m + 1.2) * ppm));
	const int Hh = header + 20 + static_cast<int>(std::lround((o.x_max_m + 0.8) * ppm));
	cv::Mat img(Hh, std::max(W, 900), CV_8UC3, cv::Scalar(255, 255, 255));
	const double u0 = img.cols / 2.0, v0 = header + 0.35 * ppm;
	// Top view: X_L (outward normal) down the image, Y_L to the right.
	const auto S = [&](double X, double Y)
	{
		return cv::Point(
			static_cast<int>(std::lround(u0 + Y * ppm)),
			static_cast<int>(std::lround(v0 + X * ppm)));
	};
	const cv::Scalar black(0, 0, 0), grey(170, 170, 170), red(30, 30, 220), blue(200, 90, 20),
		green(0, 190, 0);

	// Distance rings and labels.
	for (double r = 1; r <= std::hypot(o.x_max_m, o.y_max_m) + 1e-9; r += 1)
	{
		cv::ellipse(
			img, S(0, 0), cv::Size(int(r * ppm), int(r * ppm)), 0, 0, 180,
			cv::Scalar(225, 225, 225), 1, cv::LINE_AA);
		cv::putText(
			img, fmt(r, 0) + " m", S(r, 0) + cv::Point(4, -4), cv::FONT_HERSHEY_SIMPLEX, 0.4, grey,
			1, cv::LINE_AA);
	}
	// The landmark (outer frame, drawn to scale but at least 8 px wide).
	const int half_px = std::max(4, int(std::lround(g.outerHalf() * ppm)));
	cv::rectangle(
		img, S(0, 0) + cv::Point(-half_px, -5), S(0, 0) + cv::Point(half_px, 0), black, cv::FILLED);
	cv::rectangle(
		img, S(0, 0) + cv::Point(-half_px + 2, -4), S(0, 0) + cv::Point(half_px - 2, -1), green,
		cv::FILLED);
	cv::arrowedLine(img, S(0, 0), S(0.3, 0), grey, 1, cv::LINE_AA, 0, 0.2);
	cv::putText(
		img, "X_L", S(0.3, 0) + cv::Point(4, 4), cv::FONT_HERSHEY_SIMPLEX, 0.4, grey, 1,
		cv::LINE_AA);

	for (const Cell& c : cells)
	{
		const cv::Point p = S(c.X, c.Y);
		if (!c.usable)
		{
			cv::drawMarker(img, p, grey, cv::MARKER_TILTED_CROSS, 8, 1, cv::LINE_AA);
			continue;
		}
		const Measurement& m = c.u.measurement;
		// Screen covariance: (Y, X) -> (u, v).
		Eigen::Matrix2d Cs;
		Cs << m.C_R(1, 1), m.C_R(0, 1), m.C_R(0, 1), m.C_R(0, 0);
		Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(Cs);
		const double a =
			std::sqrt(mrpt::math::chi2inv(0.95, 2) * std::max(0.0, es.eigenvalues()[1])) * mag *
			ppm;
		const double b =
			std::sqrt(mrpt::math::chi2inv(0.95, 2) * std::max(0.0, es.eigenvalues()[0])) * mag *
			ppm;
		const Eigen::Vector2d ev = es.eigenvectors().col(1);
		const double ang_deg = std::atan2(ev.y(), ev.x()) * 180 / M_PI;
		cv::ellipse(
			img, p, cv::Size(std::max(1, int(std::lround(a))), std::max(1, int(std::lround(b)))),
			ang_deg, 0, 360, red, 1, cv::LINE_AA);
		// Heading: the optical axis (towards the landmark) and a
		// +-1.96 sigma wedge, magnified like the ellipses (capped at 180 deg).
		const double th = m.pose_in_landmark[2];
		const double half = std::min(M_PI, 1.96 * c.u.sigma_heading_rad * hmag);
		const double len = 0.18 * o.step_m / 0.5;
		const auto ray = [&](double t)
		{ return S(c.X + len * std::cos(t), c.Y + len * std::sin(t)); };
		cv::line(img, p, ray(th - half), blue, 1, cv::LINE_AA);
		cv::line(img, p, ray(th + half), blue, 1, cv::LINE_AA);
		cv::line(img, p, ray(th), cv::Scalar(120, 120, 120), 1, cv::LINE_AA);
		cv::circle(img, p, 2, black, cv::FILLED, cv::LINE_AA);
		if (std::abs(c.Y) < 1e-9)
			cv::putText(
				img,
				fmt(c.u.sigma_position_m * 1000, 1) + " mm " +
					fmt(c.u.sigma_heading_rad * 180 / M_PI, 2) + " deg",
				p + cv::Point(6, 14), cv::FONT_HERSHEY_SIMPLEX, 0.35, black, 1, cv::LINE_AA);
	}

	const auto text = [&](const std::string& s, int line)
	{
		cv::putText(
			img, s, cv::Point(8, 18 + 17 * line), cv::FONT_HERSHEY_SIMPLEX, 0.42, black, 1,
			cv::LINE_AA);
	};
	text(
		"Predicted uncertainty of one landmark fix (paper Fig. 3), top view; robots look at the "
		"landmark centre",
		0);
	text(
		"red: 95% position ellipse, drawn x" + fmt(mag, mag < 1 ? 2 : 0) +
			"; blue: heading +-1.96 sigma, drawn x" + fmt(hmag, 0) + "; grey x: square < " +
			fmt(o.min_size_px, 0) + " px or out of view",
		1);
	text(
		(o.noise ? o.noise_label : "sigma_px " + fmt(o.sigma_px, 3) + " per component of P") +
			"; camera " + std::to_string(camera.width()) + "x" + std::to_string(camera.height()) +
			", fx " + fmt(camera.fx(), 1) + " px; landmark scale " + fmt(o.scale, 2) +
			" (reference square " + fmt(g.inner_size_m * 1000, 0) + " mm)",
		2);
	text("labels on the axis: 1-sigma position (worst direction) and heading", 3);
	text("1 m", 4);
	cv::line(
		img, cv::Point(40, 18 + 17 * 4 - 4), cv::Point(40 + int(ppm), 18 + 17 * 4 - 4), black, 2);
	if (!cv::imwrite(path, img)) throw std::runtime_error("cannot write " + path);
	return {mag, hmag};
}

std::string describeSizeAdvice(const pose::SizeAdvice& a, double k)
{
	std::ostringstream s;
	if (!a.found)
	{
		s << "no landmark size meets the request: " << a.reason << "\n";
		return s.str();
	}
	const LandmarkGeometry g = LandmarkGeometry::scaled(a.scale);
	s << "scale " << fmt(a.scale, 3) << " (" << a.reason << "): outer frame "
	  << fmt(g.outer_size_m * 1000, 1) << " mm, reference square " << fmt(g.inner_size_m * 1000, 1)
	  << " mm, code cells " << fmt(g.cell_size_m * 1000, 1) << " mm\n";
	s << "predicted there: reference square " << fmt(a.at.size_px, 1) << " px tall; " << fmt(k, 1)
	  << " sigma: position " << fmt(k * a.at.sigma_position_m * 1000, 2)
	  << " mm (worst direction), heading " << fmt(k * a.at.sigma_heading_rad * 180 / M_PI, 3)
	  << " deg, range " << fmt(k * a.at.sigma_l2_m * 1000, 2) << " mm\n";
	return s.str();
}

std::string accuracyTable(
	const CameraModel& camera, double scale, double sigma_px, double angle,
	const std::vector<double>& distances, double min_size_px)
{
	return accuracyTable(
		camera, scale, pose::constantNoise(sigma_px), "sigma_px " + fmt(sigma_px, 3), angle,
		distances, min_size_px);
}

std::string accuracyTable(
	const CameraModel& camera, double scale, const pose::PoseOptions& noise,
	const std::string& noise_label, double angle, const std::vector<double>& distances,
	double min_size_px)
{
	const LandmarkGeometry g = LandmarkGeometry::scaled(scale);
	std::ostringstream s;
	s << "# landmark scale " << fmt(scale, 3) << " (reference square "
	  << fmt(g.inner_size_m * 1000, 1) << " mm), view angle " << fmt(angle * 180 / M_PI, 1)
	  << " deg, " << noise_label << ", camera " << camera.width() << "x" << camera.height()
	  << " fx " << fmt(camera.fx(), 1) << "; 1-sigma values\n";
	s << "# dist_m  size_px  l2_mm  phi1_deg  phi2_deg  pos_mm  heading_deg  usable\n";
	for (const double d : distances)
	{
		const pose::SightingUncertainty u = pose::predictUncertainty(camera, g, noise, d, angle);
		s << std::setw(8) << fmt(d, 2);
		if (u.measurement.L[0] <= 0)
		{
			s << "  (not in front of the camera)\n";
			continue;
		}
		s << std::setw(9) << fmt(u.size_px, 1) << std::setw(7) << fmt(u.sigma_l2_m * 1000, 2)
		  << std::setw(10) << fmt(u.sigma_phi1_rad * 180 / M_PI, 4) << std::setw(10)
		  << fmt(u.sigma_phi2_rad * 180 / M_PI, 3) << std::setw(8)
		  << fmt(u.sigma_position_m * 1000, 1) << std::setw(13)
		  << fmt(u.sigma_heading_rad * 180 / M_PI, 3) << "  "
		  << (!u.in_image				? "no (not in image)"
			  : u.size_px < min_size_px ? "no (too small)"
										: "yes")
		  << "\n";
	}
	return s.str();
}

}  // namespace codemark::eval
