#include <codemark/detect/json.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <sstream>

namespace codemark::detect
{
std::string jsonString(const std::string& s)
{
	// Invalid UTF-8 (a file name in another encoding) becomes U+FFFD, not
	// an exception.
	return nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string jsonNumber(double v)
{
	if (!std::isfinite(v)) return "null";
	char buf[32];
	std::snprintf(buf, sizeof buf, "%.10g", v);
	return buf;
}

std::string imageToJson(
	const std::string& image, int width, int height, double time_ms,
	const std::vector<DetectedLandmark>& dets, const std::vector<JsonFields>& extra)
{
	std::ostringstream o;
	o << "{\"image\": " << jsonString(image) << ", \"width\": " << width
	  << ", \"height\": " << height << ", \"time_ms\": " << jsonNumber(time_ms)
	  << ", \"detections\": [";
	for (size_t i = 0; i < dets.size(); ++i)
	{
		const auto& d = dets[i];
		o << (i ? ", " : "") << "{\"id\": " << d.detection.id << ", \"corners\": [";
		for (int k = 0; k < 4; ++k)
			o << (k ? ", " : "") << "[" << jsonNumber(d.detection.corners[k].x()) << ", "
			  << jsonNumber(d.detection.corners[k].y()) << "]";
		o << "], \"P\": [";
		for (int k = 0; k < 4; ++k) o << (k ? ", " : "") << jsonNumber(d.P(k));
		o << "]";
		if (i < extra.size())
			for (const auto& [key, value] : extra[i]) o << ", " << jsonString(key) << ": " << value;
		o << "}";
	}
	o << "]}";
	return o.str();
}

std::string errorToJson(const std::string& image, const std::string& error)
{
	return "{\"image\": " + jsonString(image) + ", \"error\": " + jsonString(error) + "}";
}

}  // namespace codemark::detect
