#include <codemark/detect/json.h>

#include <cmath>
#include <cstdio>
#include <sstream>

namespace codemark::detect
{
std::string jsonString(const std::string& s)
{
	std::string out = "\"";
	for (const unsigned char c : s)
	{
		switch (c)
		{
			case '"':
				out += "\\\"";
				break;
			case '\\':
				out += "\\\\";
				break;
			case '\n':
				out += "\\n";
				break;
			case '\r':
				out += "\\r";
				break;
			case '\t':
				out += "\\t";
				break;
			default:
				if (c < 0x20)
				{
					char buf[8];
					std::snprintf(buf, sizeof buf, "\\u%04x", c);
					out += buf;
				}
				else
					out += static_cast<char>(c);
		}
	}
	return out + "\"";
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
