// The rawlog stepper: both formats, streaming, one step per camera frame,
// odometry interpolated to the frame's time in the observations-only format.
#include <codemark/filters/stepper.h>
#include <codemark/pose/closed_form.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/math/wrap2pi.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationBearingRange.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <stdexcept>

namespace codemark::filters
{
using mrpt::obs::CObservation;
using mrpt::poses::CPose2D;

void StepperOptions::loadFromConfigFile(
	const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	// Read by name here: MRPT 2.5.8 does not export the enum's TEnumType filler.
	const std::string model = c.read_string(
		s, "modelSelection",
		motion.modelSelection == mrpt::obs::CActionRobotMovement2D::mmGaussian ? "mmGaussian"
																			   : "mmThrun");
	if (model == "mmGaussian")
		motion.modelSelection = mrpt::obs::CActionRobotMovement2D::mmGaussian;
	else if (model == "mmThrun")
		motion.modelSelection = mrpt::obs::CActionRobotMovement2D::mmThrun;
	else
		throw std::invalid_argument(
			"[" + s + "] modelSelection: '" + model + "' (expected mmGaussian or mmThrun)");
	motion.gaussianModel.a1 = c.read_float(s, "gaussianModel.a1", motion.gaussianModel.a1);
	motion.gaussianModel.a2 = c.read_float(s, "gaussianModel.a2", motion.gaussianModel.a2);
	motion.gaussianModel.a3 = c.read_float(s, "gaussianModel.a3", motion.gaussianModel.a3);
	motion.gaussianModel.a4 = c.read_float(s, "gaussianModel.a4", motion.gaussianModel.a4);
	motion.gaussianModel.minStdXY =
		c.read_float(s, "gaussianModel.minStdXY", motion.gaussianModel.minStdXY);
	motion.gaussianModel.minStdPHI =
		c.read_float(s, "gaussianModel.minStdPHI", motion.gaussianModel.minStdPHI);
	motion.thrunModel.alfa1_rot_rot =
		c.read_float(s, "thrunModel.alfa1_rot_rot", motion.thrunModel.alfa1_rot_rot);
	motion.thrunModel.alfa2_rot_trans =
		c.read_float(s, "thrunModel.alfa2_rot_trans", motion.thrunModel.alfa2_rot_trans);
	motion.thrunModel.alfa3_trans_trans =
		c.read_float(s, "thrunModel.alfa3_trans_trans", motion.thrunModel.alfa3_trans_trans);
	motion.thrunModel.alfa4_trans_rot =
		c.read_float(s, "thrunModel.alfa4_trans_rot", motion.thrunModel.alfa4_trans_rot);
	motion.thrunModel.additional_std_XY =
		c.read_float(s, "thrunModel.additional_std_XY", motion.thrunModel.additional_std_XY);
	motion.thrunModel.additional_std_phi =
		c.read_float(s, "thrunModel.additional_std_phi", motion.thrunModel.additional_std_phi);
	MRPT_LOAD_CONFIG_VAR(detect_images, bool, c, s);
	MRPT_LOAD_CONFIG_VAR(max_view_angle_deg, double, c, s);
	MRPT_LOAD_CONFIG_VAR(remeasure_sightings, bool, c, s);
	if (!(max_view_angle_deg > 0))
		throw std::invalid_argument("[" + s + "] max_view_angle_deg: must be > 0 [deg]");
}

void StepperOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	c.write(
		s, "modelSelection",
		motion.modelSelection == mrpt::obs::CActionRobotMovement2D::mmGaussian ? "mmGaussian"
																			   : "mmThrun",
		-1, -1);
	c.write(s, "gaussianModel.a1", motion.gaussianModel.a1, -1, -1);
	c.write(s, "gaussianModel.a2", motion.gaussianModel.a2, -1, -1);
	c.write(s, "gaussianModel.a3", motion.gaussianModel.a3, -1, -1);
	c.write(s, "gaussianModel.a4", motion.gaussianModel.a4, -1, -1);
	c.write(s, "gaussianModel.minStdXY", motion.gaussianModel.minStdXY, -1, -1);
	c.write(s, "gaussianModel.minStdPHI", motion.gaussianModel.minStdPHI, -1, -1);
	c.write(s, "detect_images", detect_images, -1, -1);
	c.write(s, "max_view_angle_deg", max_view_angle_deg, -1, -1);
	c.write(s, "remeasure_sightings", remeasure_sightings, -1, -1);
}

