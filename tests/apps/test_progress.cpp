// The progress display, drawn to a file as if to a log and as if to a
// terminal: never past its total, never backwards, its last line once.
#include <gtest/gtest.h>

#include <cstdio>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "progress.h"

namespace
{
std::string drawn(bool tty, const std::vector<std::pair<long, long>>& updates, int finishes)
{
	std::FILE* f = std::tmpfile();
	{
		codemark::app::ProgressBar bar("tool", true, f, tty);
		for (const auto& [d, t] : updates) bar.update(d, t);
		for (int k = 0; k < finishes; ++k) bar.finish();
	}
	std::rewind(f);
	std::string text;
	char buf[4096];
	while (const size_t n = std::fread(buf, 1, sizeof buf, f)) text.append(buf, n);
	std::fclose(f);
	return text;
}

std::vector<std::string> lines(const std::string& s)
{
	std::vector<std::string> out;
	std::istringstream in(s);
	for (std::string l; std::getline(in, l);) out.push_back(l);
	return out;
}

// A byte count that overshoots its estimate (a compressed input) and
// repeats its end (a fraction that reaches 1 before the last step).
std::vector<std::pair<long, long>> overshooting()
{
	std::vector<std::pair<long, long>> u;
	for (long d = 0; d <= 13000; d += 250) u.emplace_back(d, 5075);
	for (int k = 0; k < 160; ++k) u.emplace_back(1000, 1000);
	return u;
}
}  // namespace

TEST(Progress, LogGetsDecilesThenOneLastLine)
{
	const auto out = lines(drawn(false, overshooting(), 2));
	ASSERT_EQ(out.size(), 10u);	 // 10% .. 90%, then the last line once
	const std::regex line(R"(tool: (\d+)/(\d+) \((\d+)%\).*)");
	int last_pct = 0;
	for (const auto& l : out)
	{
		std::smatch m;
		ASSERT_TRUE(std::regex_match(l, m, line)) << l;
		EXPECT_LE(std::stol(m[1]), std::stol(m[2])) << l;
		EXPECT_LE(std::stoi(m[3]), 100) << l;
		EXPECT_GT(std::stoi(m[3]), last_pct) << l;
		last_pct = std::stoi(m[3]);
	}
	EXPECT_EQ(last_pct, 100);
}

TEST(Progress, TerminalRedrawsInPlaceWithRateAndTimeLeft)
{
	const std::string s = drawn(true, overshooting(), 2);
	EXPECT_NE(s.find('\r'), std::string::npos);
	EXPECT_NE(s.find("/s"), std::string::npos);
	EXPECT_NE(s.find("s left"), std::string::npos);
	EXPECT_EQ(lines(s).size(), 1u) << "one line, redrawn, ended once";
	const std::regex count(R"((\d+)/(\d+) )");
	for (auto it = std::sregex_iterator(s.begin(), s.end(), count); it != std::sregex_iterator();
		 ++it)
		EXPECT_LE(std::stol((*it)[1]), std::stol((*it)[2]));
	EXPECT_NE(s.find("100%"), std::string::npos);
}

TEST(Progress, ARunThatFailsLeavesNoLastLine)
{
	const auto out = lines(drawn(false, {{10, 100}, {55, 100}}, 0));
	ASSERT_EQ(out.size(), 2u);	// 10%, then 50% (a jump past several deciles: one line)
	EXPECT_EQ(out.back(), "tool: 55/100 (50%)");
}
