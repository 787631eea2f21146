#pragma once
/** \file CObservationCodedLandmarks.h
 * The codemark landmark observation: what one camera image showed of the
 * coded landmarks, with each sighting's measurement and covariance, as a
 * serializable MRPT observation that stock MRPT tools (RawLogViewer,
 * rawlog-edit) can read once the plugin library is loaded.
 */
#include <codemark/landmark/detection.h>
#include <codemark/pose/measurement.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/obs/CObservationBearingRange.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace codemark
{
/** A landmark observation (sensor label by convention `<CAM>_LANDMARKS`,
 * docs/spec.md section 6), with the timestamp and camera pose of the
 * image it was detected in. */
class CObservationCodedLandmarks : public mrpt::obs::CObservation
{
	DEFINE_SERIALIZABLE(CObservationCodedLandmarks, codemark)

   public:
	/** One landmark seen in the image. */
	struct TSighting
	{
		int32_t id = -1;  //!< landmark ID, 0..255
		/** Reference points in raw image pixels, TL, TR, BR, BL. */
		// Eigen's default constructor leaves coefficients uninitialised: zero them.
		std::array<Eigen::Vector2d, 4> corners{
			Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
			Eigen::Vector2d::Zero()};
		Eigen::Vector4d P = Eigen::Vector4d::Zero();  //!< [x1 y1 x2 y2] [px]
		Eigen::Matrix4d C_P = Eigen::Matrix4d::Zero();	//!< covariance of P [px^2]
		/** [l2 phi1 phi2]: horizontal range [m], bearing [rad], relative
		 * orientation [rad] (docs/spec.md section 4). */
		Eigen::Vector3d L = Eigen::Vector3d::Zero();
		Eigen::Matrix3d C_L = Eigen::Matrix3d::Zero();	//!< covariance of L
		/** Camera's planar pose in the landmark frame: x, y [m], theta [rad]. */
		Eigen::Vector3d pose_in_landmark = Eigen::Vector3d::Zero();
		Eigen::Matrix3d C_R = Eigen::Matrix3d::Zero();	//!< covariance of that pose
		DetectionQuality quality;
		pose::PoseMethod method = pose::PoseMethod::ClosedForm;	 //!< which path produced L

		/** A sighting from a detection and its measurement. */
		static TSighting From(const Detection& d, const pose::Measurement& m);
	};

	CObservationCodedLandmarks() = default;

	/** The camera's optical frame on the robot (MRPT camera convention: z
	 * along the optical axis, x right, y down), as CObservationImage's. */
	mrpt::poses::CPose3D cameraPose;
	mrpt::img::TCamera camera;	//!< intrinsics of the image's camera
	std::vector<TSighting> sightings;  //!< one per landmark detected

	void getSensorPose(mrpt::poses::CPose3D& out) const override { out = cameraPose; }
	void setSensorPose(const mrpt::poses::CPose3D& p) override { cameraPose = p; }
	void getDescriptionAsText(std::ostream& o) const override;

	/** The standard range-bearing twin: range l2, yaw phi1, pitch 0, the
	 * landmark ID, the range/bearing block of C_L as the per-reading
	 * covariance, an x-forward sensor pose at the camera's position and
	 * optical-axis heading, the camera's field of view. Its label is
	 * \a label, or this label with `_LANDMARKS` replaced by `_BR` (else
	 * `_BR` appended) when empty. */
	mrpt::obs::CObservationBearingRange::Ptr toBearingRange(
		const std::string& label = {}, float max_range_m = 20.0f) const;

	/** Upper bound on sightings accepted when reading: protects against
	 * corrupt files asking for huge allocations. */
	static constexpr uint32_t kMaxSightings = 4096;
};

/** The planar pose (x, y, heading of the horizontal projection of the
 * optical axis) of a camera given in MRPT's optical-frame convention, as an
 * x-forward CPose3D with pitch = roll = 0 at the same height. */
mrpt::poses::CPose3D xForwardPoseOfCamera(const mrpt::poses::CPose3D& optical_pose);

}  // namespace codemark
