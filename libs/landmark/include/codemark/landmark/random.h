#pragma once
/** \file random.h
 * Repeatable draws from MRPT's global random generator.
 */
#include <mrpt/random/RandomGenerators.h>

#include <cstdint>

namespace codemark
{
/** Re-seeds MRPT's global generator (mrpt::random::getRandomGenerator(),
 * which MRPT's own sampling uses, e.g. CActionRobotMovement2D::
 * drawSingleSample) so that what follows depends on \a seed alone.
 * CRandomGenerator::randomize(seed) re-seeds only the Mersenne twister: its
 * std::normal_distribution keeps the second value of the last pair it drew,
 * so the first Gaussian after randomize() depends on what the process drew
 * before. Assigning a freshly constructed generator resets both. */
inline void reseedMrptRandom(uint32_t seed)
{
	mrpt::random::getRandomGenerator() = mrpt::random::CRandomGenerator(seed);
}
}  // namespace codemark
