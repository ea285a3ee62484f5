// The entropy coder of LASzip, encoding side: the arithmetic encoder and the integer compressor
// whose output LazDecoder and LazIntegerDecoder (laz_codec.h, which says whence and the constants)
// read back. Written from LASzip's arithmeticencoder and integercompressor (Apache 2.0) and Said's
// FastAC, on the same adaptive models as the decoder: the encoder updates a model exactly as the
// decoder does, so both see the same distributions symbol by symbol.
//
// - The interval is [base, base + length) of 32 bits; a symbol narrows it, a carry out of base
//   ripples back through the bytes already written (0xFF bytes turn to 0, the one before them
//   grows by one), and whenever length drops below 2^24 the top byte of base is written.
// - done() ends the code as LASzip's encoder does: it moves base into the interval by 2^24 (one
//   byte more) or 2^23 (two more), writes those bytes, then two or three zero bytes so that the
//   decoder's 4-byte look-ahead ends exactly at the code's end. LAZ relies on that: a chunk's
//   bytes are exactly what its points need.
#pragma once

#include <cstdint>
#include <vector>

#include "converters/laz_codec.h"

namespace dpoint {

// The arithmetic encoder. Appends to its own byte vector; done() finishes the code.
class LazEncoder {
 public:
  LazEncoder() { out_.reserve(1 << 12); }
  LazEncoder(const LazEncoder&) = delete;
  LazEncoder& operator=(const LazEncoder&) = delete;

  void encodeBit(LazBitModel& m, uint32_t bit) {
    const uint32_t x = m.bit_0_prob_ * (length_ >> kBitLengthShift);
    if (bit == 0) {
      length_ = x;
      ++m.bit_0_count_;
    } else {
      const uint32_t before = base_;
      base_ += x;
      length_ -= x;
      if (before > base_) propagateCarry();
    }
    if (length_ < kMinLength) renormalise();
    if (--m.bits_until_update_ == 0) m.update();
  }

  void encodeSymbol(LazSymbolModel& m, uint32_t symbol) {
    const uint32_t before = base_;
    if (symbol == m.last_symbol_) {
      const uint32_t x = m.distribution_[symbol] * (length_ >> kSymbolLengthShift);
      base_ += x;
      length_ -= x;
    } else {
      length_ >>= kSymbolLengthShift;
      const uint32_t x = m.distribution_[symbol] * length_;
      base_ += x;
      length_ = m.distribution_[symbol + 1] * length_ - x;
    }
    if (before > base_) propagateCarry();
    if (length_ < kMinLength) renormalise();
    ++m.counts_[symbol];
    if (--m.symbols_until_update_ == 0) m.update();
  }

  // `value` (< 2^bits) as `bits` raw bits, 1..32; more than 19 as 16 low bits, then the rest.
  void writeBits(uint32_t bits, uint32_t value) {
    if (bits > 19) {
      writeBits(16, value & 0xFFFFu);
      value >>= 16;
      bits -= 16;
    }
    const uint32_t before = base_;
    base_ += value * (length_ >>= bits);
    if (before > base_) propagateCarry();
    if (length_ < kMinLength) renormalise();
  }
  void writeInt(uint32_t value) { writeBits(32, value); }

  // Ends the code; the encoder is not used afterwards.
  void done();
  const std::vector<uint8_t>& bytes() const { return out_; }
  std::vector<uint8_t>& bytes() { return out_; }

 private:
  static constexpr uint32_t kMinLength = 1u << 24;
  static constexpr uint32_t kBitLengthShift = 13;
  static constexpr uint32_t kSymbolLengthShift = 15;

  void propagateCarry() {
    size_t i = out_.size();
    while (i > 0 && out_[i - 1] == 0xFF) out_[--i] = 0;
    if (i > 0) ++out_[i - 1];
  }
  void renormalise() {
    do {
      out_.push_back(static_cast<uint8_t>(base_ >> 24));
      base_ <<= 8;
    } while ((length_ <<= 8) < kMinLength);
  }

  uint32_t base_ = 0, length_ = 0xFFFFFFFFu;
  std::vector<uint8_t> out_;
};

// LASzip's IntegerCompressor, compressing: the arguments are LazIntegerDecoder's, the models
// (LazIntegerModels) the same.
class LazIntegerEncoder {
 public:
  explicit LazIntegerEncoder(uint32_t bits = 16, uint32_t contexts = 1, uint32_t bits_high = 8, uint32_t range = 0)
      : m_(bits, contexts, bits_high, range) {}
  void reset() { m_.reset(); }

  // Codes `real` after `prediction` in `context`.
  void encode(LazEncoder& encoder, int32_t prediction, int32_t real, uint32_t context = 0);
  // The magnitude class of the last corrector (LASzip's getK), as the decoder's k().
  uint32_t k() const { return k_; }

 private:
  void writeCorrector(LazEncoder& encoder, int32_t c, LazSymbolModel& classes);

  LazIntegerModels m_;
  uint32_t k_ = 0;
};

}  // namespace dpoint
