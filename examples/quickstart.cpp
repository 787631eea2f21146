// One camera frame through codemark: image -> detection -> measurement ->
// MRPT observation -> one step of the EKF.
// usage: quickstart IMAGE CAMERA.ini MAP.txt EKF.ini
#include <codemark/filters/localizer.h>
#include <codemark/pipeline/pipeline.h>
#include <mrpt/config/CConfigFile.h>

#include <iostream>
#include <opencv2/imgcodecs.hpp>

int main(int argc, char** argv)
{
	if (argc != 5) return std::cerr << "usage: quickstart IMAGE CAMERA MAP EKF.ini\n", 2;
	const auto camera = codemark::CameraModel::load(argv[2]);
	const auto map = codemark::LandmarkMap::load(argv[3]);

	// Detect and measure (the default C_P calibration, sizes from the map).
	codemark::pipeline::PipelineOptions options;
	options.map = map;
	const auto result =
		codemark::pipeline::processImage(cv::imread(argv[1], cv::IMREAD_COLOR), camera, options);

	// The frame's MRPT observation: a level camera 0.6 m above the robot.
	auto obs = std::make_shared<codemark::CObservationCodedLandmarks>();
	obs->cameraPose = mrpt::poses::CPose3D(0, 0, 0.6, -M_PI / 2, 0, -M_PI / 2);
	obs->camera = camera.params();
	for (const auto& lm : result.landmarks)
	{
		std::cout << "landmark " << lm.detected.detection.id << ": range " << lm.measurement.L[0]
				  << " m, bearing " << lm.measurement.L[1] << " rad\n";
		obs->sightings.push_back(codemark::CObservationCodedLandmarks::TSighting::From(
			lm.detected.detection, lm.measurement));
	}

	// One EKF step; without odometry or a prior it starts from the sightings.
	mrpt::config::CConfigFile config(argv[4]);
	auto ekf = codemark::filters::makeLocalizer("ekf", config, map);
	mrpt::obs::CSensoryFrame frame;
	frame.insert(obs);
	ekf->step(nullptr, frame);
	const auto e = ekf->estimate();
	if (e.initialized)
		std::cout << "robot at x " << e.mean.x() << " m, y " << e.mean.y() << " m, yaw "
				  << e.mean.phi() << " rad\n";
	return 0;
}