ReadingOptions readingOptions(
	const mrpt::config::CConfigFileBase& cfg, const std::string& calibration,
	const std::optional<LandmarkMap>& map)
{
	ReadingOptions o;
	o.stepper.loadFromConfigFile(cfg, "stepper");
	o.pipeline.detector.loadFromConfigFile(cfg, "detector");
	if (!calibration.empty())
	{
		o.pipeline.pose = pipeline::calibratedPoseOptions(calibration);
		o.stepper.remeasure_sightings = true;
	}
	o.pipeline.pose.loadFromConfigFile(cfg, "pose");
	o.pipeline.map = map;
	return o;
}

CPose2D interpolatePose(double t0, const CPose2D& p0, double t1, const CPose2D& p1, double t)
{
	if (!(t1 > t0)) return t >= t1 ? p1 : p0;
	const double a = std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
	const double dyaw = mrpt::math::wrapToPi(p1.phi() - p0.phi());
	return CPose2D(
		p0.x() + a * (p1.x() - p0.x()), p0.y() + a * (p1.y() - p0.y()),
		mrpt::math::wrapToPi(p0.phi() + a * dyaw));
}

namespace
{
bool isCameraFrameObservation(const CObservation& o)
{
	return dynamic_cast<const mrpt::obs::CObservationImage*>(&o) ||
		   dynamic_cast<const CObservationCodedLandmarks*>(&o) ||
		   dynamic_cast<const mrpt::obs::CObservationBearingRange*>(&o);
}

// A camera frame waiting for its odometry (observations-only format).
struct Frame
{
	mrpt::Clock::time_point stamp = INVALID_TIMESTAMP;
	long entry = 0;
	std::vector<CObservation::Ptr> obs;
};
}  // namespace

struct RawlogStepper::Impl
{
	std::string path;
	StepperOptions opt;
	pipeline::PipelineOptions pipe;
	mrpt::io::CFileGZInputStream in;
	long total_bytes = 0;
	long entries = 0;
	long steps = 0;
	long actions_read = 0;	// CActionCollection entries so far
	bool eof = false;
	bool actions_observations = false;

	// Actions-observations: the motion since the last step.
	std::optional<mrpt::poses::CPosePDFGaussian> acc;

	// Observations-only.
	std::optional<Frame> open;	// frame still collecting observations
	std::deque<Frame> pending;	// closed frames waiting for odometry
	std::optional<std::pair<double, CPose2D>> last_odo;	 // latest reading (t, pose)
	std::optional<std::pair<double, CPose2D>> seg_start;  // start (t, pose) of the current segment
	bool had_frame_with_odometry = false;

	std::deque<RawlogStep> ready;

	std::string where(long entry) const { return path + ": entry #" + std::to_string(entry); }

