// LAZ item version 2: the POINT10, GPSTIME11, RGB12 and BYTE decoders of LASzip 2.0 and later
// (point formats 0–3, compressors 2 and 1), as laz_item_decoder.h drives them. dpoint's own code,
// written from LASzip's lasreaditemcompressed_v2 and laszip_common_v2 (Apache 2.0) and laz-perf's
// detail/field_*.cpp, on the entropy coder of laz_codec.h. Only little-endian hosts, as
// laz_decode.cpp.
#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <memory>
#include <vector>

#include "converters/laz_codec.h"
#include "converters/laz_common.h"
#include "converters/laz_item_decoder.h"
#include "core/bytes.h"

namespace dpoint {

static_assert(std::endian::native == std::endian::little, "LAZ fields are little-endian, copied as they are");

namespace {

// The 20 bytes formats 0–5 share: x, y, z (i32), intensity (u16), the return byte (return number
// bits 0–2, number of returns 3–5, scan direction 6, edge of flight line 7), classification,
// scan angle rank, user data (u8 each), point source ID (u16).
class Point10Decoder final : public LazItemDecoder {
 public:
  explicit Point10Decoder(const uint8_t* first) {
    x_ = loadUnaligned<int32_t>(first);
    y_ = loadUnaligned<int32_t>(first + 4);
    z_ = loadUnaligned<int32_t>(first + 8);
    // intensity_ stays 0: LASzip predicts the second point's intensity from 0, not the first's.
    returns_ = first[14];
    classification_ = first[15];
    scan_angle_ = first[16];
    user_data_ = first[17];
    source_id_ = loadUnaligned<uint16_t>(first + 18);
  }

  void decode(LazDecoder& d, uint8_t* item) override {
    // Bits 5..0: the return byte, intensity, classification, scan angle, user data and point
    // source ID changed.
    const uint32_t changed = d.decodeSymbol(changed_model_);
    if (changed & 32) returns_ = static_cast<uint8_t>(d.decodeSymbol(returns_models_[returns_]));
    const uint32_t r = returns_ & 7u, n = (returns_ >> 3) & 7u;
    const uint32_t m = kLazReturnMap[n][r], l = kLazReturnLevel[n][r];
    // LASzip sets the intensity only when some value changed; when none did, the point's return
    // byte is the last one's, so m is too, and the last intensity is last_intensity_[m] already.
    if (changed & 16) {
      last_intensity_[m] = static_cast<uint16_t>(
          intensity_decoder_.decode(d, last_intensity_[m], m < 3 ? m : 3));
    }
    intensity_ = last_intensity_[m];
    if (changed & 8)
      classification_ = static_cast<uint8_t>(d.decodeSymbol(class_models_[classification_]));
    if (changed & 4) {
      const uint32_t delta = d.decodeSymbol(scan_angle_models_[(returns_ >> 6) & 1u]);
      scan_angle_ = static_cast<uint8_t>(delta + scan_angle_);  // mod 256
    }
    if (changed & 2) user_data_ = static_cast<uint8_t>(d.decodeSymbol(user_models_[user_data_]));
    if (changed & 1) source_id_ = static_cast<uint16_t>(source_id_decoder_.decode(d, source_id_));

    // x and y: the difference from the last point, predicted by the median of its history; y's and
    // z's contexts grow with the magnitude classes (k) of the corrections before them. Sums wrap
    // as the encoder's 32-bit ones did.
    const uint32_t single = n == 1 ? 1 : 0;
    const int32_t dx = dx_decoder_.decode(d, dx_history_[m].get(), single);
    x_ = static_cast<int32_t>(static_cast<uint32_t>(x_) + static_cast<uint32_t>(dx));
    dx_history_[m].add(dx);
    uint32_t k = dx_decoder_.k();
    const int32_t dy = dy_decoder_.decode(d, dy_history_[m].get(), single + (k < 20 ? k & ~1u : 20));
    y_ = static_cast<int32_t>(static_cast<uint32_t>(y_) + static_cast<uint32_t>(dy));
    dy_history_[m].add(dy);
    k = (dx_decoder_.k() + dy_decoder_.k()) / 2;
    z_ = z_decoder_.decode(d, last_height_[l], single + (k < 18 ? k & ~1u : 18));
    last_height_[l] = z_;

    storeUnaligned(item, x_);
    storeUnaligned(item + 4, y_);
    storeUnaligned(item + 8, z_);
    storeUnaligned(item + 12, intensity_);
    item[14] = returns_;
    item[15] = classification_;
    item[16] = scan_angle_;
    item[17] = user_data_;
    storeUnaligned(item + 18, source_id_);
  }

 private:
  int32_t x_ = 0, y_ = 0, z_ = 0;
  uint16_t intensity_ = 0, source_id_ = 0;
  uint8_t returns_ = 0, classification_ = 0, scan_angle_ = 0, user_data_ = 0;
  std::array<uint16_t, 16> last_intensity_{};
  std::array<int32_t, 8> last_height_{};
  std::array<LazMedian5, 16> dx_history_, dy_history_;

