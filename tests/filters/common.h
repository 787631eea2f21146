#pragma once
// Helpers of the filter tests: synthetic sightings of a known map.
#include <codemark/filters/ekf.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <codemark/pose/closed_form.h>
#include <mrpt/math/wrap2pi.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPosePDFGaussian.h>

#include <Eigen/Dense>
#include <random>

namespace codemark::filters::test
{
/** A level forward camera 0.1 m ahead of the robot centre, 0.6 m high. */
inline mrpt::poses::CPose3D cameraOnRobot(double yaw = 0.0)
{
	return mrpt::poses::CPose3D(0.1, 0.0, 0.6, yaw, 0, 0) +
		   mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
}

/** Landmarks on the walls of a 6 x 4 m room, facing in. */
inline LandmarkMap roomMap()
{
	LandmarkMap m;
	auto add = [&](int id, double x, double y, double yaw_deg)
	{
		MapLandmark l;
		l.id = id, l.x_m = x, l.y_m = y, l.z_m = 0.6, l.yaw_rad = yaw_deg * M_PI / 180.0;
		m.landmarks.push_back(l);
	};
	add(1, 6.0, 1.0, 180), add(2, 6.0, 3.0, 180), add(3, 0.0, 1.0, 0), add(4, 0.0, 3.0, 0);
	add(5, 2.0, 4.0, -90), add(6, 4.0, 4.0, -90), add(7, 2.0, 0.0, 90), add(8, 4.0, 0.0, 90);
	return m;
}

/** The sighting of \a l from a robot at \a robot with measurement noise
 * sigma (l2 [m], phi1 [rad], phi2 [rad]) drawn from \a rng (exact when rng
 * is null). Its id is \a id_override when >= 0. */
inline CObservationCodedLandmarks::TSighting sighting(
	const mrpt::poses::CPose2D& robot, const mrpt::poses::CPose3D& cam, const MapLandmark& l,
	const Eigen::Vector3d& sigma, std::mt19937* rng = nullptr, int id_override = -1)
{
	CObservationCodedLandmarks::TSighting s;
	s.id = id_override >= 0 ? id_override : l.id;
	Eigen::Vector3d L = predictLandmarkMeasurement(
		{robot.x(), robot.y(), robot.phi()}, pose::cameraPlanarPose(cam),
		pose::landmarkPlanarPose(l.world_T_landmark()));
	if (rng)
	{
		std::normal_distribution<double> n(0.0, 1.0);
		for (int i = 0; i < 3; ++i) L[i] += sigma[i] * n(*rng);
	}
	s.L = L;
	s.C_L = sigma.cwiseAbs2().asDiagonal();
	Eigen::Matrix3d J;
	s.pose_in_landmark = pose::poseFromLandmark(L, &J);
	s.C_R = J * s.C_L * J.transpose();
	return s;
}

/** A sensory frame holding one landmark observation with \a sightings. */
inline mrpt::obs::CSensoryFrame frameOf(
	const std::vector<CObservationCodedLandmarks::TSighting>& sightings,
	const mrpt::poses::CPose3D& cam = cameraOnRobot())
{
	auto o = CObservationCodedLandmarks::Create();
	o->sensorLabel = "CAM_LANDMARKS";
	o->cameraPose = cam;
	o->sightings = sightings;
	mrpt::obs::CSensoryFrame sf;
	sf.insert(o);
	return sf;
}

/** An odometry action with mean \a u: MRPT's Gaussian model with no
 * proportional terms, so that the covariance is diag(sxy^2, sxy^2, syaw^2)
 * (computeFromOdometry, as MRPT recomputes it when reading a rawlog). */
inline mrpt::obs::CActionRobotMovement2D odometry(
	const mrpt::poses::CPose2D& u, double sxy, double syaw)
{
	mrpt::obs::CActionRobotMovement2D::TMotionModelOptions m;
	m.modelSelection = mrpt::obs::CActionRobotMovement2D::mmGaussian;
	m.gaussianModel.a1 = m.gaussianModel.a2 = m.gaussianModel.a3 = m.gaussianModel.a4 = 0;
	m.gaussianModel.minStdXY = static_cast<float>(sxy);
	m.gaussianModel.minStdPHI = static_cast<float>(syaw);
	mrpt::obs::CActionRobotMovement2D a;
	a.computeFromOdometry(u, m);
	return a;
}

}  // namespace codemark::filters::test
