#include <codemark/sim/dataset.h>
#include <gtest/gtest.h>

#include "../common/serialization_io.h"
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/img/CImage.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/random/RandomGenerators.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/filesystem.h>
#include <mrpt/config/CConfigFile.h>

#include <fstream>
#include <unistd.h>
#include <sstream>

using namespace codemark;
using namespace codemark::sim;

namespace
{
std::string tempDir(const std::string& name)
{
	// One folder per process: ctest runs tests in parallel processes.
	const std::string d =
		::testing::TempDir() + "codemark_dataset_" + std::to_string(getpid()) + "_" + name;
	mrpt::system::deleteFilesInDirectory(d, true);
	return d;
}

DatasetOptions smallOptions()
{
	DatasetOptions o;
	o.render.background = Background::Flat;
	o.frame_rate_hz = 5;
	o.odometry_rate_hz = 12;
	o.seed = 3;
	return o;
}

std::vector<std::vector<double>> readRows(const std::string& path)
{
	std::ifstream f(path);
	std::vector<std::vector<double>> rows;
	for (std::string line; std::getline(f, line);)
	{
		if (line.empty() || line[0] == '#') continue;
		std::istringstream ss(line);
		std::vector<double> r;
		for (double v; ss >> v;) r.push_back(v);
		rows.push_back(r);
	}
	return rows;
}
}  // namespace

TEST(Dataset, RoomMapFacesInward)
{
	DatasetOptions o;
	const auto m = generateRoomMap(o);
	ASSERT_EQ(m.landmarks.size(), 12u);
	for (const auto& l : m.landmarks)
	{
		// The outward normal points into the room: a step along it from the
		// wall stays inside.
		const double x = l.x_m + 0.1 * std::cos(l.yaw_rad), y = l.y_m + 0.1 * std::sin(l.yaw_rad);
		EXPECT_GT(x, 0);
		EXPECT_LT(x, o.room_width_m);
		EXPECT_GT(y, 0);
		EXPECT_LT(y, o.room_depth_m);
	}
}

TEST(Dataset, LoopIsClosedAndSmooth)
{
	DatasetOptions o;
	const auto loop = generateLoop(o, 10.0);
	ASSERT_GT(loop.size(), 50u);
	const double step = o.speed_mps / 10.0;
	for (std::size_t i = 1; i < loop.size(); ++i)
	{
		const auto d = loop[i].pose - loop[i - 1].pose;
		EXPECT_NEAR(d.norm(), step, 0.01 * step + 1e-9) << i;
		EXPECT_LT(std::abs(d.phi()), step / o.corner_radius_m + 1e-9);
		EXPECT_NEAR(loop[i].t - loop[i - 1].t, 0.1, 1e-6);	// UNIX times: ulp 2.4e-7 s
	}
	EXPECT_LT((loop.back().pose - loop.front().pose).norm(), step + 1e-9);
}

TEST(Dataset, ActionsObservationsRawlog)
{
	const auto dir = tempDir("ao");
	auto o = smallOptions();
	const auto sum = writeDataset(o, dir, false, {}, 15);
	EXPECT_EQ(sum.frames, 15);
	const auto objs = codemark::test::readRawlog(dir + "/dataset.rawlog");
	ASSERT_EQ(objs.size(), 30u);
	const auto gt = readRows(dir + "/gt_path.txt");
	ASSERT_EQ(gt.size(), 15u);
	mrpt::img::CImage::setImagesPathBase(dir + "/dataset_Images");
	mrpt::poses::CPose2D odo(gt[0][1], gt[0][2], gt[0][3]);
	for (int k = 0; k < 15; ++k)
	{
		auto acts = std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(objs[2 * k]);
		auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(objs[2 * k + 1]);
		ASSERT_TRUE(acts && sf) << k;
		auto mv = acts->getBestMovementEstimation();
		ASSERT_TRUE(mv);
		odo = odo + mv->rawOdometryIncrementReading;
		// Odometry drifts a little from the truth, never wildly.
		EXPECT_LT(std::hypot(odo.x() - gt[k][1], odo.y() - gt[k][2]), 0.05 + 0.02 * k) << k;
		auto img = sf->getObservationByClass<mrpt::obs::CObservationImage>();
		ASSERT_TRUE(img);
		EXPECT_EQ(img->sensorLabel, "CAM");
		EXPECT_NEAR(mrpt::Clock::toDouble(img->timestamp), gt[k][0], 1e-6);
		EXPECT_TRUE(img->image.isExternallyStored());
		EXPECT_EQ(img->image.getWidth(), 640u);	 // loads the external file
		EXPECT_DOUBLE_EQ(img->cameraParams.fx(), 800);
	}
	EXPECT_EQ(LandmarkMap::load(dir + "/map.txt").landmarks.size(), 12u);
}

