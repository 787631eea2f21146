#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <mrpt/serialization/CArchive.h>

#include <Eigen/Dense>
#include <cmath>
#include <iomanip>

IMPLEMENTS_SERIALIZABLE(CObservationCodedLandmarks, mrpt::obs::CObservation, codemark)

namespace codemark
{
namespace
{
template <class M>
void writeMatrix(mrpt::serialization::CArchive& out, const M& m)
{
	for (int r = 0; r < m.rows(); ++r)
		for (int c = 0; c < m.cols(); ++c) out << m(r, c);
}
template <class M>
void readMatrix(mrpt::serialization::CArchive& in, M& m)
{
	for (int r = 0; r < m.rows(); ++r)
		for (int c = 0; c < m.cols(); ++c) in >> m(r, c);
}

double deg(double rad) { return rad * 180.0 / M_PI; }
double sd(double var) { return var > 0 ? std::sqrt(var) : 0.0; }
}  // namespace

CObservationCodedLandmarks::TSighting CObservationCodedLandmarks::TSighting::From(
	const Detection& d, const pose::Measurement& m)
{
	TSighting s;
	s.id = d.id;
	s.corners = d.corners;
	s.quality = d.quality;
	s.P = m.P;
	s.C_P = m.C_P;
	s.L = m.L;
	s.C_L = m.C_L;
	s.pose_in_landmark = m.pose_in_landmark;
	s.C_R = m.C_R;
	s.method = m.method;
	return s;
}

// Version 1 adds DetectionQuality::fill_clipped (a bit per side), version 2
// DetectionQuality::image_noise_grey, version 3 edge_bend_px and
// edge_bend_se_px.
uint8_t CObservationCodedLandmarks::serializeGetVersion() const { return 3; }

void CObservationCodedLandmarks::serializeTo(mrpt::serialization::CArchive& out) const
{
	out << timestamp << sensorLabel << cameraPose << camera;
	out.WriteAs<uint32_t>(sightings.size());
	for (const auto& s : sightings)
	{
		out << s.id;
		for (const auto& c : s.corners) out << c.x() << c.y();
		writeMatrix(out, s.P);
		writeMatrix(out, s.C_P);
		writeMatrix(out, s.L);
		writeMatrix(out, s.C_L);
		writeMatrix(out, s.pose_in_landmark);
		writeMatrix(out, s.C_R);
		for (double v : s.quality.line_rms_px) out << v;
		for (int v : s.quality.line_support) out.WriteAs<int32_t>(v);
		out << s.quality.code_margin << s.quality.area_px << s.quality.corner_sigma_px;
		// Stored as pose::PoseMethod's value: ClosedForm = 0, General6Dof = 1.
		out.WriteAs<uint8_t>(static_cast<uint8_t>(s.method));
		uint8_t clipped = 0;
		for (int k = 0; k < 4; ++k) clipped |= s.quality.fill_clipped[k] ? (1u << k) : 0u;
		out.WriteAs<uint8_t>(clipped);
		out << s.quality.image_noise_grey;
		out << s.quality.edge_bend_px << s.quality.edge_bend_se_px;
	}
}

void CObservationCodedLandmarks::serializeFrom(mrpt::serialization::CArchive& in, uint8_t version)
{
	switch (version)
	{
		case 0:
		case 1:
		case 2:
		case 3:
		{
			in >> timestamp >> sensorLabel >> cameraPose >> camera;
			const auto n = in.ReadAs<uint32_t>();
			if (n > kMaxSightings)
				THROW_EXCEPTION_FMT(
					"CObservationCodedLandmarks: corrupt data, %u sightings (max %u)",
					static_cast<unsigned>(n), static_cast<unsigned>(kMaxSightings));
			sightings.assign(n, TSighting());
			for (auto& s : sightings)
			{
				in >> s.id;
				if (s.id < 0 || s.id > 255)
					THROW_EXCEPTION_FMT(
						"CObservationCodedLandmarks: corrupt data, landmark ID %d", s.id);
				for (auto& c : s.corners) in >> c.x() >> c.y();
				readMatrix(in, s.P);
				readMatrix(in, s.C_P);
				readMatrix(in, s.L);
				readMatrix(in, s.C_L);
				readMatrix(in, s.pose_in_landmark);
				readMatrix(in, s.C_R);
				for (double& v : s.quality.line_rms_px) in >> v;
				for (int& v : s.quality.line_support) v = in.ReadAs<int32_t>();
				in >> s.quality.code_margin >> s.quality.area_px >> s.quality.corner_sigma_px;
				const auto m = in.ReadAs<uint8_t>();
				if (m > static_cast<uint8_t>(pose::PoseMethod::General6Dof))
					THROW_EXCEPTION_FMT(
						"CObservationCodedLandmarks: corrupt data, pose method %u",
						static_cast<unsigned>(m));
				s.method = static_cast<pose::PoseMethod>(m);
				if (version >= 1)
				{
					const auto clipped = in.ReadAs<uint8_t>();
					if (clipped > 15)
						THROW_EXCEPTION_FMT(
							"CObservationCodedLandmarks: corrupt data, clipped-sides mask %u",
							static_cast<unsigned>(clipped));
					for (int k = 0; k < 4; ++k) s.quality.fill_clipped[k] = (clipped >> k) & 1u;
				}
				if (version >= 2)
				{
					in >> s.quality.image_noise_grey;
					if (!(s.quality.image_noise_grey >= 0) ||
						!std::isfinite(s.quality.image_noise_grey))
						THROW_EXCEPTION_FMT(
							"CObservationCodedLandmarks: corrupt data, image noise %g",
							s.quality.image_noise_grey);
				}
				if (version >= 3)
				{
					in >> s.quality.edge_bend_px >> s.quality.edge_bend_se_px;
					if (!std::isfinite(s.quality.edge_bend_px) ||
						!(s.quality.edge_bend_se_px >= 0) ||
						!std::isfinite(s.quality.edge_bend_se_px))
						THROW_EXCEPTION_FMT(
							"CObservationCodedLandmarks: corrupt data, edge bend %g +- %g",
							s.quality.edge_bend_px, s.quality.edge_bend_se_px);
				}
				// A detection never has a non-finite measurement; such a value
				// would only poison a filter later, far from its cause.
				bool finite = s.P.allFinite() && s.L.allFinite() && s.C_L.allFinite() &&
							  s.pose_in_landmark.allFinite();
				for (const auto& c : s.corners) finite = finite && c.allFinite();
				if (!finite)
					THROW_EXCEPTION_FMT(
						"CObservationCodedLandmarks: corrupt data, non-finite measurement of "
						"landmark %d",
						s.id);
			}
		}
		break;
		default:
			MRPT_THROW_UNKNOWN_SERIALIZATION_VERSION(version);
	}
}

void CObservationCodedLandmarks::getDescriptionAsText(std::ostream& o) const
{
	CObservation::getDescriptionAsText(o);
	o << "Camera pose on the robot (optical frame): " << cameraPose << "\n";
	o << "Camera: " << camera.ncols << "x" << camera.nrows << " px, fx=" << camera.fx()
	  << " fy=" << camera.fy() << " cx=" << camera.cx() << " cy=" << camera.cy() << "\n";
	o << "Coded landmarks seen: " << sightings.size() << "\n";
	const auto old = o.flags();
	const auto oldp = o.precision();
	// Values in fixed notation, their 1-sigma with 3 significant digits:
	// sub-millimetre and millidegree sigmas must not print as 0.
	auto val = [&](double v, int decimals) -> std::ostream&
	{ return o << std::fixed << std::setprecision(decimals) << v; };
	auto sig = [&](double v) -> std::ostream&
	{
		o.unsetf(std::ios::floatfield);
		return o << std::setprecision(3) << v;
	};
	for (const auto& s : sightings)
	{
		o << "\n  ID " << s.id << "  ("
		  << (s.method == pose::PoseMethod::ClosedForm ? "closed form" : "general 6-DoF") << ")\n";
		o << "    range l2         = ";
		val(s.L[0], 4) << " m    +- ";
		sig(sd(s.C_L(0, 0))) << " m\n";
		o << "    bearing phi1     = ";
		val(deg(s.L[1]), 4) << " deg  +- ";
		sig(deg(sd(s.C_L(1, 1)))) << " deg\n";
		o << "    orientation phi2 = ";
		val(deg(s.L[2]), 3) << " deg  +- ";
		sig(deg(sd(s.C_L(2, 2)))) << " deg\n";
		o << "    camera in landmark frame: x = ";
		val(s.pose_in_landmark[0], 4) << " m, y = ";
		val(s.pose_in_landmark[1], 4) << " m, theta = ";
		val(deg(s.pose_in_landmark[2]), 3) << " deg  (1-sigma ";
		sig(sd(s.C_R(0, 0))) << " m, ";
		sig(sd(s.C_R(1, 1))) << " m, ";
		sig(deg(sd(s.C_R(2, 2)))) << " deg)\n";
		o << "    corners [px]: ";
		for (const auto& c : s.corners)
		{
			o << "(";
			val(c.x(), 3) << ", ";
			val(c.y(), 3) << ") ";
		}
		o << "\n    P = [";
		for (int i = 0; i < 4; ++i) val(s.P[i], 3) << (i < 3 ? " " : "");
		o << "] px, code margin ";
		val(s.quality.code_margin, 1) << ", area ";
		val(s.quality.area_px, 0) << " px^2\n";
	}
	o.precision(oldp);
	o.flags(old);
}

mrpt::poses::CPose3D xForwardPoseOfCamera(const mrpt::poses::CPose3D& p)
{
	const auto R = p.getRotationMatrix();
	const double heading = std::atan2(R(1, 2), R(0, 2));
	return mrpt::poses::CPose3D(p.x(), p.y(), p.z(), heading, 0.0, 0.0);
}

mrpt::obs::CObservationBearingRange::Ptr CObservationCodedLandmarks::toBearingRange(
	const std::string& label, float max_range_m) const
{
	auto br = mrpt::obs::CObservationBearingRange::Create();
	br->timestamp = timestamp;
	if (!label.empty())
		br->sensorLabel = label;
	else
	{
		const std::string suffix = "_LANDMARKS";
		std::string base = sensorLabel;
		if (base.size() >= suffix.size() &&
			base.compare(base.size() - suffix.size(), suffix.size(), suffix) == 0)
			base.erase(base.size() - suffix.size());
		br->sensorLabel = base + "_BR";
	}
	br->sensorLocationOnRobot = xForwardPoseOfCamera(cameraPose);
	if (camera.fx() > 0 && camera.fy() > 0)
	{
		br->fieldOfView_yaw = static_cast<float>(2 * std::atan(0.5 * camera.ncols / camera.fx()));
		br->fieldOfView_pitch = static_cast<float>(2 * std::atan(0.5 * camera.nrows / camera.fy()));
	}
	br->minSensorDistance = 0;
	br->maxSensorDistance = max_range_m;
	br->validCovariances = true;
	double max_var_r = 0, max_var_yaw = 0;
	for (const auto& s : sightings)
	{
		mrpt::obs::CObservationBearingRange::TMeasurement m;
		m.range = static_cast<float>(s.L[0]);
		m.yaw = static_cast<float>(s.L[1]);
		m.pitch = 0;
		m.landmarkID = s.id;
		m.covariance.setZero();
		for (int r = 0; r < 2; ++r)
			for (int c = 0; c < 2; ++c) m.covariance(r, c) = s.C_L(r, c);
		// The camera measures no elevation: give pitch the bearing's variance
		// so that the 3x3 block stays positive definite.
		m.covariance(2, 2) = s.C_L(1, 1);
		br->sensedData.push_back(m);
		max_var_r = std::max(max_var_r, s.C_L(0, 0));
		max_var_yaw = std::max(max_var_yaw, s.C_L(1, 1));
	}
	br->sensor_std_range = static_cast<float>(std::sqrt(max_var_r));
	br->sensor_std_yaw = static_cast<float>(std::sqrt(max_var_yaw));
	br->sensor_std_pitch = br->sensor_std_yaw;
	return br;
}

}  // namespace codemark
