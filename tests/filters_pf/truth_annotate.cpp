// pf_truth_annotate: replaces the images of a codemark-simul rawlog
// (actions-observations format) by CObservationCodedLandmarks built from the
// ground truth (sightingTruth + C_L noise, synthetic.h), without running the
// detector. The stock pf-localization test uses it to test our map in MRPT's
// own tool independently of the detector's state.
//   pf_truth_annotate IN.rawlog GT.txt MAP.txt OUT.rawlog [SEED]
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <fstream>
#include <iostream>
#include <sstream>

#include "synthetic.h"

int main(int argc, char** argv)
{
	if (argc < 5)
	{
		std::cerr << "usage: pf_truth_annotate IN.rawlog GT.txt MAP.txt OUT.rawlog [SEED]\n";
		return 2;
	}
	try
	{
		std::vector<mrpt::poses::CPose2D> gt;
		std::ifstream g(argv[2]);
		if (!g) throw std::runtime_error(std::string(argv[2]) + ": cannot open");
		for (std::string line; std::getline(g, line);)
		{
			if (line.empty() || line[0] == '#') continue;
			std::istringstream ss(line);
			double t, x, y, yaw;
			if (ss >> t >> x >> y >> yaw) gt.emplace_back(x, y, yaw);
		}
		const auto map = codemark::LandmarkMap::load(argv[3]);
		std::mt19937 rng(argc > 5 ? std::stoul(argv[5]) : 1u);
		mrpt::io::CFileGZInputStream fin(argv[1]);
		mrpt::io::CFileGZOutputStream fout(argv[4]);
		auto in = mrpt::serialization::archiveFrom(fin);
		auto out = mrpt::serialization::archiveFrom(fout);
		size_t frame = 0, sightings = 0;
		for (;;)
		{
			mrpt::serialization::CSerializable::Ptr obj;
			try
			{
				obj = in.ReadObject();
			}
			catch (const mrpt::serialization::CExceptionEOF&)
			{
				break;
			}
			if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj))
			{
				auto img = sf->getObservationByClass<mrpt::obs::CObservationImage>();
				if (!img) continue;
				if (frame >= gt.size())
					throw std::runtime_error("more images than ground-truth rows");
				auto o = codemark::pftest::observe(gt[frame], map, &rng, 0, img->cameraPose);
				o->timestamp = img->timestamp;
				o->sensorLabel = img->sensorLabel + "_LANDMARKS";
				sightings += o->sightings.size();
				mrpt::obs::CSensoryFrame osf;
				osf.insert(o);
				out << osf;
				++frame;
			}
			else
				out << *obj;
		}
		std::cout << "pf_truth_annotate: " << frame << " frames, " << sightings << " sightings\n";
		return frame > 0 ? 0 : 1;
	}
	catch (const std::exception& e)
	{
		std::cerr << "pf_truth_annotate: " << e.what() << "\n";
		return 1;
	}
}
