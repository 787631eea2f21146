#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <gtest/gtest.h>

#include "../common/serialization_io.h"
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/io/CFileInputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/rtti/CObject.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

#include <Eigen/Dense>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>

using codemark::CObservationCodedLandmarks;

namespace
{
const std::string kGolden = std::string(CODEMARK_TEST_DATA_DIR) + "/coded_landmarks_v0.bin";

// A filled observation. Never change it: the golden file holds it as written
// by serialization version 0.
CObservationCodedLandmarks makeFilled()
{
	CObservationCodedLandmarks o;
	o.sensorLabel = "CAM_LANDMARKS";
	o.timestamp = mrpt::Clock::fromDouble(1700000000.125);
	o.cameraPose = mrpt::poses::CPose3D(0.1, -0.05, 0.6, -M_PI / 2, 0, -M_PI / 2);
	o.camera.ncols = 640;
	o.camera.nrows = 480;
	o.camera.setIntrinsicParamsFromValues(800, 800, 319.5, 239.5);
	for (int k = 0; k < 2; ++k)
	{
		CObservationCodedLandmarks::TSighting s;
		s.id = 37 + 100 * k;
		for (int i = 0; i < 4; ++i) s.corners[i] = {100.25 + 10 * i + k, 200.5 - 3 * i};
		s.P = {-12.5 + k, 40.25, 30.5, 41.75};
		s.C_P = Eigen::Vector4d(0.0025, 0.0025, 0.0025, 0.0025).asDiagonal();
		s.L = {1.5 + k, 0.02, -0.15};
		s.C_L << 1e-6, 2e-8, 1e-7, 2e-8, 3e-8, 4e-9, 1e-7, 4e-9, 5e-5;
		s.pose_in_landmark = {1.48, -0.2, M_PI - 0.15};
		s.C_R << 2e-5, 1e-6, 0, 1e-6, 8e-5, 3e-6, 0, 3e-6, 5e-5;
		s.quality.line_rms_px = {0.01, 0.02, 0.03, 0.04};
		s.quality.line_support = {60, 61, 62, 63};
		s.quality.code_margin = 55.5;
		s.quality.area_px = 3300;
		s.quality.corner_sigma_px = 0.02;
		s.method =
			k ? codemark::pose::PoseMethod::General6Dof : codemark::pose::PoseMethod::ClosedForm;
		o.sightings.push_back(s);
	}
	return o;
}

void expectSame(const CObservationCodedLandmarks& a, const CObservationCodedLandmarks& b)
{
	EXPECT_EQ(a.sensorLabel, b.sensorLabel);
	EXPECT_EQ(a.timestamp, b.timestamp);
	EXPECT_EQ(a.cameraPose, b.cameraPose);
	EXPECT_EQ(a.camera, b.camera);
	ASSERT_EQ(a.sightings.size(), b.sightings.size());
	for (std::size_t i = 0; i < a.sightings.size(); ++i)
	{
		const auto &x = a.sightings[i], &y = b.sightings[i];
		EXPECT_EQ(x.id, y.id);
		for (int k = 0; k < 4; ++k) EXPECT_EQ(x.corners[k], y.corners[k]);
		EXPECT_EQ(x.P, y.P);
		EXPECT_EQ(x.C_P, y.C_P);
		EXPECT_EQ(x.L, y.L);
		EXPECT_EQ(x.C_L, y.C_L);
		EXPECT_EQ(x.pose_in_landmark, y.pose_in_landmark);
		EXPECT_EQ(x.C_R, y.C_R);
		EXPECT_EQ(x.quality.line_rms_px, y.quality.line_rms_px);
		EXPECT_EQ(x.quality.line_support, y.quality.line_support);
		EXPECT_EQ(x.quality.code_margin, y.quality.code_margin);
		EXPECT_EQ(x.quality.area_px, y.quality.area_px);
		EXPECT_EQ(x.quality.corner_sigma_px, y.quality.corner_sigma_px);
		EXPECT_EQ(x.quality.fill_clipped, y.quality.fill_clipped);
		EXPECT_EQ(x.quality.image_noise_grey, y.quality.image_noise_grey);
		EXPECT_EQ(x.quality.edge_bend_px, y.quality.edge_bend_px);
		EXPECT_EQ(x.quality.edge_bend_se_px, y.quality.edge_bend_se_px);
		EXPECT_EQ(x.method, y.method);
	}
}
}  // namespace

TEST(CodedLandmarksObs, RegisteredOnLoad)
{
	const auto* c = mrpt::rtti::findRegisteredClass("codemark::CObservationCodedLandmarks");
	ASSERT_NE(c, nullptr);
	auto obj = c->createObject();
	EXPECT_TRUE(std::dynamic_pointer_cast<CObservationCodedLandmarks>(obj));
}

