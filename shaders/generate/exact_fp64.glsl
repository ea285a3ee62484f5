// Correctly rounded fp64 square root and reciprocal (round to nearest even), for shaders that must
// reproduce the CPU's IEEE results bit for bit (shaders/generate/escape.comp). Vulkan rounds fp64 add, sub
// and mul correctly but lets sqrt and division be off by a few ulps; here the built-in result is
// only a first guess, which integer arithmetic then moves to the correctly rounded one.
//
// Both work on the significand as an integer. Scaled by a power of two (exact) into a binade, the
// answer is the integer nearest an exact rational, and whether a candidate integer A is that
// nearest one is decided by the sign of an integer residual compared with a half step:
//   sqrt: A = round(√N), N = g·2^104 with g ∈ [1, 4): A is right iff −A < N − A² ≤ A;
//   1/m:  A = round(2^105 / Y), Y = m·2^52, m ∈ (1, 2): A is right iff |A·Y − 2^105| < Y/2.
// The residuals are tiny next to 2^63 whenever the guess is within a few hundred ulps, so they
// are computed modulo 2^64 with plain uint64 products, whose wrap-around drops only the high
// bits the residual does not have (2^104 and 2^105 are 0 modulo 2^64). A residual is never
// exactly on the half step (a square root or reciprocal of a double never ties), so the
// comparisons decide, the guess moves by one ulp at a time, and the answer is the CPU's.
// Every double here is `precise`: no fusing, no reassociation.
//
// Needs GL_ARB_gpu_shader_int64 (shaderInt64) and shaderFloat64. Inputs are positive, finite and
// give a normal result (the callers' ranges); 0 and ±∞ pass through sqrt unchanged.

// The test shader (exact_fp64_test.comp) moves the built-in guesses off by a few ulps through
// this hook, to show the correction does not rely on a device whose sqrt and division happen to
// be correctly rounded (lavapipe's are).
#ifndef EXACT_FP64_GUESS
#define EXACT_FP64_GUESS(guess) (guess)
#endif

const double kTwo52 = 4503599627370496.0lf;  // 2^52
const double kTwo53 = 9007199254740992.0lf;  // 2^53

// The corrections, for either form: the guess A moved an ulp at a time to the integer nearest
// √N (N known modulo 2^64, as n_low) or 2^105 / Y.
uint64_t nearestSqrt(uint64_t n_low, uint64_t a) {
  for (int step = 0; step < 64; ++step) {
    const int64_t residual = int64_t(n_low - a * a);  // N − A², exact while |N − A²| < 2^63
    if (residual > int64_t(a)) a += 1;                 // N > A² + A: above A + 1/2
    else if (residual <= -int64_t(a)) a -= 1;          // N ≤ A² − A: below A − 1/2
    else break;
  }
  return a;
}

uint64_t nearestRecip(uint64_t y_int, uint64_t a) {
  for (int step = 0; step < 64; ++step) {
    const int64_t residual = int64_t(a * y_int);  // A·Y − 2^105 modulo 2^64
    if (2 * residual > int64_t(y_int)) a -= 1;
    else if (2 * residual < -int64_t(y_int)) a += 1;
    else break;
  }
  return a;
}

// sqrtRn and recipRn in the scaled form, for any input: frexp and ldexp scale it into a binade.
// Used on lavapipe (kExactFp64Bits false), and for the inputs the bit-level forms below do not take
// (a subnormal x; a reciprocal that is not normal).
double sqrtRnScaled(double x) {
  if (x == 0.0lf || isinf(x)) return x;  // √±0 = ±0, √∞ = ∞
  int e;
  precise double f = frexp(x, e);  // x = f·2^e, f ∈ [0.5, 1)
  const int k = (e - 1) >> 1;      // ⌊(e − 1)/2⌋ (arithmetic shift)
  precise double g = ldexp(x, -2 * k);  // x·2^-2k ∈ [1, 4), exact
  const uint64_t n_low = uint64_t(g * kTwo52) << 52;  // N mod 2^64, N = g·2^104
  precise double guess = clamp(EXACT_FP64_GUESS(sqrt(g)), 1.0lf, 2.0lf);
  // An integer: the guess lies on the 2^-52 grid of [1, 2].
  const uint64_t a = nearestSqrt(n_low, uint64_t(guess * kTwo52));
  return ldexp(double(a), k - 52);  // a ≤ 2^53: exact, and the scaling is exact
}

