// The entropy coder of LASzip, decoding side (the encoding side, laz_encoder.h, shares the models): an arithmetic decoder over a byte range, its
// adaptive models and the integer decompressor that LAZ's item decoders (laz_decode.h) and its
// chunk table are built on. Written from LASzip's sources (arithmeticdecoder, arithmeticmodel,
// integercompressor; Apache 2.0) and laz-perf's (decoder.hpp, model.hpp, decompressor.hpp), which
// adapt Amir Said's FastAC ("Introduction to Arithmetic Coding: Theory and Practice", HP Labs
// HPL-2004-76; Said, Lossless Compression Handbook ch. 5, 2003). The bytes must decode exactly as
// LASzip's do, so every constant below is LASzip's:
//
// - The interval is 32 bits: `length` starts at 2^32 − 1 and is renormalised by whole bytes,
//   (value, length) shifted left 8 bits at a time, whenever it drops below 2^24. `value` is the
//   code's offset inside the interval; it starts as the first 4 bytes, big-endian.
// - A bit model keeps a probability of 0 in 13 bits; the interval's length is shifted right 13
//   before the product. Its counts are halved past 2^13, and it is re-estimated every 4, 5, 6, ...
//   bits (the cycle grows by 5/4 up to 64).
// - A symbol model (2 to 2^11 symbols) keeps a cumulative distribution in 15 bits (the length is
//   shifted right 15); counts are halved past 2^15 and the distribution rebuilt every
//   (n + 6) / 2 symbols at first, the cycle growing by 5/4 up to (n + 6) · 8. Models of more than
//   16 symbols carry a lookup table of 2^b entries (b the least ≥ 3 with n ≤ 2^(b+2)) from the top
//   bits of value / length to a first guess, finished by bisection.
// - Raw bits (readBits) split the interval into 2^bits equal parts; more than 19 are read as 16
//   low bits, then the rest.
// - The integer decompressor codes a value as prediction + corrector. The corrector's magnitude
//   class k (0..corr_bits: c in [−(2^k − 1), −2^(k−1)] ∪ [2^(k−1) + 1, 2^k]) is a symbol of a
//   per-context model; k = 0 is one bit (c = 0 or 1); k ≤ bits_high (8) is one symbol of a model
//   of 2^k symbols; a larger k is its top bits_high bits as a symbol, then k − bits_high raw bits.
//   The sum wraps into the corrector range (2^bits, or `range` when given).
//
// Safety: the decoder reads only inside the byte range it was given. Past its end it reads zeros
// and counts the overrun; a code no encoder writes (a first word of 0xFFFFFFFF, raw bits out of
// range) marks it invalid. Either way it keeps value < length, the invariant that keeps every
// table index in bounds, so a caller may decode on and check ok() once per point.
#pragma once

#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace dpoint {

// LASzip's adaptive model of one bit.
class LazBitModel {
 public:
  LazBitModel() { reset(); }
  void reset();  // equiprobable, frequent updates: the state at a chunk's start

 private:
  friend class LazDecoder;
  friend class LazEncoder;
  void update();
  uint32_t bit_0_count_ = 1, bit_count_ = 2, bit_0_prob_ = 0;
  uint32_t update_cycle_ = 4, bits_until_update_ = 4;
};

// LASzip's adaptive model of `symbols` symbols (2..2048; an assert).
class LazSymbolModel {
 public:
  explicit LazSymbolModel(uint32_t symbols);
  // Movable (the storage moves with its pointers), not copyable.
  LazSymbolModel(LazSymbolModel&&) noexcept = default;
  LazSymbolModel& operator=(LazSymbolModel&&) noexcept = default;
  LazSymbolModel(const LazSymbolModel&) = delete;
  LazSymbolModel& operator=(const LazSymbolModel&) = delete;
  void reset();  // every count 1: the state at a chunk's start
  uint32_t symbols() const { return symbols_; }

 private:
  friend class LazDecoder;
  friend class LazEncoder;
  void update();
  uint32_t symbols_ = 0, last_symbol_ = 0;
  uint32_t total_count_ = 0, update_cycle_ = 0, symbols_until_update_ = 0;
  uint32_t table_bits_ = 0, table_shift_ = 0;  // table_bits_ 0: no lookup table
  // distribution (symbols), then counts (symbols), then the lookup table (2^table_bits + 2).
  std::vector<uint32_t> storage_;
  uint32_t* distribution_ = nullptr;
  uint32_t* counts_ = nullptr;
  uint32_t* table_ = nullptr;
};

// The arithmetic decoder over bytes [data, data + size). Not copyable (the models are separate).
class LazDecoder {
 public:
  // Reads the first 4 bytes (LASzip's init).
  LazDecoder(const uint8_t* data, size_t size);
  LazDecoder(const LazDecoder&) = delete;
  LazDecoder& operator=(const LazDecoder&) = delete;

  uint32_t decodeBit(LazBitModel& m) {
    const uint32_t x = m.bit_0_prob_ * (length_ >> kBitLengthShift);
    const uint32_t bit = value_ >= x ? 1 : 0;
    if (bit == 0) {
      length_ = x;
      ++m.bit_0_count_;
    } else {
      value_ -= x;
      length_ -= x;
    }
    if (length_ < kMinLength) renormalise();
    if (--m.bits_until_update_ == 0) m.update();
    return bit;
  }