	CObservation::Ptr read()
	{
		auto ar = mrpt::serialization::archiveFrom(in);
		mrpt::serialization::CSerializable::Ptr obj;
		try
		{
			obj = ar.ReadObject();
		}
		catch (const mrpt::serialization::CExceptionEOF&)
		{
			eof = true;
			return nullptr;
		}
		catch (const std::exception& e)
		{
			throw std::runtime_error(
				where(entries) +
				" cannot be read (truncated or corrupt file, or a class whose plugin is "
				"not loaded): " +
				mrpt::exception_to_str(e));
		}
		const long entry = entries++;
		if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj))
		{
			actions_observations = true;
			onSensoryFrame(*sf, entry);
		}
		else if (auto acts = std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(obj))
		{
			actions_observations = true;
			++actions_read;
			onActions(*acts, entry);
		}
		else if (auto o = std::dynamic_pointer_cast<CObservation>(obj))
			onObservation(o, entry);
		else
			throw std::runtime_error(
				where(entry) + " holds a '" + (obj ? obj->GetRuntimeClass()->className : "null") +
				"', which is not a rawlog entry (CSensoryFrame, CActionCollection or "
				"CObservation)");
		return nullptr;
	}

	void onActions(const mrpt::obs::CActionCollection& acts, long entry)
	{
		for (const auto& a : acts)
		{
			const auto* mv = dynamic_cast<const mrpt::obs::CActionRobotMovement2D*>(a.get());
			if (!mv || !mv->poseChange) continue;
			mrpt::poses::CPosePDFGaussian g;
			g.copyFrom(*mv->poseChange);
			if (!std::isfinite(g.mean.x()) || !std::isfinite(g.mean.y()) ||
				!std::isfinite(g.mean.phi()))
				throw std::runtime_error(
					where(entry) + ": odometry increment (CActionRobotMovement2D) is not finite: " +
					g.mean.asString());
			if (!g.cov.asEigen().allFinite())
				throw std::runtime_error(
					where(entry) +
					": odometry increment (CActionRobotMovement2D) has a non-finite covariance");
			if (!acc)
				acc = g;
			else
				*acc += g;
			break;	// one movement per collection
		}
	}

	mrpt::obs::CActionRobotMovement2D::Ptr actionFromPdf(const mrpt::poses::CPosePDFGaussian& g)
	{
		auto act = mrpt::obs::CActionRobotMovement2D::Create();
		act->poseChange = mrpt::poses::CPosePDFGaussian::Create(g);
		act->rawOdometryIncrementReading = g.mean;
		act->estimationMethod = mrpt::obs::CActionRobotMovement2D::emOdometry;
		act->motionModelConfiguration = opt.motion;
		return act;
	}

	void onSensoryFrame(const mrpt::obs::CSensoryFrame& sf, long entry)
	{
		Frame f;
		f.entry = entry;
		for (const auto& o : sf)
			if (o && isCameraFrameObservation(*o))
			{
				if (f.obs.empty()) f.stamp = o->timestamp;
				f.obs.push_back(o);
			}
		if (f.obs.empty()) return;	// no camera frame: its motion carries over
		mrpt::obs::CActionRobotMovement2D::Ptr odo;
		if (acc) odo = actionFromPdf(*acc);
		acc.reset();
		emit(f, odo);
	}

	// Observations-only: the motion model applies to each odometry interval
	// (reading to reading, as a robot's odometry accumulates its noise); a
	// part of an interval, cut at an image time, gets the model of its
	// increment with the covariance scaled by its share of the interval's
	// duration. The segments since the previous image are composed.
	void addSegment(const CPose2D& from, const CPose2D& to, double fraction)
	{
		mrpt::obs::CActionRobotMovement2D act;
		act.computeFromOdometry(to - from, opt.motion);
		mrpt::poses::CPosePDFGaussian g;
		g.copyFrom(*act.poseChange);
		g.cov *= std::clamp(fraction, 0.0, 1.0);
		if (!acc)
			acc = g;
		else
			*acc += g;
	}

	void onObservation(const CObservation::Ptr& o, long entry)
	{
		if (auto odo = std::dynamic_pointer_cast<mrpt::obs::CObservationOdometry>(o))
		{
			if (!std::isfinite(odo->odometry.x()) || !std::isfinite(odo->odometry.y()) ||
				!std::isfinite(odo->odometry.phi()))
				throw std::runtime_error(
					where(entry) + ": odometry reading (CObservationOdometry '" + odo->sensorLabel +
					"') is not finite: " + odo->odometry.asString());
			closeOpen();
			const double t = mrpt::Clock::toDouble(odo->timestamp);
			const double interval = last_odo ? t - last_odo->first : 0.0;
			// Every pending frame up to this reading's time gets the odometry
			// interpolated between the previous reading and this one.
			while (!pending.empty() && mrpt::Clock::toDouble(pending.front().stamp) <= t)
			{
				const double tf = mrpt::Clock::toDouble(pending.front().stamp);
				if (!last_odo)
				{
					emit(pending.front(), nullptr);	 // before any odometry
					pending.pop_front();
					continue;
				}
				const CPose2D p =
					interpolatePose(last_odo->first, last_odo->second, t, odo->odometry, tf);
				addSegment(
					seg_start->second, p, interval > 0 ? (tf - seg_start->first) / interval : 1.0);
				seg_start = {tf, p};
				emitAccumulated(pending.front());
				pending.pop_front();
			}
			if (last_odo)
				addSegment(
					seg_start->second, odo->odometry,
					interval > 0 ? (t - seg_start->first) / interval : 1.0);
			last_odo = {t, odo->odometry};
			seg_start = last_odo;
			return;
		}
		if (!isCameraFrameObservation(*o)) return;
		// A frame: consecutive camera observations with one timestamp, one per
		// sensor label (so that rawlogs without timestamps still split).
		if (open && (open->stamp != o->timestamp || std::any_of(
														open->obs.begin(), open->obs.end(),
														[&](const CObservation::Ptr& x) {
															return x->sensorLabel == o->sensorLabel;
														})))
			closeOpen();
		if (!open)
		{
			open = Frame();
			open->stamp = o->timestamp;
			open->entry = entry;
		}
		open->obs.push_back(o);
		open->entry = entry;
	}

	void closeOpen()
	{
		if (!open) return;
		pending.push_back(std::move(*open));
		open.reset();
	}

	// Observations-only: the frame with the motion accumulated since the
	// previous frame (null for the first frame after odometry started).
	void emitAccumulated(const Frame& f)
	{
		mrpt::obs::CActionRobotMovement2D::Ptr act;
		if (acc && had_frame_with_odometry) act = actionFromPdf(*acc);
		if (act) act->timestamp = f.stamp;
		acc.reset();
		had_frame_with_odometry = true;
		emit(f, act);
	}

	void finish()
	{
		closeOpen();
		while (!pending.empty())
		{
			// After the last reading: no later one to interpolate with; the
			// last reading is the best known odometry (no extrapolation).
			if (last_odo)
				emitAccumulated(pending.front());
			else
				emit(pending.front(), nullptr);
			pending.pop_front();
		}
	}

	// NaN or inf in a measurement the filters fuse: a clear error naming the
	// entry, never a silently wrong estimate.
	void checkFinite(const CObservation& o, long entry) const
	{
		if (const auto* c = dynamic_cast<const CObservationCodedLandmarks*>(&o))
		{
			for (std::size_t i = 0; i < c->sightings.size(); ++i)
			{
				const auto& t = c->sightings[i];
				const char* bad = !t.L.allFinite()					? "L"
								  : !t.C_L.allFinite()				? "C_L"
								  : !t.pose_in_landmark.allFinite() ? "pose_in_landmark"
								  : !t.C_R.allFinite()				? "C_R"
																	: nullptr;
				if (bad)
					throw std::runtime_error(
						where(entry) + " (" + o.sensorLabel + "): sighting #" + std::to_string(i) +
						" (ID " + std::to_string(t.id) + ") has a non-finite " + bad);
			}
		}
		else if (const auto* b = dynamic_cast<const mrpt::obs::CObservationBearingRange*>(&o))
		{
			for (std::size_t i = 0; i < b->sensedData.size(); ++i)
			{
				const auto& m = b->sensedData[i];
				const bool ok = std::isfinite(m.range) && std::isfinite(m.yaw) &&
								std::isfinite(m.pitch) &&
								(!b->validCovariances || m.covariance.asEigen().allFinite());
				if (!ok)
					throw std::runtime_error(
						where(entry) + " (" + o.sensorLabel + "): reading #" + std::to_string(i) +
						" (landmark ID " + std::to_string(m.landmarkID) +
						") has a non-finite range, yaw, pitch or covariance");
			}
		}
	}

	void emit(const Frame& f, const mrpt::obs::CActionRobotMovement2D::Ptr& odo)
	{
		RawlogStep s;
		s.index = steps++;
		s.entry = f.entry;
		s.actions = actions_observations ? actions_read : -1;
		s.has_timestamp = f.stamp != INVALID_TIMESTAMP;
		s.timestamp =
			s.has_timestamp ? mrpt::Clock::toDouble(f.stamp) : static_cast<double>(s.index);
		s.odometry = odo;
		// Labels that already have a landmark observation in this frame.
		std::vector<std::string> annotated;
		for (const auto& o : f.obs)
			if (dynamic_cast<const CObservationCodedLandmarks*>(o.get()))
				annotated.push_back(o->sensorLabel);
		for (const auto& o : f.obs)
		{
			checkFinite(*o, f.entry);
			if (auto img = std::dynamic_pointer_cast<mrpt::obs::CObservationImage>(o))
			{
				if (!opt.detect_images) continue;
				const std::string want = img->sensorLabel + "_LANDMARKS";
				if (std::find(annotated.begin(), annotated.end(), want) != annotated.end())
					continue;
				try
				{
					s.observations.insert(pipeline::observeImage(*img, pipe));
				}
				catch (const std::exception& e)
				{
					throw std::runtime_error(
						where(f.entry) + " (" + img->sensorLabel +
						"): " + mrpt::exception_to_str(e));
				}
				++s.images_detected;
			}
			else if (const auto c = std::dynamic_pointer_cast<CObservationCodedLandmarks>(o);
					 c && opt.remeasure_sightings)
			{
				try
				{
					s.observations.insert(pipeline::remeasure(*c, pipe));
				}
				catch (const std::exception& e)
				{
					throw std::runtime_error(
						where(f.entry) + " (" + c->sensorLabel + "): " + mrpt::exception_to_str(e));
				}
			}
			else
				s.observations.insert(o);
		}
		dropOblique(s);
		ready.push_back(std::move(s));
	}

	// Replaces coded observations that hold sightings beyond
	// max_view_angle_deg by copies without them.
	void dropOblique(RawlogStep& s) const
	{
		if (opt.max_view_angle_deg >= 90.0) return;
		const double max_rad = opt.max_view_angle_deg * M_PI / 180.0;
		auto oblique = [&](const CObservationCodedLandmarks::TSighting& t)
		{ return pose::viewAngle(t.L) > max_rad; };
		mrpt::obs::CSensoryFrame out;
		bool changed = false;
		for (const auto& o : s.observations)
		{
			const auto c = std::dynamic_pointer_cast<CObservationCodedLandmarks>(o);
			if (!c || std::none_of(c->sightings.begin(), c->sightings.end(), oblique))
			{
				out.insert(o);
				continue;
			}
			auto copy = std::make_shared<CObservationCodedLandmarks>(*c);
			const auto n = copy->sightings.size();
			copy->sightings.erase(
				std::remove_if(copy->sightings.begin(), copy->sightings.end(), oblique),
				copy->sightings.end());
			s.sightings_too_oblique += static_cast<int>(n - copy->sightings.size());
			out.insert(copy);
			changed = true;
		}
		if (changed) s.observations = std::move(out);
	}
};

