// One camera frame through codemark: image -> detection -> measurement ->
// MRPT observation -> one step of the EKF.
// usage: quickstart IMAGE CAMERA.ini MAP.txt EKF.ini
#include <codemark/filters/localizer.h>
#include <codemark/landmark/camera.h>
#include <codemark/landmark/map.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <codemark/pipeline/pipeline.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/obs/CSensoryFrame.h>

#include <cmath>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

int main(int argc, char** argv)
{
	if (argc != 5)
	{
		std::cerr << "usage: quickstart IMAGE CAMERA.ini MAP.txt EKF.ini\n";
		return 2;
	}
	const cv::Mat image = cv::imread(argv[1], cv::IMREAD_COLOR);
	if (image.empty())
	{
		std::cerr << argv[1] << ": cannot read the image\n";
		return 1;
	}
	const auto camera = codemark::CameraModel::load(argv[2]);
	const auto map = codemark::LandmarkMap::load(argv[3]);

	// Detect and measure: the default calibration of C_P, each ID's printed
	// size from the map.
	codemark::pipeline::PipelineOptions options;
	options.map = map;
	const auto result = codemark::pipeline::processImage(image, camera, options);

	// The frame's MRPT observation, as codemark-annotate stores it: a level
	// camera 0.6 m above the robot's origin, looking forward.
	auto obs = std::make_shared<codemark::CObservationCodedLandmarks>();
	obs->sensorLabel = "CAM_LANDMARKS";
	obs->cameraPose = mrpt::poses::CPose3D(0, 0, 0.6, -M_PI / 2, 0, -M_PI / 2);
	obs->camera = camera.params();
	for (const auto& lm : result.landmarks)
	{
		const auto& m = lm.measurement;
		std::cout << "landmark " << lm.detected.detection.id << ": range " << m.L[0]
				  << " m, bearing " << m.L[1] << " rad, orientation " << m.L[2] << " rad\n";
		obs->sightings.push_back(codemark::CObservationCodedLandmarks::TSighting::From(
			lm.detected.detection, m));
	}

	// One step of the EKF: with no odometry and no initial pose, it starts
	// from the frame's most precise sighting.
	mrpt::config::CConfigFile config(argv[4]);
	auto ekf = codemark::filters::makeLocalizer("ekf", config, map);
	mrpt::obs::CSensoryFrame frame;
	frame.insert(obs);
	ekf->step(nullptr, frame);
	const auto estimate = ekf->estimate();
	if (!estimate.initialized)
	{
		std::cout << "no landmark of the map in view\n";
		return 0;
	}
	std::cout << "robot at x " << estimate.mean.x() << " m, y " << estimate.mean.y()
			  << " m, yaw " << estimate.mean.phi() << " rad, position sigma "
			  << std::sqrt(estimate.cov(0, 0) + estimate.cov(1, 1)) << " m\n";
	return 0;
}
