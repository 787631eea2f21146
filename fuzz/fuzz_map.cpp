// libFuzzer target: the landmark map file parser (LandmarkMap::parse). It
// must either return a map whose every landmark is valid or throw
// MapFileError naming the line.
#include <codemark/landmark/map.h>

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
	try
	{
		const auto map = codemark::LandmarkMap::parse(in, "fuzz.txt");
		for (const auto& l : map.landmarks)
		{
			if (l.id < 0 || l.id > 255) __builtin_trap();
			if (!std::isfinite(l.scale) || l.scale <= 0) __builtin_trap();
		}
	}
	catch (const codemark::MapFileError&)
	{
	}
	return 0;
}
