#pragma once
/** \file CCodedLandmarksMap.h
 * A metric map of coded landmarks (id, pose, scale) for MRPT's particle
 * filters: the observation likelihood of codemark::CObservationCodedLandmarks
 * and of mrpt::obs::CObservationBearingRange with landmark IDs (Gaussian in
 * range, yaw, pitch), each mixed with a uniform for outliers. A coded
 * sighting of the closed form (a level camera) is scored where it was
 * measured: its primary measurement P = [x1 y1 x2 y2] against the P that
 * the particle's pose predicts, with its C_P (scoreP()); other sightings
 * (the general 6-DoF path) in L = [l2 phi1 phi2] with their C_L. It lives in the plugin so
 * that stock tools (pf-localization with LD_PRELOAD) can build it from an ini:
 *
 *     [MetricMap]
 *     codedLandmarksMap_count = 1
 *     [MetricMap_codedLandmarksMap_00_creationOpts]
 *     map_file = map.txt            // docs/spec.md section 3
 *     [MetricMap_codedLandmarksMap_00_likelihoodOpts]
 *     outlier_probability = 0.05
 */
#include <codemark/landmark/map.h>
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/maps/CMetricMap.h>
#include <mrpt/maps/TMetricMapInitializer.h>
#include <mrpt/math/TPoint3D.h>

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace codemark
{
/** The coded-landmark map (world frame). The map is static: inserting
 * observations does not change it. */
class CCodedLandmarksMap : public mrpt::maps::CMetricMap
{
	DEFINE_SERIALIZABLE(CCodedLandmarksMap, codemark)

   public:
	/** How observations are scored (section `..._likelihoodOpts`). */
	struct TLikelihoodOptions : public mrpt::config::CLoadableOptions
	{
		/** Weight of the uniform in the per-sighting mixture
		 * (1 - p) N(r; 0, C) + p U: the probability that a sighting is an
		 * outlier (wrong ID, bad detection), in [0, 1). */
		double outlier_probability = 0.05;
		/** Multiplies every standard deviation of C_P and C_L (and of the
		 * range-bearing covariances): > 1 makes the filter trust sightings
		 * less. */
		double sigma_scale = 1.0;
		/** Standard deviation added in quadrature to the range [m] (for a
		 * sighting scored in P, mapped into P through dP/dL at the
		 * particle's predicted L). */
		double min_std_range_m = 0.01;
		/** Standard deviation added in quadrature to each angle [deg] (as
		 * min_std_range_m). */
		double min_std_angle_deg = 0.5;
		/** Upper range of the outliers' uniform density in L [m]; the
		 * angles' span is 2 pi each. In P the uniform spans the image: x1,
		 * x2 its width, y1, y2 half its height. */
		double max_range_m = 20.0;

		void loadFromConfigFile(
			const mrpt::config::CConfigFileBase& source, const std::string& section) override;
		void saveToConfigFile(
			mrpt::config::CConfigFileBase& target, const std::string& section) const override;
	};

	CCodedLandmarksMap() = default;
	/** A map holding \a map's landmarks. */
	explicit CCodedLandmarksMap(const LandmarkMap& map);

	TLikelihoodOptions likelihoodOptions;

	/** Replaces the landmarks. */
	void setLandmarks(const LandmarkMap& map);
	/** The landmarks, in the order given. */
	const LandmarkMap& landmarks() const { return m_map; }
	/** The landmark with \a id, or nullptr (constant time for IDs < 65536). */
	const MapLandmark* find(int id) const;
	/** Axis-aligned bounds of the landmark centres [m]; false when empty. */
	bool boundingBox(mrpt::math::TPoint3D& min_m, mrpt::math::TPoint3D& max_m) const;

	/** Log-likelihood of one coded-landmark sighting with measurement \a L
	 * and covariance \a C_L, seen by a camera at planar pose (\a cam_x,
	 * \a cam_y, heading (\a cam_cos, \a cam_sin)) in the world, of
	 * landmark \a lm. The Gaussian-uniform mixture of the options. */
	double sightingLogLikelihood(
		const Eigen::Vector3d& L, const Eigen::Matrix3d& C_L, double cam_x, double cam_y,
		double cam_cos, double cam_sin, const MapLandmark& lm) const;

	/** The L = [l2 phi1 phi2] that a level camera at planar world pose
	 * (\a cam_x, \a cam_y [m], heading (\a cam_cos, \a cam_sin)) measures
	 * of a landmark at (\a lm_x, \a lm_y [m], yaw (\a lm_cos, \a lm_sin)):
	 * the inverse of pose::poseFromLandmark() (spec section 4). */
	static Eigen::Vector3d predictL(
		double cam_x, double cam_y, double cam_cos, double cam_sin, double lm_x, double lm_y,
		double lm_cos, double lm_sin);

	/** A camera's planar pose in the world: optical centre (\a cam_x,
	 * \a cam_y [m]) and the unit heading (\a cam_cos, \a cam_sin) of its
	 * optical axis's horizontal projection, for a robot at (\a rx, \a ry)
	 * with heading (\a rc, \a rs) and the camera's optical frame
	 * \a robot_T_camera (MRPT camera convention). False when the optical
	 * axis is vertical. */
	static bool cameraInWorld(
		double rx, double ry, double rc, double rs, const mrpt::poses::CPose3D& robot_T_camera,
		double& cam_x, double& cam_y, double& cam_cos, double& cam_sin);

	/** C_L as the likelihood uses it: sigma_scale^2 C_L plus the floors
	 * (min_std_range_m^2, min_std_angle^2) on the diagonal. */
	Eigen::Matrix3d inflatedCovariance(const Eigen::Matrix3d& C_L) const;
	/** Squared Mahalanobis distance of a measured \a L (covariance \a C_L,
	 * inflated) from a predicted \a Lp, angles wrapped; +inf when the
	 * covariance is not positive definite. */
	double sightingMahalanobis2(
		const Eigen::Vector3d& L, const Eigen::Matrix3d& C_L, const Eigen::Vector3d& Lp) const;

	// CMetricMap interface
	bool isEmpty() const override { return m_map.landmarks.empty(); }
	/** Writes `<prefix>_landmarks.txt` in the map file format (spec section 3). */
	void saveMetricMapRepresentationToFile(const std::string& prefix) const override;
	/** Each landmark as a thin box of its printed size at its pose, the axes
	 * of frame L and its ID. */
	void getVisualizationInto(mrpt::opengl::CSetOfObjects& o) const override;
	std::string asString() const override;

	/** Upper bound on landmarks accepted when reading: protects against
	 * corrupt files asking for huge allocations. */
	static constexpr uint32_t kMaxLandmarks = 1u << 20;

	MAP_DEFINITION_START(CCodedLandmarksMap)
	/** Landmark map file (spec section 3), read when the map is created;
	 * relative paths are relative to the working directory. */
	std::string map_file;
	CCodedLandmarksMap::TLikelihoodOptions likelihoodOpts;
	MAP_DEFINITION_END(CCodedLandmarksMap)

   protected:
	void internal_clear() override;
	bool internal_insertObservation(
		const mrpt::obs::CObservation& obs,
		const std::optional<const mrpt::poses::CPose3D>& robotPose = std::nullopt) override;
	/** LOG-likelihood of \a obs seen from the robot pose \a takenFrom: the
	 * sum over its sightings/readings of known IDs; 0 for other classes. */
	double internal_computeObservationLikelihood(
		const mrpt::obs::CObservation& obs, const mrpt::poses::CPose3D& takenFrom) const override;
	bool internal_canComputeObservationLikelihood(
		const mrpt::obs::CObservation& obs) const override;

   private:
	/** A landmark's planar pose with its yaw's cosine and sine precomputed
	 * (the likelihood runs once per particle and sighting). */
	struct Cached
	{
		double x = 0, y = 0, z = 0, cos_yaw = 1, sin_yaw = 0;
	};
	LandmarkMap m_map;
	std::vector<Cached> m_cache;  //!< parallel to m_map.landmarks
	std::vector<int32_t> m_index;  //!< id -> index in m_map, -1 when absent (ids < 65536)
	void rebuildIndex();
	/** The mixture log-likelihood of a measured \a L (covariance \a C_L,
	 * inflated by the options) for a camera at (\a xl, \a yl [m], heading
	 * (\a ux, \a uy)) in the landmark's frame. */
	double scoreL(
		const Eigen::Vector3d& L, const Eigen::Matrix3d& C_L, double xl, double yl, double ux,
		double uy) const;
	/** The mixture log-likelihood of a measured \a P (covariance \a C_P)
	 * of a landmark with inner half-height \a h_m seen with focal length
	 * \a lambda_px, for a camera at (\a xl, \a yl [m], heading (\a ux,
	 * \a uy)) in the landmark's frame: N(P; P(L), sigma_scale^2 C_P + J D
	 * J^T), L the pose's predicted L, J = dP/dL there and D the floors on
	 * L's diagonal, mixed with the uniform of density exp(\a log_uniform).
	 * A camera behind the landmark's plane, or an edge behind the camera,
	 * scores the uniform alone. */
	double scoreP(
		const Eigen::Vector4d& P, const Eigen::Matrix4d& C_P, double h_m, double lambda_px,
		double log_uniform, double xl, double yl, double ux, double uy) const;
	int indexOf(int id) const;
};

}  // namespace codemark