TEST(CodedLandmarksObs, RoundTripDefaultAndFilled)
{
	for (const auto& o : {CObservationCodedLandmarks(), makeFilled()})
	{
		auto back = std::dynamic_pointer_cast<CObservationCodedLandmarks>(
			codemark::test::fromBytes(codemark::test::toBytes(o)));
		ASSERT_TRUE(back);
		expectSame(o, *back);
	}
}

TEST(CodedLandmarksObs, GoldenFileStaysReadable)
{
	if (std::getenv("CODEMARK_WRITE_GOLDEN"))
	{
		const auto b = codemark::test::toBytes(makeFilled());
		std::ofstream(kGolden, std::ios::binary)
			.write(reinterpret_cast<const char*>(b.data()), b.size());
	}
	std::ifstream f(kGolden, std::ios::binary);
	ASSERT_TRUE(f.good()) << kGolden;
	const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(f)), {});
	auto back =
		std::dynamic_pointer_cast<CObservationCodedLandmarks>(codemark::test::fromBytes(bytes));
	ASSERT_TRUE(back);
	expectSame(makeFilled(), *back);
}

TEST(CodedLandmarksObs, ClippedSidesRoundTrip)
{
	// Version 1's clipped-sides bits (the golden file above is version 0:
	// read back as none clipped).
	auto o = makeFilled();
	o.sightings[0].quality.fill_clipped = {{true, true, false, false}};
	o.sightings[1].quality.fill_clipped = {{false, true, false, true}};
	const auto back = std::dynamic_pointer_cast<CObservationCodedLandmarks>(
		codemark::test::fromBytes(codemark::test::toBytes(o)));
	ASSERT_TRUE(back);
	expectSame(o, *back);
}

TEST(CodedLandmarksObs, ImageNoiseRoundTrip)
{
	// Version 2's image noise (the golden file, version 0, reads it as 0,
	// not measured).
	auto o = makeFilled();
	o.sightings[0].quality.image_noise_grey = 2.125;
	o.sightings[1].quality.image_noise_grey = 5.5;
	const auto back = std::dynamic_pointer_cast<CObservationCodedLandmarks>(
		codemark::test::fromBytes(codemark::test::toBytes(o)));
	ASSERT_TRUE(back);
	expectSame(o, *back);
	// A negative noise is corrupt data, not a measurement.
	o.sightings[1].quality.image_noise_grey = -1;
	EXPECT_ANY_THROW(codemark::test::fromBytes(codemark::test::toBytes(o)));
}

TEST(CodedLandmarksObs, EdgeBendRoundTrip)
{
	// Version 3's edge bend and its standard error (older versions read
	// them as 0, not measured).
	auto o = makeFilled();
	o.sightings[0].quality.edge_bend_px = 0.25;
	o.sightings[0].quality.edge_bend_se_px = 0.03125;
	o.sightings[1].quality.edge_bend_px = -0.125;
	o.sightings[1].quality.edge_bend_se_px = 0.0078125;
	const auto back = std::dynamic_pointer_cast<CObservationCodedLandmarks>(
		codemark::test::fromBytes(codemark::test::toBytes(o)));
	ASSERT_TRUE(back);
	expectSame(o, *back);
	// A negative standard error is corrupt data.
	o.sightings[1].quality.edge_bend_se_px = -0.5;
	EXPECT_ANY_THROW(codemark::test::fromBytes(codemark::test::toBytes(o)));
}

TEST(CodedLandmarksObs, TruncatedBytesThrow)
{
	const auto b = codemark::test::toBytes(makeFilled());
	for (std::size_t n = 0; n < b.size(); n += 7)
	{
		std::vector<uint8_t> cut(b.begin(), b.begin() + n);
		EXPECT_ANY_THROW(codemark::test::fromBytes(cut)) << "truncated at " << n;
	}
}

TEST(CodedLandmarksObs, BitFlipsNeverCrash)
{
	const auto b = codemark::test::toBytes(makeFilled());
	std::mt19937 rng(11);
	int thrown = 0, parsed = 0;
	for (int trial = 0; trial < 1000; ++trial)
	{
		auto f = b;
		const int flips = 1 + trial % 4;
		for (int k = 0; k < flips; ++k)
			f[rng() % f.size()] ^= static_cast<uint8_t>(1u << (rng() % 8));
		try
		{
			auto o = codemark::test::fromBytes(f);
			++parsed;
			if (auto c = std::dynamic_pointer_cast<CObservationCodedLandmarks>(o))
			{
				for (const auto& s : c->sightings) EXPECT_TRUE(s.id >= 0 && s.id <= 255);
				EXPECT_LE(c->sightings.size(), CObservationCodedLandmarks::kMaxSightings);
			}
		}
		catch (const std::exception&)
		{
			++thrown;
		}
	}
	EXPECT_GT(thrown, 0);
	EXPECT_GT(parsed, 0);
}

