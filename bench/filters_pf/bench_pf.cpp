// codemark-bench-filters-pf: prints a markdown report (docs/benchmarks/filters-pf.md).
//  1. CParticleFilter::executeOn time per update against the number of
//     particles (fixed sample size, standard proposal, no resampling: BETA=0,
//     so both maps do the same work besides the likelihood), with our
//     CCodedLandmarksMap and with a map whose likelihood is a constant (MRPT's
//     own overhead: motion sampling, CPose3D per particle, the loop).
//  2. The particle filter localizer (shipped pf.ini) from a uniform start:
//     frames with sightings until the position error is < 10 cm (and the
//     estimate reports itself initialized), over several seeds.
#include <codemark/landmark/random.h>
#include <codemark/filters/particle_filter.h>
#include <codemark/mrpt/CCodedLandmarksMap.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/vector_loadsave.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/random/RandomGenerators.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "synthetic.h"

namespace codemark::bench
{
/** A map whose log-likelihood is 0 for every observation: the baseline. */
class ConstantLikelihoodMap : public mrpt::maps::CMetricMap
{
	DEFINE_SERIALIZABLE(ConstantLikelihoodMap, codemark::bench)
   public:
	bool isEmpty() const override { return false; }
	void saveMetricMapRepresentationToFile(const std::string&) const override {}
	void getVisualizationInto(mrpt::opengl::CSetOfObjects&) const override {}
	std::string asString() const override { return "ConstantLikelihoodMap"; }

   protected:
	void internal_clear() override {}
	bool internal_insertObservation(
		const mrpt::obs::CObservation&, const std::optional<const mrpt::poses::CPose3D>&) override
	{
		return false;
	}
	double internal_computeObservationLikelihood(
		const mrpt::obs::CObservation&, const mrpt::poses::CPose3D&) const override
	{
		return 0;
	}
};
}  // namespace codemark::bench

IMPLEMENTS_SERIALIZABLE(ConstantLikelihoodMap, mrpt::maps::CMetricMap, codemark::bench)

namespace codemark::bench
{
uint8_t ConstantLikelihoodMap::serializeGetVersion() const { return 0; }
void ConstantLikelihoodMap::serializeTo(mrpt::serialization::CArchive&) const {}
void ConstantLikelihoodMap::serializeFrom(mrpt::serialization::CArchive&, uint8_t) {}
}  // namespace codemark::bench

namespace
{
using Clock = std::chrono::steady_clock;

/** Mean executeOn time [ms] over about \a budget_s seconds. */
double timeUpdate(
	mrpt::maps::CMetricMap::Ptr map, size_t n, const mrpt::obs::CSensoryFrame& sf,
	const mrpt::obs::CActionCollection& acts, double budget_s)
{
	mrpt::slam::CMonteCarloLocalization2D pdf;
	pdf.options.metricMap = map;
	pdf.resetUniform(2.0, 2.4, 1.5, 1.9, 0.1, 0.5, static_cast<int>(n));
	mrpt::bayes::CParticleFilter pf;
	pf.m_options.PF_algorithm = mrpt::bayes::CParticleFilter::pfStandardProposal;
	pf.m_options.adaptiveSampleSize = false;
	pf.m_options.BETA = 0;	// never resample: same work for both maps
	mrpt::bayes::CParticleFilter::TParticleFilterStats st;
	pf.executeOn(pdf, &acts, &sf, &st);	 // warm-up
	int reps = 0;
	const auto t0 = Clock::now();
	double el = 0;
	do
	{
		pf.executeOn(pdf, &acts, &sf, &st);
		pdf.normalizeWeights();
		++reps;
		el = std::chrono::duration<double>(Clock::now() - t0).count();
	} while (el < budget_s || reps < 3);
	return 1e3 * el / reps;
}
}  // namespace

