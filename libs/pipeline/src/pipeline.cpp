#include <codemark/pipeline/pipeline.h>
#include <codemark/pose/calibration.h>
#include <mrpt/img/CImage.h>

#include <opencv2/imgproc.hpp>

#include <chrono>
#include <mutex>
#include <stdexcept>

namespace codemark::pipeline
{
pose::PoseOptions calibratedPoseOptions(const std::string& path_or_name)
{
	pose::PoseOptions base;
	base.second_order_pose_covariance = true;
	if (path_or_name != kDefaultCalibration)
		return pose::loadCalibration(pose::resolveCalibration(path_or_name), base);
	// Every PipelineOptions starts from the default: read its file once.
	static std::mutex m;
	static std::optional<pose::PoseOptions> cached;
	const std::lock_guard<std::mutex> lock(m);
	if (!cached)
		cached = pose::loadCalibration(pose::shippedCalibrationPath(kDefaultCalibration), base);
	return *cached;
}

LandmarkGeometry geometryFor(int id, const PipelineOptions& o)
{
	if (o.map)
		if (const auto* l = o.map->find(id); l && l->scale != 1.0)
			return o.geometry.scaledBy(l->scale);
	return o.geometry;
}

ImageResult processImage(
	const cv::Mat& bgr, const CameraModel& camera, const PipelineOptions& o,
	const std::string& debug_dir)
{
	ImageResult r;
	const auto det = detect::detect(bgr, camera, o.geometry, o.detector, debug_dir);
	r.timings = det.timings;
	const auto t0 = std::chrono::steady_clock::now();
	for (const auto& d : det.landmarks)
	{
		MeasuredLandmark m;
		m.detected = d;
		try
		{
			m.measurement =
				pose::measure(d.detection, camera, geometryFor(d.detection.id, o), o.pose);
		}
		catch (const std::invalid_argument&)
		{
			r.unmeasured.push_back(d);	// degenerate corners: no measurement, no sighting
			continue;
		}
		r.landmarks.push_back(std::move(m));
	}
	r.pose_us =
		std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
	return r;
}

cv::Mat imageAsBgr(const mrpt::obs::CObservationImage& img, const std::string& images_dir)
{
	cv::Mat m;
	std::string file = "embedded image";
	try
	{
		if (!img.image.isExternallyStored())
			m = img.image.asCvMatRef();
		else
		{
			// Resolved here rather than through MRPT's process-wide images
			// folder, which parallel readers of different rawlogs share.
			const std::string name = img.image.getExternalStorageFile();
			file = images_dir.empty() || (!name.empty() && name.front() == '/')
					   ? img.image.getExternalStorageFileAbsolutePath()
					   : images_dir + "/" + name;
			mrpt::img::CImage loaded;
			if (loaded.loadFromFile(file)) m = loaded.asCvMatRef();
		}
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error("cannot load image '" + file + "': " + e.what());
	}
	if (m.empty()) throw std::runtime_error("cannot load image '" + file + "' (missing or empty)");
	cv::Mat bgr;
	if (m.depth() != CV_8U) throw std::runtime_error("image is not 8-bit per channel");
	if (m.channels() == 1)
		cv::cvtColor(m, bgr, cv::COLOR_GRAY2BGR);
	else if (m.channels() == 4)
		cv::cvtColor(m, bgr, cv::COLOR_BGRA2BGR);
	else
		bgr = m;
	return bgr;
}

CObservationCodedLandmarks::Ptr observeImage(
	const mrpt::obs::CObservationImage& img, const PipelineOptions& o, ImageResult* out)
{
	const CameraModel camera =
		o.camera_override ? *o.camera_override : CameraModel(img.cameraParams);
	const cv::Mat bgr = imageAsBgr(img, o.images_dir);
	if (bgr.cols != camera.width() || bgr.rows != camera.height())
		throw std::runtime_error(
			"image is " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) +
			" but the camera is " + std::to_string(camera.width()) + "x" +
			std::to_string(camera.height()));
	ImageResult r = processImage(bgr, camera, o);

	auto obs = CObservationCodedLandmarks::Create();
	obs->sensorLabel = img.sensorLabel + "_LANDMARKS";
	obs->timestamp = img.timestamp;
	obs->cameraPose = img.cameraPose;
	obs->camera = camera.params();
	for (const auto& m : r.landmarks)
		obs->sightings.push_back(
			CObservationCodedLandmarks::TSighting::From(m.detected.detection, m.measurement));
	if (out) *out = std::move(r);
	return obs;
}

CObservationCodedLandmarks::Ptr remeasure(
	const CObservationCodedLandmarks& c, const PipelineOptions& o)
{
	auto copy = std::make_shared<CObservationCodedLandmarks>(c);
	const CameraModel camera = o.camera_override ? *o.camera_override : CameraModel(c.camera);
	for (auto& t : copy->sightings)
	{
		Detection d;
		d.id = t.id;
		d.corners = t.corners;
		d.quality = t.quality;
		t = CObservationCodedLandmarks::TSighting::From(
			d, pose::measure(d, camera, geometryFor(t.id, o), o.pose));
	}
	return copy;
}

std::string imagesDirectoryOf(const std::string& rawlog_path)
{
	const auto slash = rawlog_path.find_last_of('/');
	const std::string dir = slash == std::string::npos ? "." : rawlog_path.substr(0, slash);
	std::string name = slash == std::string::npos ? rawlog_path : rawlog_path.substr(slash + 1);
	if (const auto dot = name.find_last_of('.'); dot != std::string::npos && dot > 0)
		name.erase(dot);
	return (dir.empty() ? std::string("/") : dir + "/") + name + "_Images";
}

}  // namespace codemark::pipeline
