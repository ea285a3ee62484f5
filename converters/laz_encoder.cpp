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

LazIntegerEncoder::LazIntegerEncoder(uint32_t bits, uint32_t contexts, uint32_t bits_high, uint32_t range)
    : bits_high_(bits_high) {
  assert(bits >= 1 && bits <= 32 && contexts >= 1 && bits_high >= 1 && bits_high <= 11);
  // The same classes as LazIntegerDecoder's constructor.
  if (range != 0) {
    corr_bits_ = 0;
    for (uint32_t r = range; r != 0; r >>= 1) ++corr_bits_;
    if (range == (1u << (corr_bits_ - 1))) --corr_bits_;
    corr_range_ = range;
  } else if (bits < 32) {
    corr_bits_ = bits;
    corr_range_ = 1u << bits;
  } else {
    corr_bits_ = 32;
    corr_range_ = 0;
  }
  if (corr_range_ != 0) {
    corr_min_ = -static_cast<int32_t>(corr_range_ / 2);
    corr_max_ = static_cast<int32_t>(static_cast<uint32_t>(corr_min_) + corr_range_ - 1);
  } else {
    corr_min_ = INT32_MIN;
    corr_max_ = INT32_MAX;
  }
  classes_.reserve(contexts);
  for (uint32_t c = 0; c < contexts; ++c) classes_.emplace_back(corr_bits_ + 1);
  correctors_.resize(corr_bits_);
}

void LazIntegerEncoder::reset() {
  for (LazSymbolModel& m : classes_) m.reset();
  corrector_0_.reset();
  for (std::unique_ptr<LazSymbolModel>& m : correctors_)
    if (m) m->reset();
}

LazSymbolModel& LazIntegerEncoder::corrector(uint32_t k) {
  std::unique_ptr<LazSymbolModel>& m = correctors_[k - 1];
  if (!m) m = std::make_unique<LazSymbolModel>(1u << (k <= bits_high_ ? k : bits_high_));
  return *m;
}

void LazIntegerEncoder::encode(LazEncoder& encoder, int32_t prediction, int32_t real, uint32_t context) {
  assert(context < classes_.size());
  // real − prediction with the 32-bit wrap of LASzip's int arithmetic, then into the corrector range.
  int32_t c = static_cast<int32_t>(static_cast<uint32_t>(real) - static_cast<uint32_t>(prediction));
  if (corr_range_ != 0) {
    if (c < corr_min_) c = static_cast<int32_t>(static_cast<uint32_t>(c) + corr_range_);
    else if (c > corr_max_) c = static_cast<int32_t>(static_cast<uint32_t>(c) - corr_range_);
  }
  writeCorrector(encoder, c, classes_[context]);
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
    encoder.encodeBit(corrector_0_, static_cast<uint32_t>(c));  // c is 0 or 1
    return;
  }
  if (k_ >= 32) return;
  // Into [0, 2^k): the negative half up by 2^k − 1, the positive half down by 1.
  const uint32_t shifted = c < 0 ? static_cast<uint32_t>(c) + ((1u << k_) - 1) : static_cast<uint32_t>(c) - 1;
  if (k_ <= bits_high_) {
    encoder.encodeSymbol(corrector(k_), shifted);
  } else {
    const uint32_t low_bits = k_ - bits_high_;
    encoder.encodeSymbol(corrector(k_), shifted >> low_bits);
    encoder.writeBits(low_bits, shifted & ((1u << low_bits) - 1));
  }
}

}  // namespace dpoint
