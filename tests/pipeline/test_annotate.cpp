#include <codemark/filters/stepper.h>
#include <codemark/landmark/truth.h>
#include <codemark/pose/closed_form.h>
#include <codemark/pipeline/annotate.h>
#include <codemark/sim/dataset.h>
#include <gtest/gtest.h>

#include "../common/serialization_io.h"
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/filesystem.h>

#include <cstdio>
#include <fstream>
#include <unistd.h>
#include <sstream>

using namespace codemark;

namespace
{
std::string freshDir(const std::string& name)
{
	// One folder per process: ctest runs each TEST in its own process, in
	// parallel, and the shared dataset must not be rewritten under a reader.
	const std::string d =
		::testing::TempDir() + "codemark_pipeline_" + std::to_string(getpid()) + "_" + name;
	mrpt::system::deleteFilesInDirectory(d, true);
	mrpt::system::createDirectory(d);
	return d;
}

// A simulated dataset, written once per format and shared by the tests.
struct Dataset
{
	std::string dir;
	sim::DatasetSummary sum;
};
const Dataset& dataset(bool obs_only)
{
	static std::map<bool, Dataset> cache;
	auto it = cache.find(obs_only);
	if (it != cache.end()) return it->second;
	Dataset d;
	d.dir = freshDir(obs_only ? "obs" : "ao");
	sim::DatasetOptions o;	// the realistic defaults: texture, noise 2, blur 0.8
	o.seed = 7;
	d.sum = sim::writeDataset(o, d.dir, obs_only, {}, 80);
	return cache[obs_only] = d;
}

std::string slurp(const std::string& p)
{
	std::ifstream f(p, std::ios::binary);
	std::stringstream s;
	s << f.rdbuf();
	return s.str();
}
}  // namespace

TEST(Annotate, ImagesDirectoryConvention)
{
	EXPECT_EQ(pipeline::imagesDirectoryOf("dir/x.rawlog"), "dir/x_Images");
	EXPECT_EQ(pipeline::imagesDirectoryOf("/a/b/data.set.rawlog"), "/a/b/data.set_Images");
	EXPECT_EQ(pipeline::imagesDirectoryOf("x.rawlog"), "./x_Images");
}

TEST(Annotate, SightingsMatchTheSimulatorsTruth)
{
	const auto& d = dataset(false);
	const std::string out = d.dir + "/annotated.rawlog";
	pipeline::AnnotateOptions o;
	o.threads = 2;
	const auto s = pipeline::annotateRawlog(d.dir + "/dataset.rawlog", out, o);
	EXPECT_EQ(s.images, 80);
	EXPECT_TRUE(s.actions_observations);
	const auto objs = codemark::test::readRawlog(out);
	ASSERT_EQ(objs.size(), 160u);
	const auto cam_on_robot = sim::DatasetOptions().cameraPoseOnRobot();
	int checked = 0, within = 0, oblique = 0;
	double oblique_z = 0;
	// Normalised errors (error / reported sigma) of l2, phi1, phi2, near
	// (< 2 m) and far: their mean is the bias, their RMS should be 1.
	double sum[2][3] = {}, sum2[2][3] = {};
	int count[2] = {};
	for (int k = 0; k < 80; ++k)
	{
		auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(objs[2 * k + 1]);
		ASSERT_TRUE(sf);
		ASSERT_EQ(sf->size(), 2u);
		// The landmark observation comes right after its image.
		auto img =
			std::dynamic_pointer_cast<mrpt::obs::CObservationImage>(sf->getObservationByIndex(0));
		auto lm =
			std::dynamic_pointer_cast<CObservationCodedLandmarks>(sf->getObservationByIndex(1));
		ASSERT_TRUE(img && lm);
		EXPECT_EQ(lm->sensorLabel, "CAM_LANDMARKS");
		EXPECT_EQ(lm->timestamp, img->timestamp);
		EXPECT_EQ(lm->cameraPose, img->cameraPose);
		const mrpt::poses::CPose3D world_T_camera =
			mrpt::poses::CPose3D(d.sum.ground_truth[k].pose) + cam_on_robot;
		for (const auto& sg : lm->sightings)
		{
			const auto* ml = d.sum.map.find(sg.id);
			ASSERT_NE(ml, nullptr) << "wrong ID " << sg.id << " in frame " << k;
			const auto truth = sightingTruth(world_T_camera - ml->world_T_landmark());
			// The detection is the landmark the truth says: close to its range.
			EXPECT_NEAR(sg.L[0], truth.L[0], 0.05 * truth.L[0]) << "frame " << k << " id " << sg.id;
			const double sigma = std::sqrt(sg.C_L(0, 0));
			// Beyond the view angle the filters use (StepperOptions'
			// max_view_angle_deg, 60 deg) a 1-2 px thin vertical frame makes
			// the range 0.5-0.8% short (this loop's 71-deg sightings at
			// 3.4-4.1 m): counted apart, not checked.
			if (pose::viewAngle(truth.L) >
				filters::StepperOptions().max_view_angle_deg * M_PI / 180)
			{
				++oblique;
				oblique_z += (sg.L[0] - truth.L[0]) / sigma;
				continue;
			}
			within += std::abs(sg.L[0] - truth.L[0]) <= 3 * sigma;
			++checked;
			const int far = truth.L[0] >= 2.0;
			++count[far];
			for (int i = 0; i < 3; ++i)
			{
				const double e = i == 0 ? sg.L[0] - truth.L[0] : wrapToPi(sg.L[i] - truth.L[i]);
				const double z = e / std::sqrt(sg.C_L(i, i));
				sum[far][i] += z;
				sum2[far][i] += z * z;
			}
		}
	}
	for (int far = 0; far < 2; ++far)
		if (count[far])
			std::printf(
				"%s: %d sightings; error/sigma mean (bias) and RMS: l2 %+.2f %.2f, phi1 %+.2f "
				"%.2f, "
				"phi2 %+.2f %.2f\n",
				far ? ">= 2 m" : "< 2 m", count[far], sum[far][0] / count[far],
				std::sqrt(sum2[far][0] / count[far]), sum[far][1] / count[far],
				std::sqrt(sum2[far][1] / count[far]), sum[far][2] / count[far],
				std::sqrt(sum2[far][2] / count[far]));
	if (oblique)
		std::printf(
			"beyond the filters' view angle: %d sightings, mean range error / sigma %+.2f\n",
			oblique, oblique_z / oblique);
	EXPECT_GE(checked, 40);
	EXPECT_GE(within, 0.95 * checked) << within << " of " << checked << " ranges within 3 sigma";
}

