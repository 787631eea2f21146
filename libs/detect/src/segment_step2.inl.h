// The step-2 colour mask kernel, included by segment.cpp (baseline) and by
// segment_avx2.cpp (AVX2) with CODEMARK_STEP2_KERNEL naming the function.
// OpenCV's universal intrinsics at their widest for the unit's instruction
// set: 16 cells per block with SSE2, 32 with AVX2.
#ifndef CODEMARK_STEP2_KERNEL
#error "define CODEMARK_STEP2_KERNEL before including segment_step2.inl.h"
#endif

namespace codemark::detect
{
// Defined once per including TU, each under its own name, and called from
// the other: not inline.
// NOLINTNEXTLINE(misc-definitions-in-headers)
int CODEMARK_STEP2_KERNEL(const Step2Rows& rows, const FillPredicate& pred)
{
#if CV_SIMD
	constexpr int kCells = cv::v_uint8::nlanes;
	const int n_block = rows.mask_cols / kCells * kCells;
	if (rows.bgr_cols < 2 * n_block) return 0;
	const cv::v_int16 min_sum = cv::vx_setall_s16(static_cast<short>(pred.min_sum - 1));
	const cv::v_uint16 sat = cv::vx_setall_u16(static_cast<ushort>(pred.sat64));
	const cv::v_uint16 k192 = cv::vx_setall_u16(192), low = cv::vx_setall_u16(0x00ff);
	const cv::v_int16 k120 = cv::vx_setall_s16(120);
	const cv::v_int16 hlo = cv::vx_setall_s16(static_cast<short>(pred.hue_lo));
	const cv::v_int16 hhi = cv::vx_setall_s16(static_cast<short>(pred.hue_hi));
	// The predicate on the cells whose channels are in the low bytes of u16s.
	const auto cells = [&](const cv::v_uint8& b8, const cv::v_uint8& g8, const cv::v_uint8& r8)
	{
		const cv::v_uint16 bu = cv::v_reinterpret_as_u16(b8) & low,
						   gu = cv::v_reinterpret_as_u16(g8) & low,
						   ru = cv::v_reinterpret_as_u16(r8) & low;
		const cv::v_int16 b = cv::v_reinterpret_as_s16(bu), g = cv::v_reinterpret_as_s16(gu),
						  r = cv::v_reinterpret_as_s16(ru);
		const cv::v_int16 sum = b + g + r;
		const cv::v_uint16 mnu = cv::v_min(bu, ru);
		const cv::v_int16 chroma = g - cv::v_reinterpret_as_s16(mnu);
		const cv::v_int16 hue = cv::v_mul_wrap(k120, b - r);
		return (sum > min_sum) & (g > r) & (g > b) &
			   cv::v_reinterpret_as_s16(
				   cv::v_mul_wrap(k192, mnu) <=
				   cv::v_mul_wrap(sat, cv::v_reinterpret_as_u16(sum))) &
			   (hue >= cv::v_mul_wrap(hlo, chroma)) & (hue <= cv::v_mul_wrap(hhi, chroma));
	};
	for (int i = 0; i < rows.mask_rows; ++i)
	{
		const uint8_t* row = rows.bgr + 2 * i * rows.bgr_step;
		uint8_t* out = rows.mask + i * rows.mask_step;
		for (int j = 0; j < n_block; j += kCells)
		{
			// 2 kCells pixels, of which the even ones are the cells j ..
			// j + kCells - 1.
			cv::v_uint8 b0, g0, r0, b1, g1, r1;
			cv::v_load_deinterleave(row + 6 * j, b0, g0, r0);
			cv::v_load_deinterleave(row + 6 * j + 3 * kCells, b1, g1, r1);
			const cv::v_int8 m = cv::v_pack(cells(b0, g0, r0), cells(b1, g1, r1));
			cv::v_store(out + j, cv::v_reinterpret_as_u8(m));
		}
	}
	return n_block;
#else
	(void)rows;
	(void)pred;
	return 0;
#endif
}
}  // namespace codemark::detect
