#pragma once
/** \file errors.h
 * One-line error messages for the apps: MRPT's exceptions carry a banner
 * ("==== MRPT exception ====") and a call-stack trace over several lines,
 * which say nothing to a user and break the apps' contract of one line on
 * stderr that names what is wrong and where.
 */
#include <sstream>
#include <string>

namespace codemark::app
{
/** \a what on one line: the MRPT banner and call stack dropped, the
 * remaining lines joined with "; ". */
inline std::string oneLine(const std::string& what)
{
	std::string msg = what;
	const auto stack = msg.find("Call stack backtrace");
	if (stack != std::string::npos) msg.resize(stack);
	std::string out, line;
	std::istringstream in(msg);
	while (std::getline(in, line))
	{
		while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
		if (line.empty() || line.find("==== MRPT exception ====") != std::string::npos ||
			line.find("==== non-MRPT exception ====") != std::string::npos)
			continue;
		// MRPT: "Message:  WHAT" then "Location: FILE:LINE: [function]": keep WHAT.
		if (line.rfind("Location:", 0) == 0) continue;
		if (line.rfind("Message:", 0) == 0) line = line.substr(line.find_first_not_of(" ", 8));
		out += (out.empty() ? "" : "; ") + line;
	}
	return out.empty() ? what : out;
}
}  // namespace codemark::app
