// make_rawlogs: writes the bad MRPT rawlogs of the bad-input sweep
// (sweep.py). The byte-level damage (truncation, bit flips) is done in
// Python; what needs MRPT's classes is done here:
//   nan-odometry IN OUT      copy of IN with the 2nd odometry reading NaN
//   inf-odometry IN OUT      same with +inf
//   nan-observation IN OUT   copy of IN with the 1st landmark sighting's L NaN
//   scans OUT                observations-only rawlog of CObservation2DRangeScan only
//   foreign OUT              a file of CPose2D objects (not rawlog entries)
//   image OUT IMAGE_NAME     one CObservationImage whose image is stored
//                            externally as IMAGE_NAME (in OUT's _Images dir)
//   map-object MAP.txt OUT   a CCodedLandmarksMap of MAP.txt serialized as in a
//                            rawlog (a seed of fuzz/corpus/fuzz_deserialize)
#include <codemark/mrpt/CCodedLandmarksMap.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

#include <iostream>
#include <limits>
#include <string>
#include <vector>

using namespace mrpt::obs;
using mrpt::serialization::CSerializable;

namespace
{
std::vector<CSerializable::Ptr> readAll(const std::string& path)
{
	mrpt::io::CFileGZInputStream in(path);
	auto ar = mrpt::serialization::archiveFrom(in);
	std::vector<CSerializable::Ptr> out;
	for (;;)
	{
		try
		{
			out.push_back(ar.ReadObject());
		}
		catch (const mrpt::serialization::CExceptionEOF&)
		{
			break;
		}
	}
	return out;
}

void writeAll(const std::string& path, const std::vector<CSerializable::Ptr>& objs)
{
	mrpt::io::CFileGZOutputStream out(path);
	auto ar = mrpt::serialization::archiveFrom(out);
	for (const auto& o : objs) ar << *o;
}

/** Replaces the 2nd odometry reading of either rawlog format by \a bad. */
int badOdometry(const std::string& in, const std::string& out, double bad)
{
	auto objs = readAll(in);
	int seen = 0;
	for (auto& o : objs)
	{
		if (auto acts = std::dynamic_pointer_cast<CActionCollection>(o))
		{
			auto mv = acts->getBestMovementEstimation();
			if (!mv || ++seen != 2) continue;
			CActionRobotMovement2D nan;
			nan.timestamp = mv->timestamp;
			nan.computeFromOdometry(
				mrpt::poses::CPose2D(bad, 0, bad), mv->motionModelConfiguration);
			acts->clear();
			acts->insert(nan);
		}
		else if (auto odo = std::dynamic_pointer_cast<CObservationOdometry>(o))
		{
			if (++seen != 2) continue;
			odo->odometry = mrpt::poses::CPose2D(bad, 0, bad);
		}
	}
	if (seen < 2)
	{
		std::cerr << in << ": fewer than 2 odometry readings\n";
		return 1;
	}
	writeAll(out, objs);
	return 0;
}

int nanObservation(const std::string& in, const std::string& out)
{
	auto objs = readAll(in);
	for (auto& o : objs)
	{
		std::vector<CObservation::Ptr> obs;
		if (auto sf = std::dynamic_pointer_cast<CSensoryFrame>(o))
			for (const auto& ob : *sf) obs.push_back(ob);
		else if (auto ob = std::dynamic_pointer_cast<CObservation>(o))
			obs.push_back(ob);
		for (const auto& ob : obs)
			if (auto cl = std::dynamic_pointer_cast<codemark::CObservationCodedLandmarks>(ob);
				cl && !cl->sightings.empty())
			{
				cl->sightings[0].L.setConstant(std::numeric_limits<double>::quiet_NaN());
				writeAll(out, objs);
				return 0;
			}
	}
	std::cerr << in << ": no landmark sighting to spoil\n";
	return 1;
}

int scans(const std::string& out)
{
	std::vector<CSerializable::Ptr> objs;
	for (int i = 0; i < 3; ++i)
	{
		auto s = CObservation2DRangeScan::Create();
		s->sensorLabel = "LASER";
		s->timestamp = mrpt::Clock::fromDouble(1.0e9 + i);
		s->resizeScan(10);
		for (size_t k = 0; k < 10; ++k)
			s->setScanRange(k, 1.0f + k), s->setScanRangeValidity(k, true);
		objs.push_back(s);
	}
	writeAll(out, objs);
	return 0;
}

int foreign(const std::string& out)
{
	std::vector<CSerializable::Ptr> objs;
	for (int i = 0; i < 3; ++i) objs.push_back(std::make_shared<mrpt::poses::CPose2D>(i, 0, 0));
	writeAll(out, objs);
	return 0;
}

int image(const std::string& out, const std::string& name)
{
	auto im = CObservationImage::Create();
	im->sensorLabel = "CAMERA";
	im->timestamp = mrpt::Clock::fromDouble(1.0e9);
	im->cameraParams.ncols = 640;
	im->cameraParams.nrows = 480;
	im->cameraParams.setIntrinsicParamsFromValues(800, 800, 319.5, 239.5);
	im->image.setExternalStorage(name);
	writeAll(out, {im});
	return 0;
}
int mapObject(const std::string& map, const std::string& out)
{
	auto m = std::make_shared<codemark::CCodedLandmarksMap>(codemark::LandmarkMap::load(map));
	mrpt::io::CFileOutputStream f(out);
	auto ar = mrpt::serialization::archiveFrom(f);
	ar << *m;
	return 0;
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		const std::string mode = argc > 1 ? argv[1] : "";
		const double nan = std::numeric_limits<double>::quiet_NaN();
		const double inf = std::numeric_limits<double>::infinity();
		if (mode == "nan-odometry" && argc == 4) return badOdometry(argv[2], argv[3], nan);
		if (mode == "inf-odometry" && argc == 4) return badOdometry(argv[2], argv[3], inf);
		if (mode == "nan-observation" && argc == 4) return nanObservation(argv[2], argv[3]);
		if (mode == "scans" && argc == 3) return scans(argv[2]);
		if (mode == "foreign" && argc == 3) return foreign(argv[2]);
		if (mode == "image" && argc == 4) return image(argv[2], argv[3]);
		if (mode == "map-object" && argc == 4) return mapObject(argv[2], argv[3]);
		std::cerr << "usage: make_rawlogs nan-odometry|inf-odometry|nan-observation IN OUT | "
					 "scans|foreign OUT | image OUT IMAGE_NAME | map-object MAP.txt OUT\n";
		return 2;
	}
	catch (const std::exception& e)
	{
		std::cerr << "make_rawlogs: " << e.what() << "\n";
		return 1;
	}
}
