/** \file bench_camera.cpp
 * codemark-bench-camera: the detector and the shipped C_P on the POV-Ray
 * single-landmark set (scripts/povray-sets.sh, docs/povray.md) per image
 * source and camera preset (docs/camera-pipeline.md): the set's cached
 * linear POV-Ray renders, and the project's renderer at the same poses with
 * the same scene keys, each through every preset. For each
 * source and preset it reports the detection rate, the corner error and the
 * signed size error of the reference square per distance, the range, phi2
 * and position errors, and the mean NEES of C_R with its chi-square band,
 * as a Markdown report (scripts/bench-camera.sh writes
 * docs/benchmarks/camera.md) and one CSV row per frame.
 */
#include <codemark/landmark/camera.h>
#include <codemark/pipeline/pipeline.h>
#include <codemark/sim/camera_pipeline.h>
#include <codemark/sim/frames.h>
#include <codemark/sim/povray.h>
#include <codemark/sim/render.h>
#include <mrpt/config/CConfigFile.h>
#include <opencv2/imgcodecs.hpp>
#include <mrpt/math/distributions.h>
#include <tclap/CmdLine.h>

#include "progress.h"

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

using namespace codemark;

namespace
{
constexpr double kDeg = M_PI / 180;
/** The targets' population: the square spans at least this, seen at most
 * 60 degrees off the normal. */
constexpr double kMinSidePx = 30;
constexpr double kMaxViewDeg = 60;
/** chi2inv(0.999, 3): a sighting beyond it is a 1-in-1000 event if honest. */
const double kNeesTail = mrpt::math::chi2inv(0.999, 3);

namespace fs = std::filesystem;

/** One frame of the set: a group's pose, its scene keys and its linear
 * POV-Ray render. */
struct SetFrame
{
	std::string group;	// "<light>-<print>", e.g. dim-fluorescent
	std::string light, print;
	int index = 0;	// within the group
	mrpt::poses::CPose3D world_T_camera;
	sim::RenderOptions scene;  // the group's scene keys (set.ini)
	std::string linear_png;	 // POV-Ray's 16-bit linear render
	uint64_t seed = 0;	// the camera pipeline's noise
	double distance_m = 0, view_angle_rad = 0;	// from the truth
};

/** The landmark map of the set (one landmark). */
LandmarkMap setMap(const fs::path& dir)
{
	const fs::path p = dir / "map.txt";
	if (!fs::exists(p)) throw std::runtime_error(p.string() + ": missing (not a set directory)");
	return LandmarkMap::load(p.string());
}

/** The frames of every group of the set in \a dir (scripts/povray-sets.sh's
 * DIR/PRESET/single), groups in name order. */
std::vector<SetFrame> loadSet(const fs::path& dir, const sim::Scene& base)
{
	std::vector<fs::path> groups;
	for (const auto& e : fs::directory_iterator(dir))
		if (e.is_directory() && fs::exists(e.path() / "poses.txt")) groups.push_back(e.path());
	std::sort(groups.begin(), groups.end());
	if (groups.empty())
		throw std::runtime_error(dir.string() + ": no group folders with poses.txt");
	std::vector<SetFrame> out;
	uint64_t g = 0;
	for (const auto& gdir : groups)
	{
		++g;
		const std::string name = gdir.filename().string();
		const auto dash = name.find('-');
		if (dash == std::string::npos)
			throw std::runtime_error(gdir.string() + ": group name is not LIGHT-PRINT");
		sim::RenderOptions scene;
		const fs::path ini = gdir / "set.ini";
		if (!fs::exists(ini)) throw std::runtime_error(ini.string() + ": missing");
		scene.loadFromConfigFile(mrpt::config::CConfigFile(ini.string()), "RENDER");
		const auto poses = sim::loadCameraPoses((gdir / "poses.txt").string());
		for (size_t i = 0; i < poses.size(); ++i)
		{
			SetFrame f;
			f.group = name;
			f.light = name.substr(0, dash);
			f.print = name.substr(dash + 1);
			f.index = static_cast<int>(i);
			f.world_T_camera = poses[i];
			f.scene = scene;
			char png[32];
			std::snprintf(png, sizeof png, "linear_%03zu.png", i);
			f.linear_png = (gdir / png).string();
			f.seed = g * 1000003ULL + i;
			sim::Scene sc = base;
			sc.world_T_camera = f.world_T_camera;
			const auto truth = sim::groundTruth(sc).at(0);
			f.distance_m = truth.sighting.L[0];
			f.view_angle_rad =
				std::atan2(truth.sighting.pose_in_landmark[1], truth.sighting.pose_in_landmark[0]);
			out.push_back(std::move(f));
		}
	}
	return out;
}

/** The project's renderer's light for a group's light name: the POV-Ray
 * levels' gains (dim 0.35, bright 1.6) and, for graded light, a gradient of
 * +-25% across the image. */
sim::RenderOptions ownLight(const SetFrame& f, sim::RenderOptions o)
{
	if (f.light == "dim") o.gain *= 0.35;
	if (f.light == "bright") o.gain *= 1.6;
	if (f.light == "gradient")
	{
		o.gradient = 0.5;
		o.gradient_angle_rad = 0.7 * f.index;
	}
	return o;
}

/** One frame's result. */
struct FrameResult
{
	SetFrame frame;
	double side_px = 0;	 // shortest side of the true reference square [px]
	bool eligible = false;	// side >= 30 px and view <= 60 deg
	bool detected = false;	// the landmark found with its ID
	int wrong_ids = 0;	// detections with another ID
	double corner_err_px = NAN;	 // mean of the four corners' distances
	double width_err_px = NAN, height_err_px = NAN;	 // measured minus true
	double range_err_rel = NAN;	 // (l2 - true) / true
	double phi2_err_rad = NAN;
	double pos_err_m = NAN;	 // planar position of the camera in frame L
	double nees = NAN;	// of C_R, 3 DoF
	double line_rms_px = NAN;  // the four line fits' RMS residual, averaged
	double corner_sigma_px = NAN;  // the detector's own corner sigma
	double noise_grey = NAN;  // the image noise the detector measured
	double bend_px = NAN, bend_se_px = NAN;	 // the bands' bend and its standard error
	/** Per side k (corner k to k + 1): the mean of its two corners' errors
	 * across the true side [px], positive outwards, and their difference
	 * (the far corner's less the near one's: the side's tilt); whether the
	 * true side runs more along u than v. */
	std::array<double, 4> side_offset_px{NAN, NAN, NAN, NAN}, side_tilt_px{NAN, NAN, NAN, NAN};
	std::array<bool, 4> side_horizontal{};
	/** The error of the left side's height less the right side's [px]: what
	 * phi2 reads near face-on. */
	double height_diff_err_px = NAN;
};

double wrapPi(double a) { return std::atan2(std::sin(a), std::cos(a)); }

double sideLengths(const std::array<Eigen::Vector2d, 4>& c, double* width, double* height)
{
	// TL TR BR BL: top and bottom edges give the width, left and right the height.
	*width = 0.5 * ((c[1] - c[0]).norm() + (c[2] - c[3]).norm());
	*height = 0.5 * ((c[3] - c[0]).norm() + (c[2] - c[1]).norm());
	return std::min(
		std::min((c[1] - c[0]).norm(), (c[2] - c[3]).norm()),
		std::min((c[3] - c[0]).norm(), (c[2] - c[1]).norm()));
}

FrameResult evaluate(
	const SetFrame& f, const sim::Render& r, const CameraModel& camera,
	const pipeline::PipelineOptions& popt, int id)
{
	FrameResult out;
	out.frame = f;
	const sim::LandmarkTruth& t = r.truth.at(0);
	double w_true = 0, h_true = 0;
	out.side_px = sideLengths(t.corners_px, &w_true, &h_true);
	out.eligible = out.side_px >= kMinSidePx && std::abs(f.view_angle_rad) <= kMaxViewDeg * kDeg;
	const pipeline::ImageResult res = pipeline::processImage(r.image, camera, popt);
	for (const auto& m : res.landmarks)
	{
		if (m.detected.detection.id != id)
		{
			++out.wrong_ids;
			continue;
		}
		if (out.detected) continue;
		out.detected = true;
		const auto& c = m.detected.detection.corners;
		double sum = 0;
		for (int k = 0; k < 4; ++k) sum += (c[k] - t.corners_px[k]).norm();
		out.corner_err_px = sum / 4;
		const DetectionQuality& q = m.detected.detection.quality;
		out.line_rms_px =
			0.25 * (q.line_rms_px[0] + q.line_rms_px[1] + q.line_rms_px[2] + q.line_rms_px[3]);
		out.corner_sigma_px = q.corner_sigma_px;
		out.noise_grey = q.image_noise_grey;
		out.bend_px = q.edge_bend_px;
		out.bend_se_px = q.edge_bend_se_px;
		double w = 0, h = 0;
		sideLengths(c, &w, &h);
		out.width_err_px = w - w_true;
		out.height_err_px = h - h_true;
		const Eigen::Vector2d centre =
			0.25 * (t.corners_px[0] + t.corners_px[1] + t.corners_px[2] + t.corners_px[3]);
		for (int k = 0; k < 4; ++k)
		{
			const Eigen::Vector2d &a = t.corners_px[k], &b = t.corners_px[(k + 1) % 4];
			const Eigen::Vector2d dir = (b - a).normalized();
			Eigen::Vector2d normal(-dir.y(), dir.x());
			if (normal.dot(0.5 * (a + b) - centre) < 0) normal = -normal;
			const double ea = normal.dot(c[k] - a), eb = normal.dot(c[(k + 1) % 4] - b);
			out.side_offset_px[k] = 0.5 * (ea + eb);
			out.side_tilt_px[k] = eb - ea;
			out.side_horizontal[k] = std::abs(dir.x()) > std::abs(dir.y());
		}
		const auto heightDiff = [](const std::array<Eigen::Vector2d, 4>& q)
		{ return (q[3] - q[0]).norm() - (q[2] - q[1]).norm(); };
		out.height_diff_err_px = heightDiff(c) - heightDiff(t.corners_px);
		const pose::Measurement& me = m.measurement;
		const Eigen::Vector3d& L = t.sighting.L;
		out.range_err_rel = (me.L[0] - L[0]) / L[0];
		out.phi2_err_rad = wrapPi(me.L[2] - L[2]);
		Eigen::Vector3d e = me.pose_in_landmark - t.sighting.pose_in_landmark;
		e[2] = wrapPi(e[2]);
		out.pos_err_m = e.head<2>().norm();
		const Eigen::LDLT<Eigen::Matrix3d> ldlt(me.C_R);
		if (ldlt.info() == Eigen::Success && ldlt.isPositive()) out.nees = e.dot(ldlt.solve(e));
	}
	return out;
}

/** Statistics of a group of frames. */
struct Group
{
	int frames = 0, eligible = 0, eligible_detected = 0, detected = 0, wrong_ids = 0;
	std::vector<double> corner, width, height, range, phi2, pos, nees;

