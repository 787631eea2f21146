#include <codemark/landmark/text.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
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

namespace
{
std::string trim(const std::string& s)
{
	const auto b = s.find_first_not_of(" \t\r\n");
	if (b == std::string::npos) return {};
	const auto e = s.find_last_not_of(" \t\r\n");
	return s.substr(b, e - b + 1);
}

bool sameName(const std::string& a, const std::string& b)
{
	return a.size() == b.size() && std::equal(
									   a.begin(), a.end(), b.begin(),
									   [](char x, char y)
									   {
										   return std::tolower(static_cast<unsigned char>(x)) ==
												  std::tolower(static_cast<unsigned char>(y));
									   });
}
}  // namespace

std::string iniWhere(const std::string& file, const std::string& section, const std::string& key)
{
	std::ifstream in(file);
	std::string current;
	int n = 0;
	for (std::string line; std::getline(in, line);)
	{
		++n;
		const std::string t = trim(line);
		if (t.empty() || t[0] == '#' || t[0] == ';' || t.rfind("//", 0) == 0) continue;
		if (t[0] == '[')
		{
			const auto close = t.find(']');
			current = trim(t.substr(1, close == std::string::npos ? std::string::npos : close - 1));
			continue;
		}
		const auto eq = t.find('=');
		if (eq != std::string::npos && sameName(current, section) &&
			sameName(trim(t.substr(0, eq)), key))
			return file + ":" + std::to_string(n) + ": ";
	}
	return file + ": ";
}

std::string oneLineMessage(const std::string& what)
{
	std::string msg = what;
	if (const auto stack = msg.find("Call stack backtrace"); stack != std::string::npos)
		msg.resize(stack);
	std::string joined;
	std::istringstream lines(msg);
	for (std::string l; std::getline(lines, l);)
	{
		// A banner ("==== MRPT exception ====") may follow a prefix on the
		// same line (a caller's "entry 12: " before MRPT's text): keep that.
		if (const auto banner = l.find("====");
			banner != std::string::npos && l.find("exception ====") != std::string::npos)
			l.resize(banner);
		l = trim(l);
		if (l.empty()) continue;
		if (l.rfind("Location:", 0) == 0) continue;
		if (l.rfind("Message:", 0) == 0) l = trim(l.substr(8));
		joined += (joined.empty() ? "" : "; ") + l;
	}
	return joined.empty() ? trim(what) : joined;
}

namespace
{
// True when \a msg begins "PATH: " or "PATH:LINE: " with PATH an existing
// file (the error already names its own file, e.g. a calibration file read
// while a config file loads).
bool startsWithAFile(const std::string& msg)
{
	const auto colon = msg.find(": ");
	if (colon == std::string::npos || colon == 0) return false;
	std::string path = msg.substr(0, colon);
	if (const auto c = path.rfind(':');
		c != std::string::npos && c + 1 < path.size() &&
		std::all_of(
			path.begin() + static_cast<std::ptrdiff_t>(c) + 1, path.end(),
			[](unsigned char ch) { return std::isdigit(ch); }))
		path.resize(c);
	std::error_code ec;
	return std::filesystem::is_regular_file(path, ec);
}

// iniWhere() for a message that begins "[SECTION] KEY" (the options'
// validators' convention: "[ekf] gate_probability: must be in (0, 1)"),
// else "FILE: ".
std::string whereMessageKeyIs(const std::string& file, const std::string& msg)
{
	if (msg.empty() || msg[0] != '[') return file + ": ";
	const auto close = msg.find(']');
	if (close == std::string::npos || close + 1 >= msg.size() || msg[close + 1] != ' ')
		return file + ": ";
	const auto key_begin = close + 2;
	auto key_end = key_begin;
	while (key_end < msg.size() && (std::isalnum(static_cast<unsigned char>(msg[key_end])) ||
									msg[key_end] == '_' || msg[key_end] == '.'))
		++key_end;
	if (key_end == key_begin) return file + ": ";
	return iniWhere(file, msg.substr(1, close - 1), msg.substr(key_begin, key_end - key_begin));
}
}  // namespace

