#pragma once
/** \file text.h
 * Reading the project's plain-text tables (map files, trajectories, ground
 * truth, pose lists): strict numbers, and errors that name the file and line;
 * output folders made with their parents.
 */
#include <mrpt/config/CConfigFileBase.h>

#include <initializer_list>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

namespace codemark
{
/** \a token as a number when it is entirely one finite number ("1.5"; not
 * "1.5x", "nan", "inf" or ""), else nullopt. */
std::optional<double> parseFiniteNumber(const std::string& token);

/** \a text as MRPT's read_bool() reads it when it is one of true, false,
 * yes, no, 1 or 0 (any case, surrounding blanks ignored), else nullopt:
 * read_bool() takes anything else as false without a word. */
std::optional<bool> parseIniBoolean(const std::string& text);

/** The numbers of one line of a table, everything from the first of
 * \a comment_chars on dropped; empty for a blank or comment line. Throws
 * std::runtime_error "FILE:LINE: 'TOKEN' is not a finite number". */
std::vector<double> parseNumberRow(
	std::string text, const std::string& file, int line, const char* comment_chars = "#");

/** A bad value in an ini file: the section and key at fault (the file is
 * not known to MRPT's config readers; see rethrowNamingIniFile()). */
class IniValueError : public std::runtime_error
{
   public:
	IniValueError(const std::string& section_, const std::string& key_, const std::string& what)
		: std::runtime_error(what), section(section_), key(key_)
	{
	}
	std::string section, key;
};

/** Checks that each of \a keys that [\a section] of \a cfg sets holds
 * finite numbers only (MRPT's read_double() takes "0.2x" as 0.2 and "abc"
 * as 0): one number, or with \a vector a list such as "[640 480]". With
 * \a integers the numbers must also be whole. A trailing ';' or '#' comment
 * is allowed, as MRPT keeps those in values. Throws IniValueError
 * "[SECTION] KEY = 'VALUE': not a finite number", prefixed with
 * "FILE:LINE: " when \a file (the ini's path) is given. */
void requireIniNumbers(
	const mrpt::config::CConfigFileBase& cfg, const std::string& section,
	std::initializer_list<const char*> keys, bool integers = false, bool vector = false,
	const std::string& file = {});

/** Checks that each of \a keys that [\a section] of \a cfg sets holds a
 * boolean as MRPT's read_bool() reads it: true, false, yes, no, 1 or 0
 * (any case). read_bool() takes anything else as false without a word:
 * "maybe", "on", and "true ; note" too (it keeps a ';' or '#' comment in
 * the value, unlike a '//' one). Throws
 * IniValueError "[SECTION] KEY = 'VALUE': not a boolean (true/false)",
 * prefixed with "FILE:LINE: " when \a file is given. */
void requireIniBooleans(
	const mrpt::config::CConfigFileBase& cfg, const std::string& section,
	std::initializer_list<const char*> keys, const std::string& file = {});

/** "FILE:LINE: " of \a key in [\a section] of the ini file \a file, or
 * "FILE: " when the key is not found there. */
std::string iniWhere(const std::string& file, const std::string& section, const std::string& key);

/** An exception message on one line: MRPT's banner, "Location:" line and
 * call stack dropped (text before a banner on its line kept), the remaining
 * lines joined with "; ". */
std::string oneLineMessage(const std::string& what);

/** Call inside a catch block around the loading of the ini \a file:
 * rethrows the exception being handled as std::runtime_error (or
 * std::invalid_argument if it was one) naming the file, and the line for an
 * IniValueError or a message that begins "[SECTION] KEY" (the options'
 * validators); one line (MRPT's banner and call stack dropped). A message
 * that already begins with another existing file's path is kept as is. */
[[noreturn]] void rethrowNamingIniFile(const std::string& file);

/** Creates the folder \a path with its missing parents (an existing folder
 * is fine; mrpt::system::createDirectory() makes one level only). Throws
 * std::runtime_error "PATH: cannot create WHAT: REASON", REASON the
 * system's, or "a file of that name is in the way". */
void createFolder(const std::string& path, const std::string& what);

}  // namespace codemark
