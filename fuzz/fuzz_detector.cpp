// libFuzzer target: the detector's top-level function on arbitrary images.
// Bytes 0-1: width, 2-3: height (each 0..1023), 4: type (channels 1, 3 or 4;
// 8 or 16 bit), the rest: pixel data, repeated to fill the image. With a
// PNG or JPEG signature the bytes go through cv::imdecode instead.
#include <codemark/detect/detector.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdint>
#include <cstring>
#include <stdexcept>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	static const codemark::CameraModel camera = codemark::CameraModel::paperDefault();
	static const codemark::LandmarkGeometry geometry;
	static const codemark::detect::DetectorOptions options;
	cv::Mat image;
	const bool png = size > 8 && std::memcmp(data, "\x89PNG", 4) == 0;
	const bool jpeg = size > 4 && data[0] == 0xFF && data[1] == 0xD8;
	if (png || jpeg)
	{
		// Decoding is OpenCV's business; keep the images small so that a
		// run tests the detector rather than the decoder's allocations.
		const cv::Mat buf(1, static_cast<int>(size), CV_8UC1, const_cast<uint8_t*>(data));
		image = cv::imdecode(buf, cv::IMREAD_UNCHANGED);
		if (image.total() > 1024u * 1024u) return 0;
	}
	else
	{
		if (size < 5) return 0;
		const int w = (data[0] | (data[1] << 8)) & 1023;
		const int h = (data[2] | (data[3] << 8)) & 1023;
		static const int kTypes[] = {CV_8UC3,  CV_8UC1, CV_8UC4, CV_16UC3,
									 CV_16UC1, CV_8UC3, CV_8UC3, CV_8UC3};
		const int type = kTypes[data[4] & 7];
		image.create(h, w, type);
		const uint8_t* px = data + 5;
		const size_t n = size - 5;
		const size_t bytes = image.total() * image.elemSize();
		if (bytes == 0)
		{
			// an empty image (0 rows or columns): no pixel data
		}
		else if (n == 0)
			std::memset(image.data, 0, bytes);
		else
			for (size_t i = 0; i < bytes; ++i) image.data[i] = px[i % n];
	}
	try
	{
		const auto r = codemark::detect::detect(image, camera, geometry, options);
		for (const auto& l : r.landmarks)
			if (l.detection.id < 0 || l.detection.id > 255) __builtin_trap();
	}
	catch (const std::invalid_argument&)
	{
		// The documented rejection of images that are not 8-bit BGR.
	}
	return 0;
}
