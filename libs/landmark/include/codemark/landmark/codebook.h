#pragma once
/** \file codebook.h
 * The 3x3 code board (docs/spec.md section 1): the centre cell is always
 * black; the other eight cells, read row by row from the top-left as seen
 * from the front and skipping the centre, are bits 7..0 (black = 1).
 */
#include <array>
#include <optional>

namespace codemark
{
constexpr int kNumIds = 256;  //!< IDs run 0..255

/** Cells [row][col] as seen from the front; true = black. */
using CodeCells = std::array<std::array<bool, 3>, 3>;

/** The cells of \a id. Throws std::out_of_range unless 0 <= id <= 255. */
CodeCells encodeId(int id);

/** The ID of \a cells, or nullopt when the centre cell is green (not a
 * landmark). */
std::optional<int> decodeCells(const CodeCells& cells);

}  // namespace codemark
