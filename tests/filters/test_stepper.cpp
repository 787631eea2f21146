// The rawlog stepper on small synthetic rawlogs of both formats.
#include <codemark/filters/stepper.h>
#include <gtest/gtest.h>
#include <codemark/landmark/camera.h>
#include <mrpt/img/CImage.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/serialization/CArchive.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "../pose/common.h"
#include "common.h"

using namespace codemark;
using namespace codemark::filters;
using namespace codemark::filters::test;
using mrpt::poses::CPose2D;

namespace
{
const double kT0 = 1700000000.0;

std::string tempFile(const std::string& name)
{
	const auto dir = std::filesystem::temp_directory_path() /
					 ("codemark_test_stepper_" + std::to_string(getpid()));
	std::filesystem::create_directories(dir);
	return (dir / name).string();
}

void writeRawlog(
	const std::string& path, const std::vector<mrpt::serialization::CSerializable::Ptr>& entries,
	bool plain = false)
{
	if (plain)
	{
		mrpt::io::CFileOutputStream f(path);
		auto ar = mrpt::serialization::archiveFrom(f);
		for (const auto& e : entries) ar << *e;
		return;
	}
	mrpt::io::CFileGZOutputStream f(path);
	auto ar = mrpt::serialization::archiveFrom(f);
	for (const auto& e : entries) ar << *e;
}

CObservationCodedLandmarks::Ptr landmarksAt(double t, const std::string& label = "CAM_LANDMARKS")
{
	auto o = CObservationCodedLandmarks::Create();
	o->sensorLabel = label;
	o->timestamp = t > 0 ? mrpt::Clock::fromDouble(t) : INVALID_TIMESTAMP;
	o->cameraPose = cameraOnRobot();
	return o;
}

// Odometry of a robot whose odometry pose is linear in time (so that linear
// interpolation is exact): x = t, y = 0.3 t, yaw = 0.2 t (t from kT0).
CPose2D odoPose(double dt) { return CPose2D(dt, 0.3 * dt, 0.2 * dt); }

mrpt::obs::CObservationOdometry::Ptr odoAt(double dt)
{
	auto o = mrpt::obs::CObservationOdometry::Create();
	o->sensorLabel = "ODOMETRY";
	o->timestamp = mrpt::Clock::fromDouble(kT0 + dt);
	o->odometry = odoPose(dt);
	return o;
}
}  // namespace

TEST(Stepper, InterpolatePose)
{
	const CPose2D a(0, 0, M_PI - 0.1), b(1, 2, -M_PI + 0.1);
	const CPose2D m = interpolatePose(1.0, a, 2.0, b, 1.5);
	EXPECT_NEAR(m.x(), 0.5, 1e-12);
	EXPECT_NEAR(m.y(), 1.0, 1e-12);
	EXPECT_NEAR(std::abs(m.phi()), M_PI, 1e-12);  // shortest arc across the cut
	EXPECT_NEAR(interpolatePose(1.0, a, 2.0, b, 5.0).x(), 1.0, 1e-12);	// clamped
}

TEST(Stepper, ObservationsOnlyInterpolatesOdometryToTheImageTime)
{
	// Odometry at 0.05, 0.15, ..., 0.95 s; camera frames at 0.32, 0.71 and
	// 1.50 s (after the last reading), never at a reading's time.
	std::vector<mrpt::serialization::CSerializable::Ptr> e;
	for (int k = 0; k < 10; ++k)
	{
		const double t = 0.05 + 0.1 * k;
		e.push_back(odoAt(t));
		if (k == 2) e.push_back(landmarksAt(kT0 + 0.32));
		if (k == 6)
		{
			e.push_back(landmarksAt(kT0 + 0.71));
			e.push_back(landmarksAt(kT0 + 0.71, "CAM2_LANDMARKS"));	 // a second camera, same time
		}
	}
	e.push_back(landmarksAt(kT0 + 1.50));
	const std::string path = tempFile("obs_only.rawlog");
	writeRawlog(path, e);

	RawlogStepper st(path);
	RawlogStep s;
	ASSERT_TRUE(st.next(s));
	EXPECT_EQ(s.index, 0);
	EXPECT_TRUE(s.has_timestamp);
	EXPECT_NEAR(s.timestamp - kT0, 0.32, 1e-6);
	EXPECT_EQ(s.observations.size(), 1u);

	ASSERT_TRUE(st.next(s));
	EXPECT_NEAR(s.timestamp - kT0, 0.71, 1e-6);
	EXPECT_EQ(s.observations.size(), 2u);  // both cameras in one step
	ASSERT_TRUE(s.odometry);
	const CPose2D inc = s.odometry->poseChange->getMeanVal();
	const CPose2D expected = odoPose(0.71) - odoPose(0.32);
	EXPECT_NEAR(inc.x(), expected.x(), 1e-6);
	EXPECT_NEAR(inc.y(), expected.y(), 1e-6);
	EXPECT_NEAR(inc.phi(), expected.phi(), 1e-6);
	// Not the increment between the last readings before each image.
	const CPose2D last_readings = odoPose(0.65) - odoPose(0.25);
	EXPECT_GT(std::abs(inc.x() - last_readings.x()), 0.005);
	// The composed covariance grows with the motion and is symmetric.
	mrpt::math::CMatrixDouble33 C;
	s.odometry->poseChange->getCovariance(C);
	EXPECT_GT(C(0, 0), 0);
	EXPECT_NEAR(C(0, 1), C(1, 0), 1e-15);

	ASSERT_TRUE(st.next(s));  // after the last reading: flushed at the end
	EXPECT_NEAR(s.timestamp - kT0, 1.50, 1e-6);
	ASSERT_TRUE(s.odometry);
	const CPose2D inc2 = s.odometry->poseChange->getMeanVal();
	const CPose2D expected2 = odoPose(0.95) - odoPose(0.71);
	EXPECT_NEAR(inc2.x(), expected2.x(), 1e-6);
	EXPECT_FALSE(st.next(s));
	EXPECT_FALSE(st.actionsObservationsFormat());
}

