// LASzip's adaptive models and integer decompressor (converters/laz_codec.h says what and whence).
// The hot paths (decodeBit, decodeSymbol, readBits) are inline in the header; here are the model
// re-estimation, which runs every few dozen symbols, and the corrector decoding.
#include "converters/laz_codec.h"

namespace dpoint {

namespace {

constexpr uint32_t kBitLengthShift = 13;
constexpr uint32_t kBitMaxCount = 1u << kBitLengthShift;
constexpr uint32_t kSymbolLengthShift = 15;
constexpr uint32_t kSymbolMaxCount = 1u << kSymbolLengthShift;
[[maybe_unused]] constexpr uint32_t kMaxSymbols = 1u << 11;  // checked by assert only
// Models up to this many symbols are decoded by bisection alone (FastAC's choice).
constexpr uint32_t kNoTableSymbols = 16;

}  // namespace

// --- Bit model -------------------------------------------------------------------------------------

void LazBitModel::reset() {
  bit_0_count_ = 1;
  bit_count_ = 2;
  bit_0_prob_ = 1u << (kBitLengthShift - 1);
  update_cycle_ = bits_until_update_ = 4;
}

void LazBitModel::update() {
  if ((bit_count_ += update_cycle_) > kBitMaxCount) {
    bit_count_ = (bit_count_ + 1) >> 1;
    bit_0_count_ = (bit_0_count_ + 1) >> 1;
    if (bit_0_count_ == bit_count_) ++bit_count_;  // keep a 1 possible
  }
  // p0 = bit_0_count / bit_count in 13 bits, through a 31-bit reciprocal as FastAC computes it
  // (the exact rounding matters: the encoder used the same).
  const uint32_t scale = 0x80000000u / bit_count_;
  bit_0_prob_ = (bit_0_count_ * scale) >> (31 - kBitLengthShift);
  update_cycle_ = (5 * update_cycle_) >> 2;
  if (update_cycle_ > 64) update_cycle_ = 64;
  bits_until_update_ = update_cycle_;
}

// --- Symbol model ----------------------------------------------------------------------------------

LazSymbolModel::LazSymbolModel(uint32_t symbols) : symbols_(symbols), last_symbol_(symbols - 1) {
  assert(symbols >= 2 && symbols <= kMaxSymbols);
  if (symbols > kNoTableSymbols) {
    uint32_t bits = 3;
    while (symbols > (1u << (bits + 2))) ++bits;
    table_bits_ = bits;
    table_shift_ = kSymbolLengthShift - bits;
  }
  const size_t table_entries = table_bits_ != 0 ? (size_t{1} << table_bits_) + 2 : 0;
  storage_.assign(2 * size_t{symbols} + table_entries, 0);
  distribution_ = storage_.data();
  counts_ = distribution_ + symbols;
  table_ = table_bits_ != 0 ? counts_ + symbols : nullptr;
  reset();
}

void LazSymbolModel::reset() {
  total_count_ = 0;
  update_cycle_ = symbols_;
  for (uint32_t k = 0; k < symbols_; ++k) counts_[k] = 1;
  update();
  symbols_until_update_ = update_cycle_ = (symbols_ + 6) >> 1;
}

void LazSymbolModel::update() {
  if ((total_count_ += update_cycle_) > kSymbolMaxCount) {
    total_count_ = 0;
    for (uint32_t n = 0; n < symbols_; ++n) total_count_ += (counts_[n] = (counts_[n] + 1) >> 1);
  }
  // The cumulative distribution in 15 bits, through a 31-bit reciprocal (FastAC's rounding).
  const uint32_t scale = 0x80000000u / total_count_;
  uint32_t sum = 0;
  if (table_bits_ == 0) {
    for (uint32_t k = 0; k < symbols_; ++k) {
      distribution_[k] = (scale * sum) >> (31 - kSymbolLengthShift);
      sum += counts_[k];
    }
  } else {
    // table[t]: the last symbol whose distribution value is below t << table_shift, so a decoded
    // dv in [t, t + 1) << table_shift lies between symbols table[t] and table[t + 1].
    const uint32_t table_size = 1u << table_bits_;
    uint32_t s = 0;
    for (uint32_t k = 0; k < symbols_; ++k) {
      distribution_[k] = (scale * sum) >> (31 - kSymbolLengthShift);
      sum += counts_[k];
      const uint32_t w = distribution_[k] >> table_shift_;
      while (s < w) table_[++s] = k - 1;
    }
    table_[0] = 0;
    while (s <= table_size) table_[++s] = symbols_ - 1;
  }
  update_cycle_ = (5 * update_cycle_) >> 2;
  const uint32_t max_cycle = (symbols_ + 6) << 3;
  if (update_cycle_ > max_cycle) update_cycle_ = max_cycle;
  symbols_until_update_ = update_cycle_;
}

// --- Decoder ---------------------------------------------------------------------------------------

LazDecoder::LazDecoder(const uint8_t* data, size_t size) : begin_(data), next_(data), end_(data + size) {
  for (int i = 0; i < 4; ++i) value_ = (value_ << 8) | nextByte();
  // The code lies inside the encoder's first interval [0, 2^32 − 1): a first word of all ones is
  // no encoder's output, and would break value < length.
  if (value_ == 0xFFFFFFFFu) {
    invalid_ = true;
    value_ = 0;
  }
}

// --- Integer decoder -------------------------------------------------------------------------------

LazIntegerModels::LazIntegerModels(uint32_t bits, uint32_t contexts, uint32_t split_bits, uint32_t range)
    : bits_high(split_bits) {
  assert(bits >= 1 && bits <= 32 && contexts >= 1 && bits_high >= 1 && bits_high <= 11);
  if (range != 0) {
    // The fewest bits that hold range − 1 (a power of two needs one bit less than its own width).
    corr_bits = 0;
    for (uint32_t r = range; r != 0; r >>= 1) ++corr_bits;
    if (range == (1u << (corr_bits - 1))) --corr_bits;
    corr_range = range;
  } else if (bits < 32) {
    corr_bits = bits;
    corr_range = 1u << bits;
  } else {
    corr_bits = 32;
    corr_range = 0;
  }
  corr_min = corr_range != 0 ? -static_cast<int32_t>(corr_range / 2) : INT32_MIN;
  classes.reserve(contexts);
  for (uint32_t c = 0; c < contexts; ++c) classes.emplace_back(corr_bits + 1);
  correctors.resize(corr_bits);
}

void LazIntegerModels::reset() {
  for (LazSymbolModel& m : classes) m.reset();
  corrector_0.reset();
  for (std::unique_ptr<LazSymbolModel>& m : correctors)
    if (m) m->reset();
}

LazSymbolModel& LazIntegerModels::corrector(uint32_t k) {
  std::unique_ptr<LazSymbolModel>& m = correctors[k - 1];
  if (!m) m = std::make_unique<LazSymbolModel>(1u << (k <= bits_high ? k : bits_high));
  return *m;
}

int32_t LazIntegerDecoder::decode(LazDecoder& decoder, int32_t prediction, uint32_t context) {
  assert(context < m_.classes.size());
  // All in unsigned arithmetic: the sum wraps as LASzip's int32 sum does on every compiler it
  // supports, without the undefined behaviour of a signed overflow.
  uint32_t real = static_cast<uint32_t>(prediction) + readCorrector(decoder, m_.classes[context]);
  if (m_.corr_range != 0) {
    if (static_cast<int32_t>(real) < 0) real += m_.corr_range;
    else if (real >= m_.corr_range) real -= m_.corr_range;
  }
  return static_cast<int32_t>(real);
}

// The corrector as a 32-bit two's-complement pattern.
uint32_t LazIntegerDecoder::readCorrector(LazDecoder& decoder, LazSymbolModel& classes) {
  k_ = decoder.decodeSymbol(classes);
  if (k_ == 0) return decoder.decodeBit(m_.corrector_0);  // c is 0 or 1
  if (k_ >= 32) return static_cast<uint32_t>(m_.corr_min);
  uint32_t c;
  if (k_ <= m_.bits_high) {
    c = decoder.decodeSymbol(m_.corrector(k_));
  } else {
    const uint32_t low_bits = k_ - m_.bits_high;
    c = decoder.decodeSymbol(m_.corrector(k_)) << low_bits;
    c |= decoder.readBits(low_bits);
  }
  // c in [0, 2^k) back to the class's two halves: [2^(k−1), 2^k) is c + 1 in [2^(k−1) + 1, 2^k],
  // [0, 2^(k−1)) is c − (2^k − 1) in [−(2^k − 1), −2^(k−1)].
  if (c >= (1u << (k_ - 1))) return c + 1;
  return c - ((1u << k_) - 1);
}

}  // namespace dpoint
