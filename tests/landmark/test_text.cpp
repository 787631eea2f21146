#include <codemark/landmark/geometry.h>
#include <codemark/landmark/text.h>
#include <gtest/gtest.h>

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
