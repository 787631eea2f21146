#pragma once
// Synthetic sightings for the particle-filter tests and benchmark: a 6 x 4 m
// room with 12 coded landmarks, a level forward camera, exact L from
// sightingTruth() (independent of the map's forward model) plus Gaussian
// noise with the stated C_L, and noisy odometry on a circle.
#include <codemark/landmark/map.h>
#include <codemark/landmark/truth.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pose/predict.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/system/datetime.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

namespace codemark::pftest
{
/** 12 landmarks (IDs 1..12) at 0.6 m on the walls of a 6 x 4 m room, facing in. */
inline LandmarkMap room()
{
	LandmarkMap m;
	int id = 1;
	auto add = [&](double x, double y, double yaw)
	{
		MapLandmark l;
		l.id = id++, l.x_m = x, l.y_m = y, l.z_m = 0.6, l.yaw_rad = yaw;
		m.landmarks.push_back(l);
	};
	for (double y : {1.0, 2.0, 3.0}) add(0.0, y, 0.0);
	for (double y : {1.0, 2.0, 3.0}) add(6.0, y, M_PI);
	for (double x : {1.5, 3.0, 4.5}) add(x, 0.0, M_PI / 2);
	for (double x : {1.5, 3.0, 4.5}) add(x, 4.0, -M_PI / 2);
	return m;
}

/** A level forward camera 0.1 m ahead of the robot centre, 0.6 m high. */
inline mrpt::poses::CPose3D robotTCamera()
{
	return mrpt::poses::CPose3D(0.1, 0, 0.6, 0, 0, 0) +
		   mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
}

/** C_L of a sighting at range \a l2_m: 1% of the range, 0.2 deg bearing,
 * 2 deg relative orientation (the paper's orders of magnitude). */
inline Eigen::Matrix3d sightingCov(double l2_m)
{
	const double d = M_PI / 180;
	return Eigen::Vector3d(std::pow(0.01 * l2_m, 2), std::pow(0.2 * d, 2), std::pow(2.0 * d, 2))
		.asDiagonal();
}

/** The sightings (by a camera \a robot_T_camera) of \a map's landmarks in view (range 0.4..5 m,
 * bearing within +-25 deg, seen from the front within +-60 deg) from a robot at \a world_T_robot;
 * with noise drawn from C_L when \a rng is given. */
inline CObservationCodedLandmarks::Ptr observe(
	const mrpt::poses::CPose2D& world_T_robot, const LandmarkMap& map, std::mt19937* rng = nullptr,
	double t = 0, const mrpt::poses::CPose3D& robot_T_camera = robotTCamera())
{
	auto o = CObservationCodedLandmarks::Create();
	o->sensorLabel = "CAM_LANDMARKS";
	o->timestamp = mrpt::Clock::fromDouble(1700000000.0 + t);
	o->cameraPose = robot_T_camera;
	const auto world_T_camera = pose::worldTCamera(world_T_robot, robot_T_camera);
	std::normal_distribution<double> n01(0.0, 1.0);
	for (const auto& lm : map.landmarks)
	{
		const SightingTruth tr = sightingTruth(world_T_camera - lm.world_T_landmark());
		const double d = M_PI / 180;
		if (tr.L[0] < 0.4 || tr.L[0] > 5.0 || std::abs(tr.L[1]) > 25 * d ||
			std::abs(tr.L[2]) > 60 * d || tr.pose_in_landmark[0] <= 0)
			continue;
		CObservationCodedLandmarks::TSighting s;
		s.id = lm.id;
		s.C_L = sightingCov(tr.L[0]);
		s.L = tr.L;
		if (rng)
		{
			const Eigen::Vector3d z(n01(*rng), n01(*rng), n01(*rng));
			s.L += Eigen::Matrix3d(s.C_L.llt().matrixL()) * z;
		}
		Eigen::Matrix3d J;
		s.pose_in_landmark = pose::poseFromLandmark(s.L, &J);
		s.C_R = J * s.C_L * J.transpose();
		o->sightings.push_back(s);
	}
	return o;
}

/** The motion model that describes the odometry below. */
inline mrpt::obs::CActionRobotMovement2D::TMotionModelOptions motionModel()
{
	mrpt::obs::CActionRobotMovement2D::TMotionModelOptions mm;
	mm.modelSelection = mrpt::obs::CActionRobotMovement2D::mmGaussian;
	mm.gaussianModel.a1 = 0.05;
	mm.gaussianModel.a2 = 0.001;
	mm.gaussianModel.a3 = 0.05;
	mm.gaussianModel.a4 = 0.05;
	mm.gaussianModel.minStdXY = 0.005;
	mm.gaussianModel.minStdPHI = 0.5 * M_PI / 180;
	return mm;
}

/** Odometry from \a prev to \a cur, with 2% translation and 2% rotation noise. */
inline mrpt::obs::CActionRobotMovement2D odometry(
	const mrpt::poses::CPose2D& prev, const mrpt::poses::CPose2D& cur, std::mt19937& rng)
{
	const mrpt::poses::CPose2D incr = cur - prev;
	std::normal_distribution<double> n01(0.0, 1.0);
	const double dist = incr.norm();
	const mrpt::poses::CPose2D noisy(
		incr.x() + 0.02 * dist * n01(rng), incr.y() + 0.02 * dist * n01(rng),
		incr.phi() + (0.02 * std::abs(incr.phi()) + 0.002) * n01(rng));
	mrpt::obs::CActionRobotMovement2D a;
	a.computeFromOdometry(noisy, motionModel());
	return a;
}

/** Pose \a k of a counter-clockwise circle of radius 1 m about (3, 2),
 * 0.08 m per step (0.4 m/s at 5 Hz), heading along the circle. */
inline mrpt::poses::CPose2D circlePose(int k)
{
	const double a = 0.08 * k - M_PI / 2;
	return mrpt::poses::CPose2D(3 + std::cos(a), 2 + std::sin(a), a + M_PI / 2);
}

}  // namespace codemark::pftest