  LazSymbolModel changed_model_{64};
  // The return byte, classification and user data each have a model per previous value.
  LazKeyedModels<256> returns_models_{256}, class_models_{256}, user_models_{256};
  std::array<LazSymbolModel, 2> scan_angle_models_{LazSymbolModel(256), LazSymbolModel(256)};  // by scan direction
  LazIntegerDecoder intensity_decoder_{16, 4};
  LazIntegerDecoder source_id_decoder_{16, 1};
  LazIntegerDecoder dx_decoder_{32, 2};
  LazIntegerDecoder dy_decoder_{32, 22};
  LazIntegerDecoder z_decoder_{32, 20};
};

// GPS time (a double) as its 64-bit pattern. Up to four sequences (interleaved flight lines) are
// followed at once, each with its last time and last integer difference; a point either repeats,
// steps by a multiple of the last difference (the multiplier a symbol, the remainder an integer),
// switches to another sequence, or starts a new one with a full 64-bit value.
class GpsTimeDecoder final : public LazItemDecoder {
 public:
  explicit GpsTimeDecoder(const uint8_t* first) { time_[0] = loadUnaligned<uint64_t>(first); }

  void decode(LazDecoder& d, uint8_t* item) override {
    // A switch to another sequence decodes the point again in that one (LASzip recurses). An
    // encoder switches at most once per point (to a sequence where the difference fits 32 bits,
    // then codes it there), so a second switch is corrupt data: refusing it bounds the loop, which
    // crafted data could otherwise spin for billions of cheap symbols.
    for (int pass = 0;; ++pass) {
      if (pass == 2 || !d.ok()) {
        corrupt_ = pass == 2;
        break;
      }
      if (diff_[last_] == 0) {
        const uint32_t s = d.decodeSymbol(zero_diff_model_);
        if (s == 1) {  // a difference that fits 32 bits
          diff_[last_] = time_decoder_.decode(d, 0, 0);
          time_[last_] += static_cast<uint64_t>(static_cast<int64_t>(diff_[last_]));
          extreme_[last_] = 0;
        } else if (s == 2) {
          startSequence(d);
        } else if (s > 2) {
          last_ = (last_ + s - 2) & 3u;
          continue;
        }
        break;  // s == 0: unchanged
      }
      const uint32_t s = d.decodeSymbol(multi_model_);
      if (s == 1) {
        time_[last_] += widen(time_decoder_.decode(d, diff_[last_], 1));
        extreme_[last_] = 0;
      } else if (s < kUnchanged) {
        time_[last_] += widen(multipleDifference(d, s));
      } else if (s == kFull) {
        startSequence(d);
      } else if (s > kFull) {
        last_ = (last_ + s - kFull) & 3u;
        continue;
      }
      break;  // s == kUnchanged
    }
    storeUnaligned(item, time_[last_]);
  }
  bool corrupt() const override { return corrupt_; }

 private:
  static constexpr uint32_t kMulti = kLazGpsMulti, kUnchanged = kLazGpsUnchanged, kFull = kLazGpsFull;
  static constexpr int32_t kMultiMinus = kLazGpsMultiMinus;

  static uint64_t widen(int32_t v) { return static_cast<uint64_t>(static_cast<int64_t>(v)); }
  // multiple · last difference with the encoder's 32-bit wrap-around.
  int32_t times(int32_t multiple) const {
    return static_cast<int32_t>(static_cast<uint32_t>(multiple) * static_cast<uint32_t>(diff_[last_]));
  }
  // A difference counted among the extreme multipliers (0, ≥ 500, ≤ −10): after four in a row it
  // becomes the sequence's difference.
  void countExtreme(int32_t difference) {
    if (++extreme_[last_] > 3) {
      diff_[last_] = difference;
      extreme_[last_] = 0;
    }
  }

  int32_t multipleDifference(LazDecoder& d, uint32_t s) {
    if (s == 0) {
      const int32_t difference = time_decoder_.decode(d, 0, 7);
      countExtreme(difference);
      return difference;
    }
    if (s < kMulti) return time_decoder_.decode(d, times(static_cast<int32_t>(s)), s < 10 ? 2 : 3);
    if (s == kMulti) {
      const int32_t difference = time_decoder_.decode(d, times(static_cast<int32_t>(kMulti)), 4);
      countExtreme(difference);
      return difference;
    }
    const int32_t multiple = static_cast<int32_t>(kMulti) - static_cast<int32_t>(s);  // −1..−10
    if (multiple > kMultiMinus) return time_decoder_.decode(d, times(multiple), 5);
    const int32_t difference = time_decoder_.decode(d, times(kMultiMinus), 6);
    countExtreme(difference);
    return difference;
  }

  // A new sequence: the high 32 bits predicted by the current sequence's, the low 32 raw.
  void startSequence(LazDecoder& d) {
    const int32_t high = time_decoder_.decode(d, static_cast<int32_t>(time_[last_] >> 32), 8);
    next_ = (next_ + 1) & 3u;
    time_[next_] = (static_cast<uint64_t>(static_cast<uint32_t>(high)) << 32) | d.readInt();
    last_ = next_;
    diff_[last_] = 0;
    extreme_[last_] = 0;
  }