TEST(Stepper, ActionsObservationsComposesTheActionsSinceTheLastFrame)
{
	auto act = [](const CPose2D& u)
	{
		auto ac = mrpt::obs::CActionCollection::Create();
		ac->insert(odometry(u, 0.01, 0.02));
		return ac;
	};
	auto sf = [](double t)
	{
		auto f = mrpt::obs::CSensoryFrame::Create();
		f->insert(landmarksAt(t));
		return f;
	};
	const CPose2D u1(0.1, 0, 0.5), u2(0.2, 0.05, -0.1), u3(0.3, 0, 0);
	const std::string path = tempFile("actions_observations.rawlog");
	writeRawlog(
		path, {act(CPose2D()), sf(kT0), act(u1), mrpt::obs::CSensoryFrame::Create(), act(u2),
			   sf(kT0 + 1), act(u3), sf(kT0 + 2)});
	RawlogStepper st(path);
	RawlogStep s;
	ASSERT_TRUE(st.next(s));
	ASSERT_TRUE(st.next(s));
	ASSERT_TRUE(s.odometry);
	const CPose2D inc = s.odometry->poseChange->getMeanVal();
	const CPose2D expected = u1 + u2;
	EXPECT_NEAR(inc.x(), expected.x(), 1e-12);
	EXPECT_NEAR(inc.y(), expected.y(), 1e-12);
	EXPECT_NEAR(inc.phi(), expected.phi(), 1e-12);
	mrpt::math::CMatrixDouble33 C;
	s.odometry->poseChange->getCovariance(C);
	EXPECT_NEAR(C(2, 2), 2 * 0.02 * 0.02, 1e-8);  // both yaw variances
	EXPECT_GT(C(1, 1), 0.01 * 0.01);  // the first yaw noise moves the second step sideways
	ASSERT_TRUE(st.next(s));
	EXPECT_NEAR(s.odometry->poseChange->getMeanVal().x(), 0.3, 1e-12);
	EXPECT_FALSE(st.next(s));
	EXPECT_TRUE(st.actionsObservationsFormat());
}

// MRPT robot-path ground truth: row 0 is the start pose, row k the pose
// after k actions. A sensory frame ahead of the first action (kf-slam_demo
// has one; kf-slam skips it) is taken at row 0; a frame without camera
// observations still counts its action.
TEST(Stepper, ActionsObservationsStepsCountTheActionsBeforeThem)
{
	auto act = [](const CPose2D& u)
	{
		auto ac = mrpt::obs::CActionCollection::Create();
		ac->insert(odometry(u, 0.01, 0.02));
		return ac;
	};
	auto sf = [](double t)
	{
		auto f = mrpt::obs::CSensoryFrame::Create();
		f->insert(landmarksAt(t));
		return f;
	};
	const CPose2D u(0.1, 0, 0);
	const std::string path = tempFile("actions_count.rawlog");
	writeRawlog(
		path, {sf(kT0), act(u), sf(kT0 + 1), act(u), mrpt::obs::CSensoryFrame::Create(), act(u),
			   sf(kT0 + 3)});
	RawlogStepper st(path);
	RawlogStep s;
	std::vector<long> actions, indices;
	while (st.next(s))
	{
		actions.push_back(s.actions);
		indices.push_back(s.index);
	}
	EXPECT_EQ(actions, (std::vector<long>{0, 1, 3}));
	EXPECT_EQ(indices, (std::vector<long>{0, 1, 2}));

	// Observations-only rawlogs have no actions.
	const std::string obs_only = tempFile("obs_only_count.rawlog");
	writeRawlog(obs_only, {landmarksAt(kT0), landmarksAt(kT0 + 1)});
	RawlogStepper st2(obs_only);
	ASSERT_TRUE(st2.next(s));
	EXPECT_EQ(s.actions, -1);
}