RawlogStepper::RawlogStepper(
	const std::string& path, const StepperOptions& options, const pipeline::PipelineOptions& pipe)
	: impl_(std::make_unique<Impl>())
{
	impl_->path = path;
	impl_->opt = options;
	impl_->pipe = pipe;
	if (!std::filesystem::exists(path)) throw std::runtime_error(path + ": no such file");
	if (!impl_->in.open(path)) throw std::runtime_error(path + ": cannot open");
	impl_->total_bytes = static_cast<long>(impl_->in.getTotalBytesCount());
	if (impl_->total_bytes == 0) throw std::runtime_error(path + ": empty file, not a rawlog");
	// This rawlog's external images, not MRPT's process-wide folder (other
	// steppers may read other rawlogs at the same time).
	impl_->pipe.images_dir = pipeline::imagesDirectoryOf(path);
}

RawlogStepper::~RawlogStepper() = default;

bool RawlogStepper::next(RawlogStep& out)
{
	while (impl_->ready.empty())
	{
		if (impl_->eof) return false;
		impl_->read();
		if (impl_->eof) impl_->finish();
	}
	out = std::move(impl_->ready.front());
	impl_->ready.pop_front();
	return true;
}

double RawlogStepper::progress() const
{
	if (impl_->total_bytes <= 0) return 1.0;
	return std::min(1.0, static_cast<double>(impl_->in.getPosition()) / impl_->total_bytes);
}

long RawlogStepper::entriesRead() const { return impl_->entries; }
bool RawlogStepper::actionsObservationsFormat() const { return impl_->actions_observations; }

}  // namespace codemark::filters
