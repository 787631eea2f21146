// libFuzzer target: deserialization of codemark's MRPT classes from
// arbitrary bytes (mrpt::serialization::archiveFrom over a memory stream).
// Byte 0 picks the reader:
//   0: into a CObservationCodedLandmarks (ar >> obj: class header, version, data)
//   1: into a CCodedLandmarksMap
//   2: a rawlog read as MRPT's tools read it (ReadObject until the end), restricted
//      to streams whose objects are codemark's classes or rawlog containers,
//      so that the run tests our readers and not every MRPT class.
// Anything unreadable must throw; nothing may crash, hang or allocate without bound.
#include <codemark/mrpt/CCodedLandmarksMap.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>

#include <cctype>
#include <cstdint>
#include <cstring>
#include <exception>

namespace
{
/** True if every class name the stream could name is one of ours: a cheap
 * pre-filter (MRPT writes a class name as its length | 0x80, then the name). */
bool onlyOurClasses(const uint8_t* data, size_t size)
{
	static const char* kOurs[] = {
		"codemark::CObservationCodedLandmarks", "codemark::CCodedLandmarksMap"};
	for (size_t i = 0; i + 1 < size; ++i)
	{
		if (!(data[i] & 0x80)) continue;
		const size_t n = data[i] & 0x7F;
		if (n < 2 || i + 1 + n > size) continue;
		const char* name = reinterpret_cast<const char*>(data + i + 1);
		bool word = name[0] == 'C' || name[0] == 'c';
		for (size_t k = 0; k < n && word; ++k)
			word = std::isalnum(static_cast<unsigned char>(name[k])) || name[k] == '_' ||
				name[k] == ':';
		if (!word) continue;
		bool ours = false;
		for (const char* o : kOurs)
			ours = ours || (std::strlen(o) == n && std::memcmp(o, name, n) == 0);
		if (!ours) return false;
	}
	return true;
}
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
			if (!onlyOurClasses(data + 1, size - 1)) return 0;
			for (int i = 0; i < 64; ++i) ar.ReadObject();
		}
	}
	catch (const std::exception&)
	{
		// CExceptionEOF and every corrupt-data error: the clean way out.
	}
	return 0;
}
