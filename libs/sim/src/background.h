#pragma once
/** \file background.h
 * Internal: the background behind the landmarks and the seeding of the
 * renderer's independent random streams.
 */
#include <codemark/sim/render.h>

#include <cstdint>

namespace codemark::sim::detail
{
/** A seed for random stream \a stream of a render with \a seed
 * (splitmix64), so that e.g. the noise does not change when the number of
 * distractors does. Never 0 (cv::RNG treats 0 specially). */
uint64_t streamSeed(uint64_t seed, uint64_t stream);

/** The background of \a options (Flat, Textured or Cluttered with its
 * distractors) as a CV_32FC3 BGR image [0..255] at gain 1. */
cv::Mat makeBackground(const RenderOptions& options, int width, int height, uint64_t seed);

}  // namespace codemark::sim::detail
