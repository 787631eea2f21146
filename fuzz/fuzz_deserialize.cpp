// libFuzzer target: deserialization of codemark's MRPT classes from
// arbitrary bytes (mrpt::serialization::archiveFrom over a memory stream).
// Byte 0 picks the reader:
//   0: into a CObservationCodedLandmarks (ar >> obj: class header, version, data)
//   1: into a CCodedLandmarksMap
//   2: an observations-only rawlog of our observations: objects read one
//      after the other until the end, as rawlog readers do. Not the generic
//      ReadObject(), which would construct any MRPT class named by the bytes
//      and test MRPT's readers rather than ours (it finds, e.g., that
//      mrpt::math::CMatrix allocates whatever size the stream says).
// Anything unreadable must throw; nothing may crash, hang or allocate without bound.
#include <codemark/mrpt/CCodedLandmarksMap.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <exception>

// MRPT's archive reads a 32-bit length (of a string, a vector) and
// allocates that much before reading the bytes, so an arbitrary stream
// asks for up to 4 GB at once: MRPT's behaviour, not ours, and it would
// stall or stop every run. Allocations beyond kMaxAlloc throw
// std::bad_alloc here (as they can in any real program), which the
// readers must handle like any other corrupt data. Memory still comes from
// malloc/free, which ASan checks.
namespace
{
constexpr std::size_t kMaxAlloc = std::size_t(64) << 20;
void* guardedAlloc(std::size_t n)
{
	if (n > kMaxAlloc) throw std::bad_alloc();
	if (void* p = std::malloc(n ? n : 1)) return p;
	throw std::bad_alloc();
}
}  // namespace
void* operator new(std::size_t n) { return guardedAlloc(n); }
void* operator new[](std::size_t n) { return guardedAlloc(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
// The sanitizer runtime's own operator new (nothrow and aligned forms, and
// calls bound inside it) pairs with our delete: both are malloc/free
// underneath, so ASan's new/free pairing check would only report that.
extern "C" const char* __asan_default_options() { return "alloc_dealloc_mismatch=0"; }

namespace
{
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	if (size < 1) return 0;
	const int mode = data[0] % 3;
	mrpt::io::CMemoryStream mem;
	mem.assignMemoryNotOwn(data + 1, size - 1);
	auto ar = mrpt::serialization::archiveFrom(mem);
	try
	{
		if (mode == 0)
		{
			codemark::CObservationCodedLandmarks obs;
			ar >> obs;
			for (const auto& s : obs.sightings)
				if (s.id < 0 || s.id > 255) __builtin_trap();
		}
		else if (mode == 1)
		{
			codemark::CCodedLandmarksMap map;
			ar >> map;
		}
		else
		{
			for (int i = 0; i < 64; ++i)
			{
				codemark::CObservationCodedLandmarks obs;
				ar >> obs;
			}
		}
	}
	catch (const std::exception&)
	{
		// CExceptionEOF and every corrupt-data error: the clean way out.
	}
	return 0;
}