void rethrowNamingIniFile(const std::string& file)
{
	try
	{
		throw;
	}
	catch (const IniValueError& e)
	{
		const std::string what = e.what();
		if (what.find(file) != std::string::npos) throw std::runtime_error(what);
		throw std::runtime_error(iniWhere(file, e.section, e.key) + what);
	}
	catch (const std::exception& e)
	{
		const std::string msg = oneLineMessage(e.what());
		const std::string named = msg.find(file) != std::string::npos || startsWithAFile(msg)
									  ? msg
									  : whereMessageKeyIs(file, msg) + msg;
		// Keep the kind: callers and tests tell invalid values from I/O errors.
		if (dynamic_cast<const std::invalid_argument*>(&e)) throw std::invalid_argument(named);
		throw std::runtime_error(named);
	}
}

std::optional<bool> parseIniBoolean(const std::string& text)
{
	std::string v = trim(text);
	std::transform(
		v.begin(), v.end(), v.begin(),
		[](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
	if (v == "true" || v == "yes" || v == "1") return true;
	if (v == "false" || v == "no" || v == "0") return false;
	return std::nullopt;
}

namespace
{
// "FILE:LINE: [SECTION] KEY = 'VALUE': WHAT" (no "FILE:LINE: " without a
// file), the refusal of requireIniNumbers() and requireIniBooleans().
IniValueError iniValueError(
	const mrpt::config::CConfigFileBase& cfg, const std::string& section, const std::string& key,
	const std::string& file, const std::string& what)
{
	return IniValueError(
		section, key,
		(file.empty() ? std::string() : iniWhere(file, section, key)) + "[" + section + "] " + key +
			" = '" + trim(cfg.read_string(section, key, "")) + "': " + what);
}
}  // namespace

void requireIniNumbers(
	const mrpt::config::CConfigFileBase& cfg, const std::string& section,
	std::initializer_list<const char*> keys, bool integers, bool vector, const std::string& file)
{
	for (const char* key : keys)
	{
		if (!cfg.keyExists(section, key)) continue;
		const std::string raw = cfg.read_string(section, key, "");
		std::string v = raw;
		if (const auto c = v.find_first_of(";#"); c != std::string::npos) v.erase(c);
		v = trim(v);
		if (vector && v.size() >= 2 && v.front() == '[' && v.back() == ']')
			v = v.substr(1, v.size() - 2);
		std::replace(v.begin(), v.end(), ',', ' ');
		std::istringstream ss(v);
		int count = 0;
		bool ok = true;
		for (std::string tok; ss >> tok && ok; ++count)
		{
			const auto x = parseFiniteNumber(tok);
			ok = x && (!integers || std::floor(*x) == *x);
		}
		if (ok && (count == 1 || (vector && count > 0))) continue;
		throw iniValueError(
			cfg, section, key, file,
			std::string("not ") + (vector ? "a list of " : "a ") + (integers ? "whole" : "finite") +
				(vector ? " numbers" : " number"));
	}
}

void requireIniBooleans(
	const mrpt::config::CConfigFileBase& cfg, const std::string& section,
	std::initializer_list<const char*> keys, const std::string& file)
{
	for (const char* key : keys)
	{
		if (!cfg.keyExists(section, key)) continue;
		// No comment stripped: read_bool() reads "true ; note" as false.
		const std::string raw = cfg.read_string(section, key, "");
		if (parseIniBoolean(raw)) continue;
		throw iniValueError(
			cfg, section, key, file,
			std::string("not a boolean (true/false") +
				(raw.find_first_of(";#") != std::string::npos
					 ? "; MRPT reads a ';' or '#' comment after a boolean as part of it, and "
					   "the whole as false"
					 : "") +
				")");
	}
}

void createFolder(const std::string& path, const std::string& what)
{
	std::error_code ec;
	std::filesystem::create_directories(path, ec);
	if (!ec && std::filesystem::is_directory(path, ec)) return;
	throw std::runtime_error(
		path + ": cannot create " + what + ": " +
		(ec ? ec.message() : std::string("a file of that name is in the way")));
}

}  // namespace codemark
