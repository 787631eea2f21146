#pragma once
/** \file errors.h
 * One-line error messages for the apps: MRPT's exceptions carry a banner
 * ("==== MRPT exception ====") and a call-stack trace over several lines,
 * which say nothing to a user and break the apps' contract of one line on
 * stderr that names what is wrong and where.
 */
#include <codemark/landmark/text.h>
#include <tclap/ArgException.h>

#include <exception>
#include <string>

namespace codemark::app
{
/** \a what on one line: the MRPT banner, location and call stack dropped,
 * the remaining lines joined with "; " (codemark::oneLineMessage). */
inline std::string oneLine(const std::string& what) { return oneLineMessage(what); }

/** The same for an exception's what(). */
inline std::string oneLine(const std::exception& e) { return oneLineMessage(e.what()); }

/** \a s with control characters (e.g. a corrupt file's bytes quoted in an
 * error message) replaced by '?', for one-line reports and CSV cells. */
inline std::string printable(std::string s)
{
	for (auto& c : s)
		if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
	return s;
}
/** TCLAP's complaint about the command line on one line, the same in every
 * tool: "TOOL: error: ARG: WHAT (see --help)", ARG left out where TCLAP names
 * none (a missing required argument is named in WHAT). */
inline std::string argumentError(const std::string& tool, const TCLAP::ArgException& e)
{
	std::string id = e.argId();
	const std::string prefix = "Argument: ";
	if (id.rfind(prefix, 0) == 0) id.erase(0, prefix.size());
	const bool named = id.find_first_not_of(' ') != std::string::npos;
	return tool + ": error: " + (named ? id + ": " : "") + e.error() + " (see --help)";
}
}  // namespace codemark::app
