// codemark-bench: runs the whole pipeline (rawlog -> detection -> filter)
// over the datasets of a benchmark ini and a set of methods, one job per
// dataset x method on a pool of threads, and writes results.csv, report.md
// and plots. The logic is in bench.h (config.cpp, job.cpp, report.cpp).
#include <codemark/landmark/text.h>
#include <tclap/CmdLine.h>

#include <condition_variable>
#include <chrono>
#include <fstream>
#include <iostream>
#include <mutex>
#include <optional>
#include <thread>

#include "bench.h"
#include "errors.h"
#include "progress.h"

using namespace codemark::bench;

namespace
{
// A 32-bit FNV-1a hash: the job's seed depends only on its names, so that
// results do not depend on the thread count or the job order.
unsigned seedOf(const std::string& s)
{
	uint32_t h = 2166136261u;
	for (unsigned char c : s) h = (h ^ c) * 16777619u;
	return h;
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd(
			"Benchmarks codemark's localization over a list of datasets (a rawlog with camera "
			"images "
			"or with codemark landmark observations, a landmark map, a ground-truth path, "
			"optionally "
			"a camera file), listed in an ini (share/codemark/bench.ini documents the keys), and a "
			"set of methods (ekf, ekf-pose, ekf-slam, pf; their inis come from [bench] "
			"config_dir). "
			"One job per dataset x method runs on a pool of threads. Writes into --out DIR: "
			"results.csv (one row per job), report.md (tables, definitions, plots), "
			"<dataset>-error.png (position error against time with the filter's 3-sigma bound), "
			"<dataset>-nis.png (each sighting's NIS per degree of freedom against time), "
			"<dataset>-trajectories.png (estimates, ground truth, landmarks), and each job's "
			"codemark-localize outputs in <dataset>/<method>/. Exits non-zero if any job failed.",
			' ', "0.1");
		TCLAP::ValueArg<std::string> config(
			"c", "config", "the benchmark ini", true, "", "BENCH.ini", cmd);
		TCLAP::ValueArg<std::string> out(
			"o", "out", "output directory, created (default: bench-out)", false, "bench-out", "DIR",
			cmd);
		TCLAP::ValueArg<unsigned> jobs(
			"j", "jobs", "parallel jobs (default: the hardware concurrency)", false, 0, "N", cmd);
		TCLAP::ValueArg<std::string> methods(
			"m", "methods",
			"comma-separated methods, overriding [bench] methods (ekf,ekf-pose,ekf-slam,pf)", false,
			"", "LIST", cmd);
		TCLAP::SwitchArg quiet("q", "quiet", "no progress bar", cmd);
		cmd.setExceptionHandling(false);  // one-line errors, below
		cmd.parse(argc, argv);

		BenchConfig cfg = loadBenchConfig(config.getValue());
		if (methods.isSet()) cfg.methods = parseMethods(methods.getValue(), "--methods");
		for (const auto& m : cfg.methods)
			if (!std::ifstream(cfg.config_dir + "/" + m + ".ini").good())
				throw std::runtime_error(
					cfg.config_dir + "/" + m + ".ini: cannot open (method " + m + ")");
		const std::string dir = out.getValue();
		codemark::createFolder(dir, "the output folder");

		struct Job
		{
			const Dataset* ds;
			std::string method;
		};
		std::vector<Job> todo;
		for (const auto& d : cfg.datasets)
			for (const auto& m : cfg.methods) todo.push_back({&d, m});
		const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
		const int nthreads = static_cast<int>(
			std::min<std::size_t>(jobs.getValue() ? jobs.getValue() : hw, todo.size()));

		std::vector<JobResult> results(todo.size());
		std::vector<double> fraction(todo.size(), 0.0);
		std::mutex mutex;  // guards fraction, shown and the progress bar
		long shown = -1;  // the last value drawn: redraw only on change
		codemark::app::ProgressBar bar("codemark-bench", !quiet.getValue());
		const long total = 1000 * static_cast<long>(todo.size());
		// The particle filter draws from MRPT's process-wide random generator
		// (mrpt::random::getRandomGenerator(), which CParticleFilter and the
		// motion-model samplers use). Running anything beside it made its
		// results depend on the timing (measured: pf ATE 3.04-3.37 cm on one
		// dataset over repeated runs with 2 threads), so a pf job seeds the
		// generator from its names and runs alone; the other jobs run in
		// parallel. A worker takes the first job not started that may run
		// now, and waits when there is none.
		auto drawsRandom = [](const std::string& method) { return method == "pf"; };
		std::vector<bool> started(todo.size(), false);
		bool random_busy = false;  // a pf job runs
		int running = 0;  // jobs running
		std::mutex queue_mutex;
		std::condition_variable queue_cv;
		auto take = [&]() -> std::optional<std::size_t>
		{
			std::unique_lock<std::mutex> lock(queue_mutex);
			while (true)
			{
				bool left = false;
				for (std::size_t k = 0; k < todo.size(); ++k)
				{
					if (started[k]) continue;
					left = true;
					const bool pf = drawsRandom(todo[k].method);
					if (random_busy || (pf && running > 0)) continue;
					started[k] = true;
					random_busy = pf;
					++running;
					return k;
				}
				if (!left) return std::nullopt;
				queue_cv.wait(lock);
			}
		};
		auto release = [&](std::size_t k)
		{
			std::lock_guard<std::mutex> lock(queue_mutex);
			if (drawsRandom(todo[k].method)) random_busy = false;
			--running;
			queue_cv.notify_all();
		};
		const auto t0 = std::chrono::steady_clock::now();
		auto worker = [&]
		{
			while (const auto next = take())
			{
				const std::size_t k = *next;
				const auto& j = todo[k];
				results[k] = runJob(
					cfg, *j.ds, j.method, dir + "/" + j.ds->name + "/" + j.method,
					drawsRandom(j.method)
						? std::optional<unsigned>(seedOf(j.ds->name + "/" + j.method))
						: std::nullopt,
					[&, k](double f)
					{
						std::lock_guard<std::mutex> lock(mutex);
						fraction[k] = f;
						double sum = 0;
						for (double v : fraction) sum += v;
						const long done = std::min(total, static_cast<long>(1000 * sum));
						if (done == shown) return;
						shown = done;
						bar.update(done, total);
					});
				release(k);
			}
		};
		std::vector<std::thread> pool;
		pool.reserve(static_cast<std::size_t>(nthreads));
		for (int i = 0; i < nthreads; ++i) pool.emplace_back(worker);
		for (auto& t : pool) t.join();
		bar.finish();
		const double wall =
			std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

		std::vector<std::pair<std::string, std::vector<std::string>>> plots;
		for (const auto& d : cfg.datasets)
		{
			std::vector<const JobResult*> mine;
			for (const auto& r : results)
				if (r.dataset == d.name) mine.push_back(&r);
			plots.emplace_back(d.name, writeDatasetPlots(d.name, mine, d.map, dir));
		}
		std::ofstream csv(dir + "/results.csv");
		csv << csvHeader() << '\n';
		for (const auto& r : results) csv << csvRow(r) << '\n';
		std::ofstream md(dir + "/report.md");
		md << markdownReport(cfg, results, plots, nthreads, wall);
		if (!csv || !md) throw std::runtime_error(dir + ": cannot write results.csv or report.md");

		int failed = 0;
		for (const auto& r : results)
			if (!r.ok)
			{
				++failed;
				std::cerr << "codemark-bench: " << r.dataset << " / " << r.method << ": " << r.error
						  << "\n";
			}
		std::cout << "codemark-bench: " << results.size() << " jobs (" << cfg.datasets.size()
				  << " datasets x " << cfg.methods.size() << " methods) on " << nthreads
				  << " threads in " << wall << " s, " << failed << " failed; wrote " << dir
				  << "/report.md and results.csv\n";
		return failed ? 1 : 0;
	}
	catch (const TCLAP::ExitException& e)
	{
		return e.getExitStatus();  // after --help or --version
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << codemark::app::argumentError("codemark-bench", e) << "\n";
	}
	catch (const std::exception& e)
	{
		std::cerr << "codemark-bench: " << e.what() << "\n";
	}
	return 1;
}