TEST(Stepper, AnnotatedImagesAreNotDetectedAgainButBareOnesAre)
{
	auto img = mrpt::obs::CObservationImage::Create();
	img->sensorLabel = "CAM";
	img->timestamp = mrpt::Clock::fromDouble(kT0);
	img->image.setExternalStorage("does_not_exist.png");
	const std::string annotated = tempFile("annotated.rawlog");
	writeRawlog(annotated, {img, landmarksAt(kT0)});
	RawlogStepper st(annotated);
	RawlogStep s;
	ASSERT_TRUE(st.next(s));  // the missing image is never loaded
	EXPECT_EQ(s.images_detected, 0);
	EXPECT_EQ(s.observations.size(), 1u);

	const std::string bare = tempFile("bare.rawlog");
	writeRawlog(bare, {odoAt(0), img});
	RawlogStepper st2(bare);
	try
	{
		st2.next(s);
		FAIL() << "a missing image file must stop the run";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("entry #1"), std::string::npos) << e.what();
	}
}

// Each stepper loads its own rawlog's external images, also while another
// stepper reads another rawlog (codemark-bench runs datasets in parallel):
// MRPT's images folder is process-wide, and the second stepper's rawlog
// must not redirect the first one's relative file names to its own folder.
TEST(Stepper, ExternalImagesComeFromTheirOwnRawlogsFolder)
{
	const auto dir = std::filesystem::path(tempFile("two_rawlogs"));
	std::filesystem::create_directories(dir / "with_Images");
	std::filesystem::create_directories(dir / "without_Images");
	const CameraModel cam = CameraModel::paperDefault();
	mrpt::img::CImage grey(cam.width(), cam.height(), mrpt::img::CH_RGB);
	grey.filledRectangle(0, 0, cam.width() - 1, cam.height() - 1, mrpt::img::TColor(128, 128, 128));
	ASSERT_TRUE(grey.saveToFile((dir / "with_Images" / "frame.png").string()));
	const auto image = [&]
	{
		auto img = mrpt::obs::CObservationImage::Create();
		img->sensorLabel = "CAM";
		img->timestamp = mrpt::Clock::fromDouble(kT0);
		img->cameraParams = cam.params();
		img->image.setExternalStorage("frame.png");
		return img;
	};
	const std::string with = (dir / "with.rawlog").string(),
					  without = (dir / "without.rawlog").string();
	writeRawlog(with, {odoAt(0), image()});
	writeRawlog(without, {odoAt(0), image()});
	RawlogStepper a(with);
	RawlogStepper b(without);  // opened after a: its folder holds no frame.png
	RawlogStep s;
	ASSERT_TRUE(a.next(s));
	EXPECT_EQ(s.images_detected, 1);
	EXPECT_THROW(b.next(s), std::runtime_error);
}

TEST(Stepper, CorruptEntryNamesItsIndexAndNoTimestampsGiveStepIndices)
{
	{
		const std::string nots = tempFile("no_timestamps.rawlog");
		writeRawlog(nots, {landmarksAt(0), landmarksAt(0)});
		RawlogStepper st(nots);
		RawlogStep s;
		int n = 0;
		while (st.next(s))
		{
			EXPECT_FALSE(s.has_timestamp);
			EXPECT_EQ(s.timestamp, static_cast<double>(s.index));
			++n;
		}
		EXPECT_EQ(n, 2);
	}
	const std::string path = tempFile("corrupt.rawlog");
	writeRawlog(path, {landmarksAt(0), landmarksAt(0)}, true);
	{
		// Append a garbage tail to the (uncompressed) rawlog.
		std::ofstream f(path, std::ios::app | std::ios::binary);
		f << "this is not an MRPT object";
	}
	RawlogStepper st(path);
	RawlogStep s;
	try
	{
		while (st.next(s))
		{
		}
		FAIL() << "the corrupt tail must throw";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("entry #"), std::string::npos) << e.what();
	}
	EXPECT_THROW(RawlogStepper(tempFile("missing.rawlog")), std::runtime_error);
}