  std::array<uint64_t, 4> time_{};
  std::array<int32_t, 4> diff_{};
  std::array<int32_t, 4> extreme_{};
  uint32_t last_ = 0, next_ = 0;
  bool corrupt_ = false;
  LazSymbolModel multi_model_{kLazGpsMultiSymbols};
  LazSymbolModel zero_diff_model_{6};  // unchanged, 32-bit difference, new sequence, 3 switches
  LazIntegerDecoder time_decoder_{32, 9};
};

// Red, green, blue (u16 each). Which of the six bytes changed is one symbol (bit 6: green and blue
// differ from red at all); red's bytes are coded against the last red, green's and blue's against
// the last value moved by red's change (blue's by the mean of red's and green's), clamped to a
// byte. All byte sums are mod 256.
class RgbDecoder final : public LazItemDecoder {
 public:
  explicit RgbDecoder(const uint8_t* first) {
    for (size_t c = 0; c < 3; ++c) last_[c] = loadUnaligned<uint16_t>(first + 2 * c);
  }

  void decode(LazDecoder& d, uint8_t* item) override {
    const uint32_t used = d.decodeSymbol(used_model_);
    const int red_lo = (used & 1) ? byteSum(d.decodeSymbol(byte_models_[0]), lo(last_[0])) : lo(last_[0]);
    const int red_hi = (used & 2) ? byteSum(d.decodeSymbol(byte_models_[1]), hi(last_[0])) : hi(last_[0]);
    int green_lo = red_lo, green_hi = red_hi, blue_lo = red_lo, blue_hi = red_hi;
    if (used & 64) {
      int change = red_lo - lo(last_[0]);
      green_lo = (used & 4) ? byteSum(d.decodeSymbol(byte_models_[2]), clampByte(change + lo(last_[1])))
                            : lo(last_[1]);
      if (used & 16) {
        change = (change + green_lo - lo(last_[1])) / 2;  // truncated toward zero, as LASzip's
        blue_lo = byteSum(d.decodeSymbol(byte_models_[4]), clampByte(change + lo(last_[2])));
      } else {
        blue_lo = lo(last_[2]);
      }
      change = red_hi - hi(last_[0]);
      green_hi = (used & 8) ? byteSum(d.decodeSymbol(byte_models_[3]), clampByte(change + hi(last_[1])))
                            : hi(last_[1]);
      if (used & 32) {
        change = (change + green_hi - hi(last_[1])) / 2;
        blue_hi = byteSum(d.decodeSymbol(byte_models_[5]), clampByte(change + hi(last_[2])));
      } else {
        blue_hi = hi(last_[2]);
      }
    }
    last_[0] = static_cast<uint16_t>(red_lo | red_hi << 8);
    last_[1] = static_cast<uint16_t>(green_lo | green_hi << 8);
    last_[2] = static_cast<uint16_t>(blue_lo | blue_hi << 8);
    for (size_t c = 0; c < 3; ++c) storeUnaligned(item + 2 * c, last_[c]);
  }

 private:
  static int lo(uint16_t v) { return v & 0xFF; }
  static int hi(uint16_t v) { return v >> 8; }
  static int clampByte(int v) { return std::clamp(v, 0, 255); }
  static int byteSum(uint32_t symbol, int base) {
    return static_cast<int>((symbol + static_cast<uint32_t>(base)) & 0xFFu);
  }

  std::array<uint16_t, 3> last_{};
  LazSymbolModel used_model_{128};
  std::array<LazSymbolModel, 6> byte_models_{LazSymbolModel(256), LazSymbolModel(256), LazSymbolModel(256),
                                             LazSymbolModel(256), LazSymbolModel(256), LazSymbolModel(256)};
};

// Extra bytes: each byte the last one plus a symbol of its own model, mod 256.
class ByteDecoder final : public LazItemDecoder {
 public:
  ByteDecoder(const uint8_t* first, size_t size) : last_(first, first + size) {
    models_.reserve(size);
    for (size_t i = 0; i < size; ++i) models_.emplace_back(256);
  }

  void decode(LazDecoder& d, uint8_t* item) override {
    for (size_t i = 0; i < last_.size(); ++i) {
      last_[i] = static_cast<uint8_t>(last_[i] + d.decodeSymbol(models_[i]));
      item[i] = last_[i];
    }
  }

 private:
  std::vector<uint8_t> last_;
  std::vector<LazSymbolModel> models_;
};

}  // namespace

std::unique_ptr<LazItemDecoder> makeLazItemDecoderV2(const LazItem& item, const uint8_t* first) {
  assert(item.version == 2);
  switch (item.type) {
    case kLazPoint10: return std::make_unique<Point10Decoder>(first);
    case kLazGpsTime11: return std::make_unique<GpsTimeDecoder>(first);
    case kLazRgb12: return std::make_unique<RgbDecoder>(first);
    case kLazByte: return std::make_unique<ByteDecoder>(first, item.size);
    default: break;
  }
  assert(false && "parseLaszipVlr refuses other item types");
  return nullptr;
}

}  // namespace dpoint