  uint32_t decodeSymbol(LazSymbolModel& m) {
    uint32_t symbol, x, y = length_;
    if (m.table_bits_ != 0) {
      length_ >>= kSymbolLengthShift;
      const uint32_t dv = value_ / length_;
      const uint32_t t = dv >> m.table_shift_;
      // value < length (before the shift) bounds dv below 2^15 + 2^15 / (length >> 15) ≤ 2^15 + 63,
      // so t ≤ the table size: the table's last two entries are there for this.
      assert(t <= (1u << m.table_bits_));
      symbol = m.table_[t];
      uint32_t n = m.table_[t + 1] + 1;
      while (n > symbol + 1) {  // bisection inside the table's bracket
        const uint32_t k = (symbol + n) >> 1;
        if (m.distribution_[k] > dv) n = k; else symbol = k;
      }
      x = m.distribution_[symbol] * length_;
      if (symbol != m.last_symbol_) y = m.distribution_[symbol + 1] * length_;
    } else {
      x = symbol = 0;
      length_ >>= kSymbolLengthShift;
      uint32_t n = m.symbols_;
      uint32_t k = n >> 1;
      do {
        const uint32_t z = length_ * m.distribution_[k];
        if (z > value_) {
          n = k;
          y = z;
        } else {
          symbol = k;
          x = z;
        }
      } while ((k = (symbol + n) >> 1) != symbol);
    }
    value_ -= x;
    length_ = y - x;
    if (length_ < kMinLength) renormalise();
    ++m.counts_[symbol];
    if (--m.symbols_until_update_ == 0) m.update();
    return symbol;
  }

  // `bits` raw bits, 1..32.
  uint32_t readBits(uint32_t bits) {
    assert(bits >= 1 && bits <= 32);
    if (bits > 19) {
      const uint32_t low = readBits(16);
      return (readBits(bits - 16) << 16) | low;
    }
    length_ >>= bits;
    const uint32_t v = value_ / length_;
    value_ -= length_ * v;  // value < length still holds, whatever v is
    if (length_ < kMinLength) renormalise();
    if (v >> bits) {  // no encoder writes this
      invalid_ = true;
      return v & ((1u << bits) - 1);
    }
    return v;
  }
  uint32_t readInt() { return readBits(32); }  // two 16-bit halves, low first, as LASzip's readInt

  // False once the decoder has read past its bytes or met an invalid code.
  bool ok() const { return overrun_ == 0 && !invalid_; }
  bool invalid() const { return invalid_; }
  size_t overrun() const { return overrun_; }  // bytes wanted past the end (read as zeros)
  size_t consumed() const { return static_cast<size_t>(next_ - begin_); }  // bytes read so far

 private:
  static constexpr uint32_t kMinLength = 1u << 24;
  static constexpr uint32_t kBitLengthShift = 13;
  static constexpr uint32_t kSymbolLengthShift = 15;

  uint32_t nextByte() {
    if (next_ < end_) return *next_++;
    ++overrun_;
    return 0;
  }
  void renormalise() {
    do {
      value_ = (value_ << 8) | nextByte();
    } while ((length_ <<= 8) < kMinLength);
  }

  const uint8_t* begin_;
  const uint8_t* next_;
  const uint8_t* end_;
  uint32_t value_ = 0, length_ = 0xFFFFFFFFu;
  size_t overrun_ = 0;
  bool invalid_ = false;
};

// Models keyed by a previous value, created when first needed, as LASzip creates them: most files
// use a few of the keys. A new model starts in its reset state, so when it is created does not
// change the code.
template <size_t N>
class LazKeyedModels {
 public:
  explicit LazKeyedModels(uint32_t symbols) : symbols_(symbols) {}
  LazSymbolModel& operator[](size_t key) {
    assert(key < N);
    if (!models_[key]) models_[key] = std::make_unique<LazSymbolModel>(symbols_);
    return *models_[key];
  }

 private:
  uint32_t symbols_;
  std::array<std::unique_ptr<LazSymbolModel>, N> models_;
};

// The models of LASzip's IntegerCompressor, which its compressor (laz_encoder.h) and decompressor
// share: values of `bits` bits (1..32) predicted in one of `contexts` contexts, the corrector in the
// given `range` (0: 2^bits), large classes split at `bits_high` bits.
struct LazIntegerModels {
  LazIntegerModels(uint32_t bits, uint32_t contexts, uint32_t bits_high, uint32_t range);
  void reset();  // every model to its start state
  // The model of class k's corrector (k = 1..corr_bits), made when the class first occurs: a
  // fresh model is the same whenever it is made, and a chunk uses few of the 32 classes (building
  // all of them was most of a small chunk's time: COPC nodes, fuzzing).
  LazSymbolModel& corrector(uint32_t k);

  uint32_t bits_high = 8;
  uint32_t corr_bits = 0;
  uint32_t corr_range = 0;  // 0: the whole 32 bits, no wrapping needed
  int32_t corr_min = 0;
  std::vector<LazSymbolModel> classes;  // one per context: k, 0..corr_bits
  LazBitModel corrector_0;              // k = 0
  std::vector<std::unique_ptr<LazSymbolModel>> correctors;  // k = 1..corr_bits, at k − 1
};

// LASzip's IntegerCompressor, decompressing (the arguments are LazIntegerModels').
class LazIntegerDecoder {
 public:
  explicit LazIntegerDecoder(uint32_t bits = 16, uint32_t contexts = 1, uint32_t bits_high = 8, uint32_t range = 0)
      : m_(bits, contexts, bits_high, range) {}
  void reset() { m_.reset(); }

  // The value coded after `prediction` in `context` (< contexts; an assert).
  int32_t decode(LazDecoder& decoder, int32_t prediction, uint32_t context = 0);
  // The magnitude class of the last corrector decoded (LASzip's getK): the point decoder uses it
  // as a context.
  uint32_t k() const { return k_; }

 private:
  uint32_t readCorrector(LazDecoder& decoder, LazSymbolModel& classes);

  LazIntegerModels m_;
  uint32_t k_ = 0;
};

}  // namespace dpoint
