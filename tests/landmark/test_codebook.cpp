#include <codemark/landmark/codebook.h>
#include <gtest/gtest.h>

using namespace codemark;

TEST(Codebook, RoundTripAllIds)
{
	for (int id = 0; id < kNumIds; ++id)
	{
		const CodeCells c = encodeId(id);
		EXPECT_TRUE(c[1][1]) << "centre cell must be black for id " << id;
		const auto back = decodeCells(c);
		ASSERT_TRUE(back.has_value());
		EXPECT_EQ(*back, id);
	}
}

TEST(Codebook, SpecBitOrder)
{
	// r0c0 is bit 7, r2c2 is bit 0 (docs/spec.md section 1).
	const CodeCells c128 = encodeId(128);
	EXPECT_TRUE(c128[0][0]);
	EXPECT_FALSE(c128[2][2]);
	const CodeCells c1 = encodeId(1);
	EXPECT_TRUE(c1[2][2]);
	EXPECT_FALSE(c1[0][0]);
	const CodeCells c16 = encodeId(16);	 // bit 4: r1c0
	EXPECT_TRUE(c16[1][0]);
	EXPECT_FALSE(c16[1][2]);
	const CodeCells c8 = encodeId(8);  // bit 3: r1c2
	EXPECT_TRUE(c8[1][2]);
	int black = 0;
	for (auto& r : encodeId(255))
		for (bool b : r) black += b;
	EXPECT_EQ(black, 9);
}

TEST(Codebook, GreenCentreIsNotALandmark)
{
	for (int id : {0, 37, 255})
	{
		CodeCells c = encodeId(id);
		c[1][1] = false;
		EXPECT_FALSE(decodeCells(c).has_value());
	}
}

TEST(Codebook, OutOfRangeIdsThrow)
{
	EXPECT_THROW(encodeId(-1), std::out_of_range);
	EXPECT_THROW(encodeId(256), std::out_of_range);
}
