#pragma once
/** \file text.h
 * Reading the project's plain-text tables (map files, trajectories, ground
 * truth, pose lists): strict numbers, and errors that name the file and line.
 */
#include <optional>
#include <string>
#include <vector>

namespace codemark
{
/** \a token as a number when it is entirely one finite number ("1.5"; not
 * "1.5x", "nan", "inf" or ""), else nullopt. */
std::optional<double> parseFiniteNumber(const std::string& token);

/** The numbers of one line of a table, everything from the first of
 * \a comment_chars on dropped; empty for a blank or comment line. Throws
 * std::runtime_error "FILE:LINE: 'TOKEN' is not a finite number". */
std::vector<double> parseNumberRow(
	std::string text, const std::string& file, int line, const char* comment_chars = "#");

}  // namespace codemark
