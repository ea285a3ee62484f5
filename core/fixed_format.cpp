// The fast path computes round(v · 10^d) exactly in 128-bit integers. A finite double is
// m · 2^e with m < 2^53, so v · 10^d = m · 5^d · 2^(e+d). For d ≤ 27, m · 5^d < 2^116; a right
// shift by -(e+d) with round-half-even on the dropped bits gives the correctly rounded integer,
// and a left shift is exact while the result stays below 2^128. Everything else (huge values,
// many decimals) goes to std::to_chars, whose fixed form the standard defines as printf's.
#include "core/fixed_format.h"

#include <cassert>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace dpoint {
namespace {

using u128 = unsigned __int128;

constexpr int kMaxFastDecimals = 27;

template <typename T, int N>
struct PowerTable {
  T values[N];
  constexpr PowerTable(T base) : values() {
    values[0] = 1;
    for (int i = 1; i < N; ++i) values[i] = values[i - 1] * base;
  }
};
constexpr PowerTable<uint64_t, kMaxFastDecimals + 1> kPow5(5);   // 5^27 < 2^63
constexpr PowerTable<uint64_t, 20> kPow10(10);                   // 10^19 < 2^64
constexpr PowerTable<u128, kMaxFastDecimals + 1> kPow10Wide(10);

constexpr char kDigitPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

// Writes exactly `width` digits of y (y < 10^width), with leading zeros, two at a time.
void writeDigits(char* p, uint64_t y, int width) {
  int i = width;
  while (i >= 2) {
    const uint64_t pair = y % 100;
    y /= 100;
    i -= 2;
    std::memcpy(p + i, kDigitPairs + 2 * pair, 2);
  }
  if (i == 1) p[0] = static_cast<char>('0' + y);
}

int digitCount(uint64_t y) {
  int n = 1;
  while (n < 20 && y >= kPow10.values[n]) ++n;
  return n;
}

// Decimal digits of x without leading zeros (a single 0 for zero).
char* writeUnsigned(char* p, u128 x) {
  if (x <= UINT64_MAX) {
    const int n = digitCount(static_cast<uint64_t>(x));
    writeDigits(p, static_cast<uint64_t>(x), n);
    return p + n;
  }
  char digits[40];
  int n = 0;
  while (x != 0) {
    digits[n++] = static_cast<char>('0' + static_cast<int>(x % 10));
    x /= 10;
  }
  while (n > 0) *p++ = digits[--n];
  return p;
}

// Exactly `width` digits of x (x < 10^width), with leading zeros.
char* writePadded(char* p, u128 x, int width) {
  if (x <= UINT64_MAX && width <= 20) {
    writeDigits(p, static_cast<uint64_t>(x), width);
    return p + width;
  }
  for (int i = width - 1; i >= 0; --i) {
    p[i] = static_cast<char>('0' + static_cast<int>(x % 10));
    x /= 10;
  }
  return p + width;
}

}  // namespace

char* formatFixed(char* p, double v, int decimals) {
  assert(std::isfinite(v) && decimals >= 0 && decimals <= 100);
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  const bool negative = bits >> 63;
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  uint64_t m = bits & ((uint64_t{1} << 52) - 1);
  int e = biased == 0 ? -1074 : biased - 1075;
  if (biased != 0) m |= uint64_t{1} << 52;

  const int shift = e + decimals;  // v · 10^d = m · 5^d · 2^shift
  if (decimals > kMaxFastDecimals || (m != 0 && shift > 0 && 64 - __builtin_clzll(m) + 2 * decimals + 12 + shift > 127)) {
    // 2·d + 12 bounds the bit length of 5^d (log2 5 < 2.33 → 5^d < 2^(2.33·d) ≤ 2^(2d + 0.33·27)).
    std::to_chars_result r = std::to_chars(p, p + fixedFormatMaxChars(decimals), v, std::chars_format::fixed, decimals);
    assert(r.ec == std::errc());
    return r.ptr;
  }
  u128 n = static_cast<u128>(m) * kPow5.values[decimals];
  if (shift >= 0) {
    n <<= shift;
  } else if (-shift >= 127) {
    n = 0;  // n < 2^116 < half of 2^127: rounds to zero
  } else {
    const int s = -shift;
    const u128 rest = n & ((u128{1} << s) - 1);
    const u128 half = u128{1} << (s - 1);
    n >>= s;
    if (rest > half || (rest == half && (n & 1))) ++n;
  }
  if (negative) *p++ = '-';
  u128 integer, fraction;
  if (n <= UINT64_MAX && decimals <= 19) {  // 64-bit division: the common case, much cheaper
    const uint64_t scale = kPow10.values[decimals];
    integer = static_cast<uint64_t>(n) / scale;
    fraction = static_cast<uint64_t>(n) % scale;
  } else {
    const u128 scale = kPow10Wide.values[decimals];
    integer = n / scale;
    fraction = n % scale;
  }
  p = writeUnsigned(p, integer);
  if (decimals > 0) {
    *p++ = '.';
    p = writePadded(p, fraction, decimals);
  }
  return p;
}

}  // namespace dpoint
