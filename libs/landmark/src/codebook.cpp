#include <codemark/landmark/codebook.h>

#include <stdexcept>
#include <string>

namespace codemark
{
namespace
{
// Bit index (7..0) of each cell read row by row, -1 for the centre.
constexpr int kBitOfCell[3][3] = {{7, 6, 5}, {4, -1, 3}, {2, 1, 0}};
}  // namespace

CodeCells encodeId(int id)
{
	if (id < 0 || id >= kNumIds)
		throw std::out_of_range("landmark ID " + std::to_string(id) + " is outside 0..255");
	CodeCells cells{};
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
		{
			const int bit = kBitOfCell[r][c];
			cells[r][c] = bit < 0 ? true : ((id >> bit) & 1) != 0;
		}
	return cells;
}

std::optional<int> decodeCells(const CodeCells& cells)
{
	if (!cells[1][1]) return std::nullopt;
	int id = 0;
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
		{
			const int bit = kBitOfCell[r][c];
			if (bit >= 0 && cells[r][c]) id |= 1 << bit;
		}
	return id;
}

}  // namespace codemark