TEST(Annotate, ObservationsOnlyFormatAndBearingRange)
{
	const auto& d = dataset(true);
	const std::string out = d.dir + "/annotated.rawlog";
	pipeline::AnnotateOptions o;
	o.bearing_range = true;
	o.drop_images = true;
	o.threads = 1;
	const auto s = pipeline::annotateRawlog(d.dir + "/dataset.rawlog", out, o);
	EXPECT_FALSE(s.actions_observations);
	int lms = 0, brs = 0, imgs = 0;
	for (const auto& obj : codemark::test::readRawlog(out))
	{
		lms += !!std::dynamic_pointer_cast<CObservationCodedLandmarks>(obj);
		brs += !!std::dynamic_pointer_cast<mrpt::obs::CObservationBearingRange>(obj);
		imgs += !!std::dynamic_pointer_cast<mrpt::obs::CObservationImage>(obj);
	}
	EXPECT_EQ(lms, 80);
	EXPECT_EQ(brs, 80);
	EXPECT_EQ(imgs, 0);
}

TEST(Annotate, OutputIsIndependentOfThreads)
{
	const auto& d = dataset(false);
	pipeline::AnnotateOptions o;
	o.threads = 1;
	pipeline::annotateRawlog(d.dir + "/dataset.rawlog", d.dir + "/t1.rawlog", o);
	o.threads = 3;
	pipeline::annotateRawlog(d.dir + "/dataset.rawlog", d.dir + "/t3.rawlog", o);
	EXPECT_EQ(slurp(d.dir + "/t1.rawlog"), slurp(d.dir + "/t3.rawlog"));
}

TEST(Annotate, BadInputsStopWithTheEntryIndex)
{
	const auto& d = dataset(false);
	const std::string dir = freshDir("bad");
	pipeline::AnnotateOptions o;
	EXPECT_THROW(
		pipeline::annotateRawlog(dir + "/missing.rawlog", dir + "/o.rawlog", o),
		std::runtime_error);
	std::ofstream(dir + "/empty.rawlog").close();
	EXPECT_THROW(
		pipeline::annotateRawlog(dir + "/empty.rawlog", dir + "/o.rawlog", o), std::runtime_error);

	// A truncated copy (uncompressed, cut in the middle of an entry).
	{
		const auto objs = codemark::test::readRawlog(d.dir + "/dataset.rawlog");
		mrpt::io::CFileOutputStream f(dir + "/full.rawlog");
		auto ar = mrpt::serialization::archiveFrom(f);
		for (std::size_t i = 0; i < 10; ++i) ar << *objs[i];
	}
	const std::string full = slurp(dir + "/full.rawlog");
	std::ofstream(dir + "/cut.rawlog", std::ios::binary) << full.substr(0, full.size() - 20);
	try
	{
		pipeline::annotateRawlog(dir + "/cut.rawlog", dir + "/o.rawlog", o);
		FAIL() << "no error for a truncated rawlog";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("entry #9"), std::string::npos) << e.what();
	}
	// Missing external images: the entry is named.
	std::ofstream(dir + "/noimg.rawlog", std::ios::binary) << full;
	try
	{
		pipeline::annotateRawlog(dir + "/noimg.rawlog", dir + "/o2.rawlog", o);
		FAIL() << "no error for missing images";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("entry #1"), std::string::npos) << e.what();
	}
}
