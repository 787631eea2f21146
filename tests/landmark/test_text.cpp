#include <codemark/landmark/geometry.h>
#include <codemark/landmark/text.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

using namespace codemark;

TEST(Text, FiniteNumbersUseTheWholeToken)
{
	EXPECT_EQ(parseFiniteNumber("1.5"), 1.5);
	EXPECT_EQ(parseFiniteNumber("-2e-3"), -2e-3);
	for (const char* bad : {"", "1.5x", "x1", "nan", "NaN", "inf", "-inf", "1e999", "--1"})
		EXPECT_FALSE(parseFiniteNumber(bad).has_value()) << bad;
}

TEST(Text, RowsDropCommentsAndNameTheLine)
{
	EXPECT_EQ(parseNumberRow("1 2.5 -3  # c", "f.txt", 1), (std::vector<double>{1, 2.5, -3}));
	EXPECT_TRUE(parseNumberRow("   % only a comment", "f.txt", 2, "#%").empty());
	EXPECT_TRUE(parseNumberRow("", "f.txt", 3).empty());
	try
	{
		parseNumberRow("1 two 3", "f.txt", 7);
		FAIL();
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("f.txt:7: 'two'"), std::string::npos) << e.what();
	}
	EXPECT_THROW(parseNumberRow("1 inf", "f.txt", 8), std::runtime_error);
}

TEST(Text, ScaledByKeepsCustomSizes)
{
	LandmarkGeometry g;
	g.inner_size_m = 0.15;
	const auto h = g.scaledBy(2.0);
	EXPECT_DOUBLE_EQ(h.inner_size_m, 0.30);
	EXPECT_DOUBLE_EQ(h.outer_size_m, 0.40);
	EXPECT_THROW(g.scaledBy(0.0), std::invalid_argument);
	EXPECT_THROW(g.scaledBy(std::nan("")), std::invalid_argument);
}

TEST(Text, CreateFolderMakesItsParentsAndNamesWhatFails)
{
	namespace fs = std::filesystem;
	const fs::path base =
		fs::temp_directory_path() / ("codemark-test-folder-" + std::to_string(::getpid()));
	fs::remove_all(base);
	const fs::path nested = base / "a" / "b";
	createFolder(nested.string(), "the test folder");
	EXPECT_TRUE(fs::is_directory(nested));
	EXPECT_NO_THROW(createFolder(nested.string(), "the test folder"));	// already there
	std::ofstream(base / "file") << "x";
	// The path itself a file, and a parent a file: each named, with a reason.
	for (const fs::path& bad : {base / "file", base / "file" / "c"})
	{
		const std::string head = bad.string() + ": cannot create the test folder: ";
		try
		{
			createFolder(bad.string(), "the test folder");
			ADD_FAILURE() << bad << ": no error";
		}
		catch (const std::runtime_error& e)
		{
			const std::string m = e.what();
			EXPECT_EQ(m.rfind(head, 0), 0u) << m;
			EXPECT_GT(m.size(), head.size()) << m;
		}
	}
	fs::remove_all(base);
}
