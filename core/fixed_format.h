// Fixed-point formatting of doubles, exactly as printf("%.*f") in the C locale rounds them
// (the exact binary value, rounded half to even at the last digit), several times faster than
// std::to_chars(..., chars_format::fixed, N) for the common case.
#pragma once

#include <cstddef>

namespace dpoint {

// Longest text formatFixed writes for `decimals` digits: sign, 309 integer digits, point.
constexpr size_t fixedFormatMaxChars(int decimals) { return 311 + static_cast<size_t>(decimals); }

// Writes v with `decimals` (0..100) digits after the point at p (no terminator) and returns the
// end. Finite v only. Needs fixedFormatMaxChars(decimals) bytes of room.
char* formatFixed(char* p, double v, int decimals);

}  // namespace dpoint
