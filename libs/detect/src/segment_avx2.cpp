// The step-2 colour mask kernel for AVX2 (32 cells a block), compiled with
// -mavx2 and called only where cv::checkHardwareSupport(CV_CPU_AVX2) holds.
// OpenCV's own dispatch is not open to user code: simd_intrinsics.hpp is its
// documented way, and CV_CPU_DISPATCH_MODE keeps these intrinsics in their
// own namespace (cv::hal_AVX2), apart from the baseline unit's. Nothing else
// of OpenCV is included here, so no inline code compiled for AVX2 can stand
// in for the baseline's at link time.
#define CV_CPU_DISPATCH_MODE AVX2
#include <opencv2/core/simd_intrinsics.hpp>

#include "segment_kernel.h"

#if !CV_AVX2
#error "segment_avx2.cpp must be compiled with -mavx2"
#endif

#define CODEMARK_STEP2_KERNEL segmentStep2Avx2
#include "segment_step2.inl.h"
