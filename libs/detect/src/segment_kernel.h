#pragma once
/** \file segment_kernel.h
 * Internal: the colour predicate of the segmentation in integer arithmetic,
 * and the step-2 mask kernel that segment.cpp compiles for the baseline
 * instruction set and segment_avx2.cpp for AVX2 (run only where the CPU has
 * it). The kernel works on raw rows so that the AVX2 translation unit needs
 * no OpenCV class whose inline code the linker could share with baseline
 * code.
 */
#include <cstddef>
#include <cstdint>

namespace codemark::detect
{
/** The HSI predicate in integer arithmetic, with every product within 16
 * bits so that the SIMD loop evaluates it on eight (or sixteen) pixels per
 * instruction: I >= t_I, G the largest channel, saturation 1 - min / I >=
 * S_min (in steps of 1/64), hue = 120 + 60 (B - R) / (G - min) inside the
 * band (in half degrees). Built by segment.cpp from SegmentationParams. */
struct FillPredicate
{
	int min_sum;  // 3 * t_I
	int sat64;	// saturation: 3 * 64 * min <= sat64 * sum
	int hue_lo, hue_hi;	 // hue_lo * (G - min) <= 120 * (B - R) <= hue_hi * (G - min)
};

/** An image and its step-2 mask as raw rows: BGR pixels (3 bytes each,
 * \a bgr_cols of them a row, rows \a bgr_step bytes apart) and mask cells
 * (\a mask_rows x \a mask_cols, rows \a mask_step bytes apart); cell (i, j)
 * is pixel (2 j, 2 i). */
struct Step2Rows
{
	const uint8_t* bgr;
	size_t bgr_step;
	int bgr_cols;
	uint8_t* mask;
	size_t mask_step;
	int mask_rows, mask_cols;
};

/** The predicate on every cell of every full SIMD block of each row, 255 or
 * 0; returns the first column left to scalar code (0: none done). */
int segmentStep2Baseline(const Step2Rows& rows, const FillPredicate& pred);
#ifdef CODEMARK_DETECT_AVX2
int segmentStep2Avx2(const Step2Rows& rows, const FillPredicate& pred);
#endif
}  // namespace codemark::detect