double recipRnScaled(double y) {
  int e;
  precise double f = frexp(y, e);  // y = f·2^e, f ∈ [0.5, 1)
  precise double m = 2.0lf * f;    // y = m·2^(e−1), m ∈ [1, 2), 1/y = (1/m)·2^(1−e)
  if (m == 1.0lf) return ldexp(1.0lf, 1 - e);
  const uint64_t y_int = uint64_t(m * kTwo52);  // Y ∈ (2^52, 2^53)
  precise double guess = clamp(EXACT_FP64_GUESS(1.0lf / m), 0.5lf, 1.0lf);
  const uint64_t a = nearestRecip(y_int, uint64_t(guess * kTwo53));  // 1/m ∈ (1/2, 1): the 2^-53 grid
  return ldexp(double(a), -52 - e);  // A·2^-53·2^(1−e)
}

// Which form sqrtRn and recipRn take (the including shader leaves constant_id 2 to this file):
// the bit-level one, faster on a GPU (escape counts of the res-2048 Mandelbulb on an H200: 865 →
// 655 ms), or the scaled one, faster on lavapipe (a res-160 Mandelbulb's counts there: 0.38 →
// 0.29 s), whose 8-wide LLVM vectors pay more for the 64-bit shifts and selects. The results are
// the same bits.
layout(constant_id = 2) const bool kExactFp64Bits = true;

const uint64_t kFraction = (uint64_t(1) << 52) - uint64_t(1);  // a double's 52 fraction bits
const uint64_t kHidden = uint64_t(1) << 52;                    // its leading 1

// A guess at a result in the binade [2^e, 2^(e+1)) as the integer A ∈ [2^52, 2^53] with the
// result A·2^(e−52), read from its bits (a guess a few ulps off may lie in a neighbouring binade:
// clamped to its ends, from which the correction moves it).
uint64_t gridOf(double guess, int e) {
  const uint64_t bits = doubleBitsToUint64(guess);
  const int exponent = int(bits >> 52) - 1023;
  return exponent > e ? kHidden << 1 : exponent < e ? kHidden : (bits & kFraction) | kHidden;
}

// A·2^(e−52) for A ∈ [2^52, 2^53] and a normal result: its bits (A = 2^53 carries into the
// exponent, which is the next binade's 1).
double fromGrid(uint64_t a, int e) { return uint64BitsToDouble((uint64_t(e + 1023) << 52) + (a - kHidden)); }

// sqrtRnScaled and recipRnScaled with the scaling done on the bits (with kExactFp64Bits): frexp,
// ldexp and the conversions between double and uint64 were half of the Mandelbulb's escape counts
// on an H200 (865 ms against 441 ms with the built-in sqrt and division, which gave the same counts
// there; the bit-level form takes 655 ms).
double sqrtRn(double x) {
  const uint64_t bits = doubleBitsToUint64(x);
  const int biased = int(bits >> 52);
  if (!kExactFp64Bits || x == 0.0lf || isinf(x) || biased == 0) return sqrtRnScaled(x);  // ±0, ∞, subnormal
  const int u = biased - 1023;  // x = M·2^(u−52), M ∈ [2^52, 2^53)
  const int k = u >> 1;         // ⌊u/2⌋ (arithmetic shift): √x ∈ [2^k, 2^(k+1))
  // N mod 2^64, N = g·2^104 with g = x·2^-2k ∈ [1, 4): g·2^52 = M·2^(u − 2k).
  const uint64_t n_low = ((bits & kFraction) | kHidden) << (52 + (u & 1));
  return fromGrid(nearestSqrt(n_low, gridOf(EXACT_FP64_GUESS(sqrt(x)), k)), k);
}

double recipRn(double y) {
  const uint64_t bits = doubleBitsToUint64(y);
  const int biased = int(bits >> 52);
  if (!kExactFp64Bits || biased == 0 || biased >= 2045) return recipRnScaled(y);  // a subnormal y, or 1/y not normal
  const int u = biased - 1023;  // y = m·2^u, m ∈ [1, 2)
  const uint64_t y_int = (bits & kFraction) | kHidden;  // Y = m·2^52
  if (y_int == kHidden) return uint64BitsToDouble(uint64_t(1023 - u) << 52);  // 2^−u exactly
  // 1/y = (1/m)·2^−u ∈ [2^(−u−1), 2^−u): A = round(2^105 / Y) on that binade's grid.
  return fromGrid(nearestRecip(y_int, gridOf(EXACT_FP64_GUESS(1.0lf / y), -u - 1)), -u - 1);
}
