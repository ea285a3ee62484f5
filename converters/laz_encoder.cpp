// LASzip's arithmetic encoder's end and its integer compressor (converters/laz_encoder.h says what
// and whence). The hot paths are inline in the header.
#include "converters/laz_encoder.h"

#include <cassert>

namespace dpoint {

void LazEncoder::done() {
  const uint32_t before = base_;
  bool another_byte = true;
  if (length_ > 2 * kMinLength) {
    base_ += kMinLength;       // a value inside the interval whatever follows: one byte more
    length_ = kMinLength >> 1;
  } else {
    base_ += kMinLength >> 1;  // two bytes more
    length_ = kMinLength >> 9;
    another_byte = false;
  }
  if (before > base_) propagateCarry();
  renormalise();
  // The decoder reads 4 bytes ahead of what it has used: pad so that it ends at the code's end.
  out_.push_back(0);
  out_.push_back(0);
  if (another_byte) out_.push_back(0);
}

void LazIntegerEncoder::encode(LazEncoder& encoder, int32_t prediction, int32_t real, uint32_t context) {
  assert(context < m_.classes.size());
  // real − prediction with the 32-bit wrap of LASzip's int arithmetic, then into the corrector
  // range [corr_min, corr_min + corr_range − 1].
  int32_t c = static_cast<int32_t>(static_cast<uint32_t>(real) - static_cast<uint32_t>(prediction));
  if (m_.corr_range != 0) {
    const int32_t corr_max = static_cast<int32_t>(static_cast<uint32_t>(m_.corr_min) + m_.corr_range - 1);
    if (c < m_.corr_min) c = static_cast<int32_t>(static_cast<uint32_t>(c) + m_.corr_range);
    else if (c > corr_max) c = static_cast<int32_t>(static_cast<uint32_t>(c) - m_.corr_range);
  }
  writeCorrector(encoder, c, m_.classes[context]);
}

void LazIntegerEncoder::writeCorrector(LazEncoder& encoder, int32_t c, LazSymbolModel& classes) {
  // k: the tightest class [−(2^k − 1), 2^k] holding c (k = 32 only for INT32_MIN).
  uint32_t magnitude = c <= 0 ? 0u - static_cast<uint32_t>(c) : static_cast<uint32_t>(c) - 1;
  k_ = 0;
  while (magnitude != 0) {
    magnitude >>= 1;
    ++k_;
  }
  encoder.encodeSymbol(classes, k_);
  if (k_ == 0) {
    encoder.encodeBit(m_.corrector_0, static_cast<uint32_t>(c));  // c is 0 or 1
    return;
  }
  if (k_ >= 32) return;
  // Into [0, 2^k): the negative half up by 2^k − 1, the positive half down by 1.
  const uint32_t shifted = c < 0 ? static_cast<uint32_t>(c) + ((1u << k_) - 1) : static_cast<uint32_t>(c) - 1;
  if (k_ <= m_.bits_high) {
    encoder.encodeSymbol(m_.corrector(k_), shifted);
  } else {
    const uint32_t low_bits = k_ - m_.bits_high;
    encoder.encodeSymbol(m_.corrector(k_), shifted >> low_bits);
    encoder.writeBits(low_bits, shifted & ((1u << low_bits) - 1));
  }
}

}  // namespace dpoint
