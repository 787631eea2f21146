#include <codemark/pipeline/annotate.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace codemark::pipeline
{
namespace fs = std::filesystem;
using mrpt::obs::CObservationImage;
using mrpt::serialization::CSerializable;

namespace
{
// One image of the input to process, and what became of it.
struct Job
{
	std::size_t entry;	//!< index of the entry in the chunk
	const CObservationImage* image;
	CObservationCodedLandmarks::Ptr result;
	double detect_us = 0;
	std::string error;
};

// Images whose files are relative to the input's <name>_Images folder stay
// valid for the output when <out name>_Images points there: link it.
void linkImagesFolder(const std::string& in_path, const std::string& out_path)
{
	const fs::path in_dir = imagesDirectoryOf(in_path), out_dir = imagesDirectoryOf(out_path);
	std::error_code ec;
	if (!fs::exists(in_dir, ec) || fs::exists(out_dir, ec)) return;
	if (fs::equivalent(
			fs::absolute(in_dir).parent_path(), fs::absolute(out_dir).parent_path(), ec) &&
		in_dir.filename() == out_dir.filename())
		return;
	fs::create_directory_symlink(fs::absolute(in_dir), out_dir, ec);
	if (ec)
		throw std::runtime_error(
			"cannot link " + out_dir.string() + " to " + in_dir.string() + ": " + ec.message());
}

void runJobs(std::vector<Job>& jobs, const PipelineOptions& pipe, int threads)
{
	std::atomic<std::size_t> next{0};
	auto work = [&]
	{
		for (std::size_t i; (i = next++) < jobs.size();)
		{
			Job& j = jobs[i];
			try
			{
				ImageResult r;
				j.result = observeImage(*j.image, pipe, &r);
				j.detect_us = r.timings.total_us;
			}
			catch (const std::exception& e)
			{
				j.error = e.what();
			}
		}
	};
	std::vector<std::thread> pool;
	for (int t = 1; t < threads; ++t) pool.emplace_back(work);
	work();
	for (auto& t : pool) t.join();
}
}  // namespace

AnnotateSummary annotateRawlog(
	const std::string& in_path, const std::string& out_path, const AnnotateOptions& o,
	const std::function<void(long, long)>& progress)
{
	const auto t_start = std::chrono::steady_clock::now();
	AnnotateSummary sum;
	if (!fs::exists(in_path)) throw std::runtime_error(in_path + ": no such file");
	mrpt::io::CFileGZInputStream in;
	if (!in.open(in_path)) throw std::runtime_error(in_path + ": cannot open");
	const long total_bytes = static_cast<long>(in.getTotalBytesCount());
	if (total_bytes == 0) throw std::runtime_error(in_path + ": empty file, not a rawlog");
	mrpt::io::CFileGZOutputStream out;
	if (!out.open(out_path)) throw std::runtime_error(out_path + ": cannot write");
	linkImagesFolder(in_path, out_path);
	// This rawlog's external images, not MRPT's process-wide folder.
	PipelineOptions pipe = o.pipeline;
	pipe.images_dir = imagesDirectoryOf(in_path);

	auto ar_in = mrpt::serialization::archiveFrom(in);
	auto ar_out = mrpt::serialization::archiveFrom(out);
	const int threads =
		o.threads > 0 ? o.threads : std::max(1u, std::thread::hardware_concurrency());
	const std::size_t chunk = 8 * static_cast<std::size_t>(threads);
	double detect_us_total = 0;
	bool eof = false;

	while (!eof)
	{
		// Read a chunk of entries.
		std::vector<CSerializable::Ptr> entries;
		while (entries.size() < chunk)
		{
			CSerializable::Ptr obj;
			try
			{
				obj = ar_in.ReadObject();
			}
			catch (const mrpt::serialization::CExceptionEOF&)
			{
				eof = true;
				break;
			}
			catch (const std::exception& e)
			{
				throw std::runtime_error(
					in_path + ": entry #" + std::to_string(sum.entries) +
					" cannot be read (truncated or corrupt file, or a class whose plugin is not "
					"loaded): " +
					mrpt::exception_to_str(e));
			}
			const bool known = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj) ||
							   std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(obj) ||
							   std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj);
			if (!known)
				throw std::runtime_error(
					in_path + ": entry #" + std::to_string(sum.entries) + " holds a '" +
					(obj ? obj->GetRuntimeClass()->className : "null") +
					"', which is not a rawlog entry (CSensoryFrame, CActionCollection or "
					"CObservation)");
			if (!std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj))
				sum.actions_observations = true;
			entries.push_back(obj);
			++sum.entries;
		}
		const long first_entry = sum.entries - static_cast<long>(entries.size());

		// Find the images and process them in parallel.
		std::vector<Job> jobs;
		for (std::size_t e = 0; e < entries.size(); ++e)
		{
			if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(entries[e]))
			{
				for (const auto& obs : *sf)
					if (auto img = std::dynamic_pointer_cast<CObservationImage>(obs))
						jobs.push_back({e, img.get(), nullptr, 0, {}});
			}
			else if (auto img = std::dynamic_pointer_cast<CObservationImage>(entries[e]))
				jobs.push_back({e, img.get(), nullptr, 0, {}});
		}
		runJobs(jobs, pipe, threads);
		for (const auto& j : jobs)
		{
			if (!j.error.empty())
				throw std::runtime_error(
					in_path + ": entry #" +
					std::to_string(first_entry + static_cast<long>(j.entry)) + " (" +
					j.image->sensorLabel + "): " + j.error);
			++sum.images;
			detect_us_total += j.detect_us;
			sum.detections += static_cast<long>(j.result->sightings.size());
			for (const auto& s : j.result->sightings) ++sum.per_id[s.id];
		}

		// Write in input order, each landmark observation right after its image.
		std::size_t next_job = 0;
		auto resultFor = [&](const CObservationImage* img)
		{
			while (next_job < jobs.size() && jobs[next_job].image != img) ++next_job;
			return jobs.at(next_job).result;
		};
		for (const auto& entry : entries)
		{
			if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(entry))
			{
				mrpt::obs::CSensoryFrame out_sf;
				for (const auto& obs : *sf)
				{
					auto img = std::dynamic_pointer_cast<CObservationImage>(obs);
					if (!img || !o.drop_images) out_sf.insert(obs);
					if (!img) continue;
					auto lm = resultFor(img.get());
					out_sf.insert(lm);
					if (o.bearing_range) out_sf.insert(lm->toBearingRange());
				}
				ar_out << out_sf;
			}
			else if (auto img = std::dynamic_pointer_cast<CObservationImage>(entry))
			{
				if (!o.drop_images) ar_out << *img;
				auto lm = resultFor(img.get());
				ar_out << *lm;
				if (o.bearing_range) ar_out << *lm->toBearingRange();
			}
			else
				ar_out << *entry;
		}
		if (progress) progress(static_cast<long>(in.getPosition()), total_bytes);
	}
	sum.detect_ms_per_image = sum.images ? detect_us_total / sum.images / 1000.0 : 0.0;
	sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
	return sum;
}

}  // namespace codemark::pipeline
