// libFuzzer target: the camera file parsers (CameraModel::load over MRPT
// ini, ROS YAML and OpenCV YAML). Byte 0 picks the file type, the rest is
// the file. A load either gives a valid camera or throws a std::exception.
#include <codemark/landmark/camera.h>

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	if (size < 1) return 0;
	static const char* kExt[] = {".ini", ".yaml", ".yml", ".ini"};
	// The parsers read files: write one per process in the tmpfs when there is one.
	static const std::string dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
	const std::string path =
		dir + "/codemark_fuzz_camera_" + std::to_string(getpid()) + kExt[data[0] & 3];
	if (FILE* f = std::fopen(path.c_str(), "wb"))
	{
		std::fwrite(data + 1, 1, size - 1, f);
		std::fclose(f);
	}
	else
		return 0;
	try
	{
		std::vector<std::string> warnings;	// collected, not printed
		const auto cam = codemark::CameraModel::load(path, &warnings);
		if (cam.width() <= 0 || cam.height() <= 0) __builtin_trap();
		if (!std::isfinite(cam.params().fx()) || cam.params().fx() <= 0) __builtin_trap();
	}
	catch (const std::exception&)
	{
	}
	std::remove(path.c_str());
	return 0;
}
