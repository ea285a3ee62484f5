// splitmix64 (Steele, Lea and Flood 2014) as a counter-based generator: output `index` of the stream
// started at `seed` is a pure function of the two, so work split over threads in any way draws the
// same numbers (random2d's points, the mesh sampler's samples).
#pragma once

#include <cstdint>

namespace dpoint {

inline constexpr uint64_t kSplitmixGamma = 0x9E3779B97F4A7C15ull;  // its increment (2^64 / golden ratio)

// splitmix64's finalizer: a bijective mix of all 64 bits.
inline uint64_t splitmixMix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Output number `index` (0-based) of splitmix64 started from `seed`.
inline uint64_t splitmix64At(uint64_t seed, uint64_t index) { return splitmixMix(seed + (index + 1) * kSplitmixGamma); }

// The top 53 bits as a double in [0, 1), exactly.
inline double unitInterval(uint64_t u) { return static_cast<double>(u >> 11) * 0x1p-53; }

}  // namespace dpoint