// NaN or inf in odometry or in a sighting: an error naming the entry and
// what is wrong, never a silently wrong estimate.
TEST(Stepper, NonFiniteOdometryAndSightingsNameTheEntry)
{
	auto expectError = [](const std::string& path, const std::string& what, long entry)
	{
		RawlogStepper st(path);
		RawlogStep s;
		try
		{
			while (st.next(s))
			{
			}
			FAIL() << path << ": must throw";
		}
		catch (const std::runtime_error& e)
		{
			const std::string m = e.what();
			EXPECT_NE(m.find("entry #" + std::to_string(entry)), std::string::npos) << m;
			EXPECT_NE(m.find(what), std::string::npos) << m;
		}
	};
	auto bad_odo = odoAt(0.2);
	bad_odo->odometry = CPose2D(std::nan(""), 0, 0);
	const std::string p1 = tempFile("nan_odometry.rawlog");
	writeRawlog(p1, {odoAt(0), landmarksAt(kT0 + 0.1), bad_odo});
	expectError(p1, "not finite", 2);

	auto lm = landmarksAt(kT0 + 0.1);
	CObservationCodedLandmarks::TSighting t;
	t.id = 4;
	t.L = Eigen::Vector3d(2.0, std::numeric_limits<double>::infinity(), 0.0);
	t.C_L = Eigen::Matrix3d::Identity() * 1e-4;
	lm->sightings.push_back(t);
	const std::string p2 = tempFile("inf_sighting.rawlog");
	writeRawlog(p2, {landmarksAt(kT0), lm});
	expectError(p2, "non-finite", 1);  // refused when the sighting is read
}

// Sightings seen beyond max_view_angle_deg from the landmark's normal are
// dropped and counted; the others pass.
TEST(Stepper, DropsObliqueSightings)
{
	auto lm = landmarksAt(kT0);
	CObservationCodedLandmarks::TSighting t;
	t.C_L = Eigen::Matrix3d::Identity() * 1e-4;
	t.id = 1, t.L = Eigen::Vector3d(2.0, 0.2, 0.5);	 // 40 deg: kept
	lm->sightings.push_back(t);
	t.id = 2, t.L = Eigen::Vector3d(2.0, -0.3, -1.0);  // 74 deg: dropped
	lm->sightings.push_back(t);
	const std::string path = tempFile("oblique.rawlog");
	writeRawlog(path, {lm});
	for (const double max_deg : {60.0, 90.0})
	{
		StepperOptions o;
		o.max_view_angle_deg = max_deg;
		RawlogStepper st(path, o);
		RawlogStep s;
		ASSERT_TRUE(st.next(s));
		std::vector<int> ids;
		for (const auto& obs : s.observations)
			if (const auto c = std::dynamic_pointer_cast<CObservationCodedLandmarks>(obs))
				for (const auto& x : c->sightings) ids.push_back(x.id);
		if (max_deg < 90)
		{
			EXPECT_EQ(ids, std::vector<int>({1}));
			EXPECT_EQ(s.sightings_too_oblique, 1);
		}
		else
		{
			EXPECT_EQ(ids, std::vector<int>({1, 2}));
			EXPECT_EQ(s.sightings_too_oblique, 0);
		}
	}
}

// A rawlog annotated with one calibration, stepped with another
// (codemark-localize --calibration): each sighting is measured again from
// its stored corners and camera under the pipeline's C_P; without
// remeasure_sightings the stored covariances stay.
TEST(Stepper, RemeasuresAnnotatedSightingsUnderThePipelinesCalibration)
{
	const CameraModel cam;
	const LandmarkGeometry g;
	Detection d;
	d.id = 7;
	d.corners = codemark::test::projectCorners(codemark::test::cameraAt(2.5, 0.4), cam, g);
	pose::PoseOptions recorded;
	recorded.sigma_px = 0.02;
	auto lm = landmarksAt(kT0);
	lm->camera = cam.params();
	lm->sightings.push_back(
		CObservationCodedLandmarks::TSighting::From(d, pose::measure(d, cam, g, recorded)));
	const std::string path = tempFile("remeasure.rawlog");
	writeRawlog(path, {lm});

	pipeline::PipelineOptions pipe;
	pipe.pose = recorded;
	pipe.pose.sigma_px = 0.2;  // 10x the recorded noise
	const pose::Measurement expected = pose::measure(d, cam, g, pipe.pose);
	for (const bool remeasure : {false, true})
	{
		StepperOptions o;
		o.remeasure_sightings = remeasure;
		RawlogStepper st(path, o, pipe);
		RawlogStep s;
		ASSERT_TRUE(st.next(s));
		const auto c = s.observations.getObservationByClass<CObservationCodedLandmarks>();
		ASSERT_TRUE(c);
		ASSERT_EQ(c->sightings.size(), 1u);
		const auto& t = c->sightings[0];
		EXPECT_EQ(t.id, 7);
		const Eigen::Matrix3d want = remeasure ? expected.C_L : lm->sightings[0].C_L;
		EXPECT_LT((t.C_L - want).norm(), 1e-12 * want.norm()) << remeasure;
		EXPECT_LT((t.L - expected.L).norm(), 1e-6);
		if (remeasure)
		{
			EXPECT_NEAR(t.C_P(0, 0), 0.04, 1e-12);
		}
	}
}