	void add(const FrameResult& r)
	{
		++frames;
		wrong_ids += r.wrong_ids;
		if (r.eligible)
		{
			++eligible;
			eligible_detected += r.detected;
		}
		if (!r.detected) return;
		++detected;
		// The errors count where the detector's limits hold (the landmark
		// spans >= 30 px, seen <= 60 deg off its normal).
		if (!r.eligible) return;
		corner.push_back(r.corner_err_px);
		width.push_back(r.width_err_px);
		height.push_back(r.height_err_px);
		range.push_back(r.range_err_rel);
		phi2.push_back(r.phi2_err_rad);
		pos.push_back(r.pos_err_m);
		if (std::isfinite(r.nees)) nees.push_back(r.nees);
	}
};

double mean(const std::vector<double>& v)
{
	if (v.empty()) return NAN;
	double s = 0;
	for (double x : v) s += x;
	return s / v.size();
}

double rms(const std::vector<double>& v)
{
	if (v.empty()) return NAN;
	double s = 0;
	for (double x : v) s += x * x;
	return std::sqrt(s / v.size());
}

double median(std::vector<double> v)
{
	if (v.empty()) return NAN;
	std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
	return v[v.size() / 2];
}

double tailShare(const std::vector<double>& v)
{
	if (v.empty()) return NAN;
	return double(std::count_if(v.begin(), v.end(), [](double x) { return x > kNeesTail; })) /
		   v.size();
}

/** The 95% band of the mean of n independent chi-square(3) draws. */
std::pair<double, double> band(size_t n)
{
	if (n == 0) return {NAN, NAN};
	const double dof = 3.0 * n;
	return {mrpt::math::chi2inv(0.025, dof) / n, mrpt::math::chi2inv(0.975, dof) / n};
}

std::string fmt(double v, int digits)
{
	if (!std::isfinite(v)) return "-";
	char b[64];
	std::snprintf(b, sizeof b, "%.*f", digits, v);
	return b;
}

std::string neesCell(const std::vector<double>& v)
{
	if (v.empty()) return "-";
	const auto [lo, hi] = band(v.size());
	const double m = mean(v);
	const bool in = m >= lo && m <= hi;
	return fmt(m, 2) + (in ? "" : (m > hi ? " (high)" : " (low)")) + " [" + fmt(lo, 2) + ", " +
		   fmt(hi, 2) + "]";
}

struct Bin
{
	const char* name;
	double lo, hi;
};
const Bin kBins[] = {
	{"0.5-1 m", 0.5, 1}, {"1-2 m", 1, 2}, {"2-3 m", 2, 3}, {"3-4 m", 3, 4}, {"4-5 m", 4, 5.01}};

struct Run
{
	std::string source, preset;
	std::vector<FrameResult> frames;
};

Group groupOf(const Run& run, double lo, double hi)
{
	Group g;
	for (const auto& r : run.frames)
		if (r.frame.distance_m >= lo && r.frame.distance_m < hi) g.add(r);
	return g;
}

/** NEES conditioned on what the detector measures: each source and
 * preset's frames (eligible, detected, bands measured) split at their
 * median standard error of the bands' bend. A C_P honest per detection,
 * not only per camera, keeps both halves in their bands. */
void writeScatterHalves(std::ostream& os, const std::vector<Run>& runs)
{
	os << "### NEES by the bands' scatter\n\n"
	   << "The same frames (bands measured) split at each row's median standard error of "
		  "the bands' bend (`edge_bend_se_px`): mean NEES of C_R with its band per half. A C_P "
		  "that follows each detection's scatter keeps both halves in band; a constant one "
		  "reads higher in the noisier half.\n\n"
	   << "| source | preset | frames | median se [px] | NEES, se below | NEES, se above |\n"
	   << "| --- | --- | --- | --- | --- | --- |\n";
	for (const auto& run : runs)
	{
		std::vector<std::pair<double, double>> se_nees;
		for (const auto& r : run.frames)
			if (r.eligible && r.detected && r.bend_se_px > 0 && std::isfinite(r.nees))
				se_nees.emplace_back(r.bend_se_px, r.nees);
		std::sort(se_nees.begin(), se_nees.end());
		const size_t half = se_nees.size() / 2;
		std::vector<double> lo, hi;
		for (size_t i = 0; i < se_nees.size(); ++i)
			(i < half ? lo : hi).push_back(se_nees[i].second);
		os << "| " << run.source << " | " << run.preset << " | " << se_nees.size() << " | "
		   << fmt(se_nees.empty() ? NAN : se_nees[half].first, 3) << " | " << neesCell(lo) << " | "
		   << neesCell(hi) << " |\n";
	}
	os << "\n";
}

/** The sides' errors split by their direction in the image. Near face-on
 * phi2 reads the difference of the left and right sides' heights, that
 * is the top and bottom sides' tilts; an edge error that depends on where
 * the edge falls in the pixel grid (the mosaic's period, JPEG's 8-px
 * blocks) is one offset along a side that follows a column exactly, and
 * a tilt along one that rises by part of a period. */
void writeSideErrors(std::ostream& os, const std::vector<Run>& runs)
{
	os << "### Side errors along rows and columns\n\n"
	   << "The same frames (eligible, detected): each side's error across it from its two "
		  "corners' errors, as the RMS of their mean (offset, positive outwards) and of their "
		  "difference (tilt, the far end's less the near one's), for the sides that run more "
		  "along the image's rows (top and bottom) and along its columns (left and right); and "
		  "the RMS error of the left side's height less the right side's, which phi2 reads near "
		  "face-on.\n\n"
	   << "| source | preset | frames | rows: offset / tilt RMS [px] | columns: offset / tilt "
		  "RMS [px] | height difference RMS [px] |\n"
	   << "| --- | --- | --- | --- | --- | --- |\n";
	for (const auto& run : runs)
	{
		std::array<std::vector<double>, 2> offset, tilt;
		std::vector<double> height_diff;
		for (const auto& r : run.frames)
		{
			if (!r.eligible || !r.detected) continue;
			height_diff.push_back(r.height_diff_err_px);
			for (int k = 0; k < 4; ++k)
			{
				const int i = r.side_horizontal[k] ? 0 : 1;
				offset[i].push_back(r.side_offset_px[k]);
				tilt[i].push_back(r.side_tilt_px[k]);
			}
		}
		os << "| " << run.source << " | " << run.preset << " | " << height_diff.size() << " | "
		   << fmt(rms(offset[0]), 3) << " / " << fmt(rms(tilt[0]), 3) << " | "
		   << fmt(rms(offset[1]), 3) << " / " << fmt(rms(tilt[1]), 3) << " | "
		   << fmt(rms(height_diff), 3) << " |\n";
	}
	os << "\n";
}

void writeReport(
	std::ostream& os, const std::vector<Run>& runs, const std::string& header,
	const std::string& camera_desc)
{
	os << header;
	os << "## Overview\n\n"
	   << "Detected: frames whose reference square spans >= 30 px and is seen <= 60 deg off "
		  "its normal, found with their ID. Errors and NEES over those frames detected: range and "
		  "phi2 RMS, "
		  "position RMS of the camera in the landmark frame; NEES: mean of C_R's normalised "
		  "squared error (3 DoF) with the 95% chi-square band of independent frames.\n\n"
	   << "| source | preset | detected | wrong IDs | corner err [px] | size err w / h [px] | "
		  "range <2 m [%] | range 2-5 m [%] | phi2 <2 m [deg] | phi2 2-5 m [deg] | NEES <2 m | "
		  "NEES 2-5 m | > 16.27 |\n"
	   << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
	for (const auto& run : runs)
	{
		const Group all = groupOf(run, 0, 100), near = groupOf(run, 0, 2),
					far = groupOf(run, 2, 100);
		os << "| " << run.source << " | " << run.preset << " | " << all.eligible_detected << " / "
		   << all.eligible << " ("
		   << fmt(all.eligible ? 100.0 * all.eligible_detected / all.eligible : NAN, 1) << "%) | "
		   << all.wrong_ids << " | " << fmt(mean(all.corner), 3) << " | " << fmt(mean(all.width), 3)
		   << " / " << fmt(mean(all.height), 3) << " | " << fmt(100 * rms(near.range), 3) << " | "
		   << fmt(100 * rms(far.range), 3) << " | " << fmt(rms(near.phi2) / kDeg, 3) << " | "
		   << fmt(rms(far.phi2) / kDeg, 3) << " | " << neesCell(near.nees) << " | "
		   << neesCell(far.nees) << " | " << fmt(100 * tailShare(all.nees), 1) << "% |\n";
	}
	os << "\n";
	writeScatterHalves(os, runs);
	writeSideErrors(os, runs);
	for (const auto& run : runs)
	{
		os << "## " << run.source << ", preset " << run.preset << "\n\n"
		   << "| distance | frames | detected (eligible) | corner err [px] | width err [px] | "
			  "height err [px] | range err mean / RMS [%] | phi2 RMS [deg] | position RMS [mm] | "
			  "NEES mean [band] | NEES median | > 16.27 |\n"
		   << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
		for (const auto& b : kBins)
		{
			const Group g = groupOf(run, b.lo, b.hi);
			os << "| " << b.name << " | " << g.frames << " | " << g.eligible_detected << " / "
			   << g.eligible << " | " << fmt(mean(g.corner), 3) << " | " << fmt(mean(g.width), 3)
			   << " | " << fmt(mean(g.height), 3) << " | " << fmt(100 * mean(g.range), 3) << " / "
			   << fmt(100 * rms(g.range), 3) << " | " << fmt(rms(g.phi2) / kDeg, 3) << " | "
			   << fmt(1000 * rms(g.pos), 1) << " | " << neesCell(g.nees) << " | "
			   << fmt(median(g.nees), 2) << " | " << fmt(100 * tailShare(g.nees), 1) << "% |\n";
		}
		// Detection per light and print: where misses come from.
		std::map<std::string, Group> by;
		for (const auto& r : run.frames)
		{
			by["light " + r.frame.light].add(r);
			by["print " + r.frame.print].add(r);
		}
		os << "\n| condition | detected (eligible) | corner err [px] | NEES mean |\n"
		   << "| --- | --- | --- | --- |\n";
		for (const auto& [name, g] : by)
			os << "| " << name << " | " << g.eligible_detected << " / " << g.eligible << " | "
			   << fmt(mean(g.corner), 3) << " | " << fmt(mean(g.nees), 2) << " |\n";
		os << "\n";
	}
	os << "Camera: " << camera_desc << ".\n";
}

void writeCsv(const std::string& path, const std::vector<Run>& runs)
{
	std::ofstream os(path);
	if (!os) throw std::runtime_error(path + ": cannot write");
	os << "source,preset,group,index,distance_m,view_deg,light,print,side_px,"
		  "eligible,detected,wrong_ids,corner_err_px,width_err_px,height_err_px,range_err_rel,"
		  "phi2_err_deg,pos_err_m,nees,line_rms_px,corner_sigma_px,noise_grey,bend_px,"
		  "bend_se_px\n";
	for (const auto& run : runs)
		for (const auto& r : run.frames)
		{
			const auto& f = r.frame;
			os << run.source << "," << run.preset << "," << f.group << "," << f.index << ","
			   << f.distance_m << "," << f.view_angle_rad / kDeg << "," << f.light << "," << f.print
			   << "," << r.side_px << "," << r.eligible << "," << r.detected << "," << r.wrong_ids
			   << "," << r.corner_err_px << "," << r.width_err_px << "," << r.height_err_px << ","
			   << r.range_err_rel << "," << r.phi2_err_rad / kDeg << "," << r.pos_err_m << ","
			   << r.nees << "," << r.line_rms_px << "," << r.corner_sigma_px << "," << r.noise_grey
			   << "," << r.bend_px << "," << r.bend_se_px << "\n";
		}
}

std::vector<std::string> splitList(const std::vector<std::string>& args)
{
	std::vector<std::string> out;
	for (const auto& a : args)
	{
		std::stringstream ss(a);
		for (std::string t; std::getline(ss, t, ',');)
			if (!t.empty()) out.push_back(t);
	}
	return out;
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd(
			"The detector and the shipped C_P on the single-landmark set, per image source and "
			"camera preset: detection rate, corner and signed square-size errors per distance, "
			"range / phi2 / position errors, mean NEES of C_R with its chi-square band. Writes a "
			"Markdown report (--out, else stdout) and one CSV row per frame (--csv).",
			' ', "0.1");
		TCLAP::MultiArg<std::string> sourceArg(
			"", "source",
			"image source: own (the project's renderer) or povray (POV-Ray 3.7, cached linear "
			"renders); repeatable or comma-separated (default own)",
			false, "own|povray", cmd);
		TCLAP::MultiArg<std::string> presetArg(
			"", "preset",
			"camera preset (linear, machine-vision, webcam, phone, family); repeatable or "
			"comma-separated (default linear,webcam,phone,family)",
			false, "NAME", cmd);
		TCLAP::ValueArg<std::string> setArg(
			"", "set",
			"the single-landmark set: a folder of scripts/povray-sets.sh (DIR/PRESET/single; any "
			"preset's, the linear renders are the same) with map.txt and one folder per group",
			true, "", "DIR", cmd);
		TCLAP::ValueArg<std::string> outArg(
			"o", "out", "Markdown report", false, "", "FILE.md", cmd);
		TCLAP::ValueArg<std::string> csvArg(
			"", "csv",
			"per-frame CSV: the frame, its errors and NEES, and what the detector measured of "
			"the landmark (line_rms_px: the four line fits' RMS residual, averaged; "
			"corner_sigma_px: the corner sigma the line fits give; noise_grey: the image noise; "
			"bend_px, bend_se_px: the green bands' bend and its standard error, 0 when not "
			"measured)",
			false, "", "FILE.csv", cmd);
		TCLAP::ValueArg<std::string> revisionArg(
			"", "revision", "revision named in the report", false, "", "TEXT", cmd);
		TCLAP::ValueArg<int> threadsArg(
			"j", "threads", "worker threads (default 2)", false, 2, "N", cmd);
		TCLAP::SwitchArg quietArg("q", "quiet", "no progress on stderr", cmd);
		TCLAP::ValueArg<std::string> configArg(
			"", "config",
			"detector parameters: an ini file with a [DETECTOR] section (default: the shipped "
			"defaults)",
			false, "", "detector.ini", cmd);
		TCLAP::ValueArg<std::string> calibrationArg(
			"", "calibration",
			"C_P's calibration: a file (docs/calibration.md) or a shipped calibration's name "
			"(default: the tools' default)",
			false, pipeline::kDefaultCalibration, "FILE|NAME", cmd);
		TCLAP::ValueArg<std::string> missesArg(
			"", "misses",
			"folder (created when missing) that receives the image of every eligible frame "
			"not detected, as SOURCE-PRESET-GROUP-INDEX.png",
			false, "", "DIR", cmd);
		cmd.parse(argc, argv);

		auto sources = splitList(sourceArg.getValue());
		if (sources.empty()) sources = {"own"};
		auto presets = splitList(presetArg.getValue());
		if (presets.empty()) presets = {"linear", "webcam", "phone", "family"};
		for (const auto& s : sources)
			if (s != "own" && s != "povray")
				throw std::invalid_argument("--source must be own or povray, got '" + s + "'");
		for (const auto& p : presets) (void)sim::RenderOptions::presetKeys(p);
		const int threads = std::max(1, threadsArg.getValue());

		const fs::path set_dir = setArg.getValue();
		if (!fs::is_directory(set_dir))
			throw std::runtime_error(set_dir.string() + ": not a folder");
		sim::Scene base;
		base.map = setMap(set_dir);
		if (base.map.landmarks.size() != 1)
			throw std::runtime_error((set_dir / "map.txt").string() + ": expected one landmark");
		const int id = base.map.landmarks[0].id;
		for (const auto& e : fs::directory_iterator(set_dir))
			if (e.is_directory() && fs::exists(e.path() / "camera.ini"))
			{
				base.camera = CameraModel::load((e.path() / "camera.ini").string());
				break;
			}
		const CameraModel& camera = base.camera;
		const auto set = loadSet(set_dir, base);
		pipeline::PipelineOptions popt;
		popt.pose = pipeline::calibratedPoseOptions(calibrationArg.getValue());
		if (configArg.isSet()) popt.detector = detect::DetectorOptions::load(configArg.getValue());
		if (missesArg.isSet()) fs::create_directories(missesArg.getValue());

		std::vector<Run> runs;
		const auto t0 = std::chrono::steady_clock::now();
		const size_t total = sources.size() * presets.size() * set.size();
		long done = 0;
		app::ProgressBar bar("codemark-bench-camera", !quietArg.getValue());
		for (const auto& source : sources)
		{
			for (const auto& preset : presets)
			{
				Run run{source, preset, std::vector<FrameResult>(set.size())};
				std::vector<std::thread> pool;
				std::atomic<size_t> next{0};
				std::mutex progress_mutex;
				std::exception_ptr failure;
				for (int w = 0; w < threads; ++w)
					pool.emplace_back(
						[&]()
						{
							for (size_t i; (i = next++) < set.size();)
							{
								try
								{
									const SetFrame& f = set[i];
									sim::Scene scene = base;
									scene.world_T_camera = f.world_T_camera;
									// The group's scene keys, then the preset's camera.
									sim::RenderOptions o = f.scene;
									o.applyPreset(preset);
									sim::Render r;
									if (source == "own")
										r = sim::render(scene, ownLight(f, o), f.seed);
									else
									{
										cv::Mat linear = sim::readLinearPng(f.linear_png);
										r.image = sim::cameraImage(
											linear, o.drawn(f.seed), camera.cx(), camera.cy(),
											f.seed);
										r.truth = sim::groundTruth(scene);
									}
									run.frames[i] = evaluate(f, r, camera, popt, id);
									if (missesArg.isSet() && run.frames[i].eligible &&
										!run.frames[i].detected)
									{
										const std::string name = source + "-" + preset + "-" +
																 f.group + "-" +
																 std::to_string(f.index) + ".png";
										cv::imwrite(
											(fs::path(missesArg.getValue()) / name).string(),
											r.image);
									}
								}
								catch (...)
								{
									std::lock_guard<std::mutex> lock(progress_mutex);
									if (!failure) failure = std::current_exception();
									next = set.size();
								}
								std::lock_guard<std::mutex> lock(progress_mutex);
								bar.update(++done, static_cast<long>(total));
							}
						});
				for (auto& t : pool) t.join();
				if (failure) std::rethrow_exception(failure);
				runs.push_back(std::move(run));
			}
		}
		bar.finish();
		const double secs =
			std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

		std::ostringstream header;
		const std::time_t now = std::time(nullptr);
		char date[32];
		std::strftime(date, sizeof date, "%Y-%m-%d", std::gmtime(&now));
		header << "# Per-camera benchmark: the detector and C_P per image source and preset\n\n"
			   << "Generated by `scripts/bench-camera.sh` (bench/camera, codemark-bench-camera) on "
			   << date;
		if (!revisionArg.getValue().empty()) header << ", " << revisionArg.getValue();
		header << "; " << fmt(secs, 0) << " s on " << threads << " threads.\n\n"
			   << "The POV-Ray single-landmark set (scripts/povray-sets.sh, docs/povray.md): "
			   << set.size()
			   << " frames, 0.5-5 m, 0-60 deg off the normal, several image positions, camera "
				  "above and below the landmark centre, dim / normal / bright / graded light, "
				  "fluorescent paper and office-printer greens. Source `povray`: the set's linear "
				  "POV-Ray renders; source `own`: the project's renderer at the same poses with "
				  "the same scene keys (dim 0.35x and bright 1.6x light as gains, graded light "
				  "as a +-25% gradient across the image). Each preset is the camera pipeline of "
				  "docs/camera-pipeline.md, applied to both. The detector is the shipped "
				  "default; C_P comes from the calibration `"
			   << calibrationArg.getValue() << "` (docs/calibration.md).\n\n";
		std::ostringstream cam;
		cam << camera.width() << " x " << camera.height() << " px, fx = " << camera.fx() << " px";
		if (outArg.isSet())
		{
			std::ofstream os(outArg.getValue());
			if (!os) throw std::runtime_error(outArg.getValue() + ": cannot write");
			writeReport(os, runs, header.str(), cam.str());
		}
		else
			writeReport(std::cout, runs, header.str(), cam.str());
		if (csvArg.isSet()) writeCsv(csvArg.getValue(), runs);
		return 0;
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << "codemark-bench-camera: " << e.error() << " (" << e.argId() << ")\n";
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-bench-camera: " << e.what() << "\n";
	}
	return 1;
}
