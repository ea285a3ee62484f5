// What LAZ's item decoders (laz_decode_v2.cpp, laz_layered_decode.cpp) and encoders (laz_encode.cpp,
// laz_layered_encode.cpp) share:
// LASzip's streaming median of x/y differences and the return contexts (laszip_common_v2.hpp,
// Apache 2.0, as read; dpoint's own code).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

namespace dpoint {

// LASzip's StreamingMedian5: not the median of the last five values but a sorted window of five
// that drops its largest value (in "high" mode) or its smallest (in "low" mode) for each new one,
// inserted in order; the mode turns to high when the new value falls below the old middle (or
// equals it, from low). Its middle predicts the next x or y difference. (LASzip writes the same as
// a tree of branches; this form gives the same window for every sequence.)
class LazMedian5 {
 public:
  int32_t get() const { return v_[2]; }
  void add(int32_t x) {
    const bool next_high = x < v_[2] || (!high_ && x == v_[2]);
    if (!high_) std::copy(v_.begin() + 1, v_.end(), v_.begin());
    size_t i = 4;
    for (; i > 0 && v_[i - 1] > x; --i) v_[i] = v_[i - 1];
    v_[i] = x;
    high_ = next_high;
  }

 private:
  std::array<int32_t, 5> v_{};
  bool high_ = true;
};

// Contexts from the return number r and the number of returns n (laszip_common_v2.hpp): kReturnMap
// [n][r] picks one of 16 histories of x/y differences and intensities, kReturnLevel[n][r] one of
// 8 heights. Both fill the entries that well-formed files never use (r > n, r or n = 0) too.
inline constexpr uint8_t kLazReturnMap[8][8] = {
    {15, 14, 13, 12, 11, 10, 9, 8},   {14, 0, 1, 3, 6, 10, 10, 9},    {13, 1, 2, 4, 7, 11, 11, 10},
    {12, 3, 4, 5, 8, 12, 12, 11},     {11, 6, 7, 8, 9, 13, 13, 12},   {10, 10, 11, 12, 13, 14, 14, 13},
    {9, 10, 11, 12, 13, 14, 15, 14},  {8, 9, 10, 11, 12, 13, 14, 15}};
inline constexpr uint8_t kLazReturnLevel[8][8] = {
    {0, 1, 2, 3, 4, 5, 6, 7}, {1, 0, 1, 2, 3, 4, 5, 6}, {2, 1, 0, 1, 2, 3, 4, 5}, {3, 2, 1, 0, 1, 2, 3, 4},
    {4, 3, 2, 1, 0, 1, 2, 3}, {5, 4, 3, 2, 1, 0, 1, 2}, {6, 5, 4, 3, 2, 1, 0, 1}, {7, 6, 5, 4, 3, 2, 1, 0}};

// GPS time's multiplier symbols (version 2): 0 (a difference unrelated to the last), 1..499 (that
// many times the last), 500 (500 or more times), 501..510 (−1..−10 times, −10 meaning −10 or
// less), then unchanged, a new sequence, and switches by 1, 2 and 3 sequences.
inline constexpr uint32_t kLazGpsMulti = 500;
inline constexpr int32_t kLazGpsMultiMinus = -10;
inline constexpr uint32_t kLazGpsUnchanged = kLazGpsMulti + static_cast<uint32_t>(-kLazGpsMultiMinus) + 1;  // 511
inline constexpr uint32_t kLazGpsFull = kLazGpsUnchanged + 1;                                              // 512
inline constexpr uint32_t kLazGpsMultiSymbols = kLazGpsFull + 4;                                           // 516

}  // namespace dpoint