TEST(Dataset, OutputFolderIsCreatedWithItsParents)
{
	const auto base = tempDir("nested");
	const auto dir = base + "/a/b";
	EXPECT_EQ(writeDataset(smallOptions(), dir, false, {}, 2).frames, 2);
	EXPECT_TRUE(mrpt::system::fileExists(dir + "/dataset.rawlog"));
	// Under a regular file no folder can be made: an error naming it.
	std::ofstream(base + "/file") << "x";
	try
	{
		writeDataset(smallOptions(), base + "/file/c", false, {}, 2);
		ADD_FAILURE() << "no error";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find(base + "/file/c"), std::string::npos) << e.what();
	}
}

TEST(Dataset, ObservationsOnlyHasOdometryAtItsOwnTimes)
{
	const auto dir = tempDir("obs");
	auto o = smallOptions();
	const auto sum = writeDataset(o, dir, true, {}, 10);
	const auto objs = codemark::test::readRawlog(dir + "/dataset.rawlog");
	int images = 0, odos = 0, odo_between = 0;
	double last_t = -1, last_img_t = -1;
	for (const auto& obj : objs)
	{
		auto obs = std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj);
		ASSERT_TRUE(obs);
		const double t = mrpt::Clock::toDouble(obs->timestamp);
		EXPECT_GE(t, last_t);  // time-ordered
		last_t = t;
		if (std::dynamic_pointer_cast<mrpt::obs::CObservationImage>(obj))
		{
			++images;
			last_img_t = t;
		}
		else if (std::dynamic_pointer_cast<mrpt::obs::CObservationOdometry>(obj))
		{
			++odos;
			if (last_img_t >= 0 && t > last_img_t) ++odo_between;
		}
	}
	EXPECT_EQ(images, 10);
	EXPECT_EQ(odos, sum.odometry_readings);
	EXPECT_GT(odos, 2 * images);  // 12 Hz against 5 Hz
	EXPECT_GT(odo_between, 0);
}

TEST(Dataset, DeterministicForASeed)
{
	auto o = smallOptions();
	o.render.noise_sigma = 2;
	const auto a = tempDir("da"), b = tempDir("db");
	writeDataset(o, a, false, {}, 5);
	// Whatever the process drew before must not matter: one Gaussian draw
	// leaves MRPT's generator with a saved second value, which its
	// randomize(seed) alone does not clear (codemark::reseedMrptRandom).
	mrpt::random::getRandomGenerator().drawGaussian1D_normalized();
	writeDataset(o, b, false, {}, 5);
	auto slurp = [](const std::string& p)
	{
		std::ifstream f(p, std::ios::binary);
		std::stringstream s;
		s << f.rdbuf();
		return s.str();
	};
	EXPECT_EQ(slurp(a + "/gt_path.txt"), slurp(b + "/gt_path.txt"));
	EXPECT_EQ(slurp(a + "/dataset.rawlog"), slurp(b + "/dataset.rawlog"));
	EXPECT_EQ(
		slurp(a + "/dataset_Images/CAM_000004.png"), slurp(b + "/dataset_Images/CAM_000004.png"));
	o.seed = 4;
	const auto c = tempDir("dc");
	writeDataset(o, c, false, {}, 5);
	EXPECT_NE(slurp(a + "/dataset.rawlog"), slurp(c + "/dataset.rawlog"));
	// The same in the observations-only format (odometry at its own rate).
	o.seed = 3;
	const auto d = tempDir("dd"), e = tempDir("de");
	writeDataset(o, d, true, {}, 5);
	mrpt::random::getRandomGenerator().drawGaussian1D_normalized();
	writeDataset(o, e, true, {}, 5);
	EXPECT_EQ(slurp(d + "/dataset.rawlog"), slurp(e + "/dataset.rawlog"));
}

TEST(Dataset, TrajectoryFileErrorsNameTheLine)
{
	const std::string p = ::testing::TempDir() + "traj_bad.txt";
	std::ofstream(p) << "0 0 0 0\n1 1 0 0\n2 1 x 0\n";
	DatasetOptions o;
	o.trajectory_file = p;
	try
	{
		sampleTrajectory(o, 5);
		FAIL();
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("traj_bad.txt:3"), std::string::npos) << e.what();
	}
	std::ofstream(p) << "0 0 0 0\n1 1 0 0\n2 2 0 0\n";
	const auto poses = sampleTrajectory(o, 2);
	ASSERT_EQ(poses.size(), 5u);
	EXPECT_NEAR(poses[1].pose.x(), 0.5, 1e-12);
}

TEST(Dataset, ShippedIniLoads)
{
	mrpt::config::CConfigFile cfg(std::string(CODEMARK_SOURCE_SHARE_DIR) + "/simul.ini");
	DatasetOptions o;
	o.loadFromConfigFile(cfg, "");
	EXPECT_EQ(o.render.background, Background::Textured);
	EXPECT_DOUBLE_EQ(o.motion.gaussianModel.a1, 0.02);
	EXPECT_EQ(o.sensor_label, "CAM");
}