TEST(CodedLandmarksObs, UnknownVersionThrows)
{
	auto b = codemark::test::toBytes(makeFilled());
	// MRPT's object header: 0x80|len, class name, version byte.
	const std::string name = "codemark::CObservationCodedLandmarks";
	const auto it = std::search(b.begin(), b.end(), name.begin(), name.end());
	ASSERT_NE(it, b.end());
	*(it + name.size()) = 99;
	EXPECT_ANY_THROW(codemark::test::fromBytes(b));
}

TEST(CodedLandmarksObs, BearingRangeTwin)
{
	const auto o = makeFilled();
	const auto br = o.toBearingRange();
	EXPECT_EQ(br->sensorLabel, "CAM_BR");
	EXPECT_EQ(br->timestamp, o.timestamp);
	ASSERT_EQ(br->sensedData.size(), 2u);
	EXPECT_TRUE(br->validCovariances);
	for (std::size_t i = 0; i < 2; ++i)
	{
		const auto& m = br->sensedData[i];
		const auto& s = o.sightings[i];
		EXPECT_EQ(m.landmarkID, s.id);
		EXPECT_FLOAT_EQ(m.range, static_cast<float>(s.L[0]));
		EXPECT_FLOAT_EQ(m.yaw, static_cast<float>(s.L[1]));
		EXPECT_EQ(m.pitch, 0.f);
		EXPECT_DOUBLE_EQ(m.covariance(0, 0), s.C_L(0, 0));
		EXPECT_DOUBLE_EQ(m.covariance(0, 1), s.C_L(0, 1));
		EXPECT_DOUBLE_EQ(m.covariance(1, 1), s.C_L(1, 1));
		EXPECT_DOUBLE_EQ(m.covariance(0, 2), 0.0);
		EXPECT_GT(m.covariance(2, 2), 0.0);
	}
	// x-forward sensor pose at the camera's position, heading of the optical
	// axis: the camera of makeFilled() looks along the robot's +x.
	const auto& sp = br->sensorLocationOnRobot;
	EXPECT_NEAR(sp.x(), 0.1, 1e-12);
	EXPECT_NEAR(sp.y(), -0.05, 1e-12);
	EXPECT_NEAR(sp.z(), 0.6, 1e-12);
	EXPECT_NEAR(sp.yaw(), 0.0, 1e-12);
	EXPECT_NEAR(sp.pitch(), 0.0, 1e-12);
	EXPECT_NEAR(br->fieldOfView_yaw, 2 * std::atan(320.0 / 800.0), 1e-6);
	EXPECT_EQ(o.toBearingRange("OTHER")->sensorLabel, "OTHER");
}

TEST(CodedLandmarksObs, CameraHeadingFromOpticalPose)
{
	// A camera turned 30 deg to the left on the robot.
	const auto cam = mrpt::poses::CPose3D(0, 0, 0.5, M_PI / 6, 0, 0) +
					 mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
	EXPECT_NEAR(codemark::xForwardPoseOfCamera(cam).yaw(), M_PI / 6, 1e-12);
}

TEST(CodedLandmarksObs, DescriptionIsReadable)
{
	std::ostringstream s;
	makeFilled().getDescriptionAsText(s);
	const std::string t = s.str();
	EXPECT_NE(t.find("ID 37"), std::string::npos);
	EXPECT_NE(t.find("range l2"), std::string::npos);
	EXPECT_NE(t.find("deg"), std::string::npos);
	EXPECT_NE(t.find("corners"), std::string::npos);
}

TEST(CodedLandmarksObs, NonFiniteMeasurementIsCorruptData)
{
	// Written as is (serializeTo does not judge), refused on reading.
	for (int field = 0; field < 3; ++field)
	{
		auto o = makeFilled();
		ASSERT_FALSE(o.sightings.empty());
		auto& s = o.sightings.back();
		if (field == 0) s.L.x() = std::numeric_limits<double>::quiet_NaN();
		if (field == 1) s.P(2) = std::numeric_limits<double>::infinity();
		if (field == 2) s.C_L(1, 1) = -std::numeric_limits<double>::infinity();
		EXPECT_ANY_THROW(codemark::test::fromBytes(codemark::test::toBytes(o)))
			<< "field " << field;
	}
}