int main(int argc, char** argv)
{
	const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
	namespace pft = codemark::pftest;
	codemark::reseedMrptRandom(1);
	const auto room = pft::room();
	const mrpt::poses::CPose2D truth(2.2, 1.7, 0.3);
	std::mt19937 rng(1);
	mrpt::obs::CSensoryFrame sf;
	const auto obs = pft::observe(truth, room, &rng);
	sf.insert(obs);
	mrpt::obs::CActionCollection acts;
	acts.insert(pft::odometry(mrpt::poses::CPose2D(), mrpt::poses::CPose2D(0.08, 0, 0.01), rng));

	std::printf("## Time per particle-filter update\n\n");
	std::printf(
		"One `CParticleFilter::executeOn` (standard proposal, fixed sample size, no resampling: "
		"`BETA = 0`, so both maps do the same work besides the likelihood) on a frame with %zu "
		"sightings; mean over repeated updates. The constant map returns log-likelihood 0: its "
		"time is MRPT's own overhead (motion sampling, a `CPose3D` per particle, the loop). Same "
		"process, same particles, same frame; ratio = ours / constant map.\n\n",
		obs->sightings.size());
	std::printf("| particles | ours [ms] | constant map [ms] | ours per 1000 [ms] | ratio |\n");
	std::printf("|---:|---:|---:|---:|---:|\n");
	auto ours = std::make_shared<codemark::CCodedLandmarksMap>(room);
	auto flat = std::make_shared<codemark::bench::ConstantLikelihoodMap>();
	for (size_t n : {size_t(100), size_t(1000), size_t(10000), size_t(100000)})
	{
		const double budget = quick ? 0.1 : (n >= 100000 ? 3.0 : 1.0);
		const double a = timeUpdate(ours, n, sf, acts, budget);
		const double b = timeUpdate(flat, n, sf, acts, budget);
		std::printf(
			"| %zu | %.3f | %.3f | %.3f | %.2f |\n", n, a, b, 1000.0 * a / double(n), a / b);
	}

	std::printf("\n## From a uniform start (shipped pf.ini)\n\n");
	std::printf(
		"Room 6 x 4 m, 12 landmarks, circle of radius 1 m at 0.4 m/s, 5 Hz, noisy odometry, "
		"sightings drawn from their C_L; the filter reads `share/codemark/config/pf.ini` (uniform "
		"global start, KLD-adaptive sample size). Converged = position error < 10 cm and "
		"`estimate().initialized`, counted in frames that hold at least one sighting.\n\n");
	std::printf(
		"| seed | frames with sightings to converge | final error [cm] | mean step [ms] | "
		"injections |\n");
	std::printf("|---:|---:|---:|---:|---:|\n");
	mrpt::config::CConfigFileMemory base(
		mrpt::io::file_get_contents(std::string(CODEMARK_SOURCE_SHARE_DIR) + "/config/pf.ini"));
	const int seeds = quick ? 3 : 10;
	for (int seed = 1; seed <= seeds; ++seed)
	{
		mrpt::config::CConfigFileMemory cfg(base.getContent());
		cfg.write("ParticleFilter", "random_seed", seed);
		codemark::filters::ParticleFilterLocalizer f(cfg, room);
		std::mt19937 r(static_cast<unsigned>(seed));
		int frames = 0, converged_at = -1;
		double err = 0, total_ms = 0;
		const int K = 60;
		for (int k = 0; k < K; ++k)
		{
			const auto t = pft::circlePose(k);
			const auto odo = pft::odometry(pft::circlePose(k - 1), t, r);
			mrpt::obs::CSensoryFrame s;
			const auto o = pft::observe(t, room, &r, 0.2 * k);
			if (!o->sightings.empty()) ++frames;
			s.insert(o);
			const auto t0 = Clock::now();
			f.step(k ? &odo : nullptr, s);
			total_ms += 1e3 * std::chrono::duration<double>(Clock::now() - t0).count();
			const auto e = f.estimate();
			err = std::hypot(e.mean.x() - t.x(), e.mean.y() - t.y());
			if (converged_at < 0 && err < 0.10 && e.initialized) converged_at = frames;
		}
		std::printf(
			"| %d | %d | %.1f | %.2f | %d |\n", seed, converged_at, 100 * err, total_ms / K,
			f.injections());
	}
	return 0;
}
