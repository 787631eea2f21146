#include <codemark/landmark/text.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace codemark
{
std::optional<double> parseFiniteNumber(const std::string& token)
{
	std::size_t used = 0;
	double v = 0;
	try
	{
		v = std::stod(token, &used);
	}
	catch (const std::exception&)
	{
		return std::nullopt;
	}
	if (used == 0 || used != token.size() || !std::isfinite(v)) return std::nullopt;
	return v;
}

std::vector<double> parseNumberRow(
	std::string text, const std::string& file, int line, const char* comment_chars)
{
	if (const auto c = text.find_first_of(comment_chars); c != std::string::npos) text.erase(c);
	std::istringstream ss(text);
	std::vector<double> v;
	for (std::string tok; ss >> tok;)
	{
		const auto x = parseFiniteNumber(tok);
		if (!x)
			throw std::runtime_error(
				file + ":" + std::to_string(line) + ": '" + tok + "' is not a finite number");
		v.push_back(*x);
	}
	return v;
}

}  // namespace codemark
