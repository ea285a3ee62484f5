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

double sqrtRn(double x) {
  if (x == 0.0lf || isinf(x)) return x;  // √±0 = ±0, √∞ = ∞
  int e;
  precise double f = frexp(x, e);  // x = f·2^e, f ∈ [0.5, 1)
  const int k = (e - 1) >> 1;      // ⌊(e − 1)/2⌋ (arithmetic shift)
  precise double g = ldexp(x, -2 * k);  // x·2^-2k ∈ [1, 4), exact
  const uint64_t n_low = uint64_t(g * kTwo52) << 52;  // N mod 2^64, N = g·2^104
  precise double guess = clamp(EXACT_FP64_GUESS(sqrt(g)), 1.0lf, 2.0lf);
  uint64_t a = uint64_t(guess * kTwo52);  // an integer: the guess lies on the 2^-52 grid of [1, 2]
  for (int step = 0; step < 64; ++step) {
    const int64_t residual = int64_t(n_low - a * a);  // N − A², exact while |N − A²| < 2^63
    if (residual > int64_t(a)) a += 1;                 // N > A² + A: above A + 1/2
    else if (residual <= -int64_t(a)) a -= 1;          // N ≤ A² − A: below A − 1/2
    else break;
  }
  return ldexp(double(a), k - 52);  // a ≤ 2^53: exact, and the scaling is exact
}

double recipRn(double y) {
  int e;
  precise double f = frexp(y, e);  // y = f·2^e, f ∈ [0.5, 1)
  precise double m = 2.0lf * f;    // y = m·2^(e−1), m ∈ [1, 2), 1/y = (1/m)·2^(1−e)
  if (m == 1.0lf) return ldexp(1.0lf, 1 - e);
  const uint64_t y_int = uint64_t(m * kTwo52);  // Y ∈ (2^52, 2^53)
  precise double guess = clamp(EXACT_FP64_GUESS(1.0lf / m), 0.5lf, 1.0lf);
  uint64_t a = uint64_t(guess * kTwo53);  // 1/m ∈ (1/2, 1): the 2^-53 grid
  for (int step = 0; step < 64; ++step) {
    const int64_t residual = int64_t(a * y_int);  // A·Y − 2^105 modulo 2^64
    if (2 * residual > int64_t(y_int)) a -= 1;
    else if (2 * residual < -int64_t(y_int)) a += 1;
    else break;
  }
  return ldexp(double(a), -52 - e);  // A·2^-53·2^(1−e)
}
