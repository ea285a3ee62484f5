// LAZ item version 1: the POINT10, GPSTIME11, RGB12 and BYTE decoders of the files LASzip 1.x wrote
// (2010–2011, most of them with compressor 1: the whole point data one code after the raw first
// point). dpoint's own code, written from LASzip's lasreaditemcompressed_v1 and
// laswriteitemcompressed_v1 (Apache 2.0), on the entropy coder of laz_codec.h; the version-2
// decoders in laz_decode_v2.cpp are the same family. What version 1 does differently:
//
// - POINT10: x, y and z come first, x and y as differences predicted by the median of the last
//   three (one history for all returns), y's and z's contexts the magnitude class of the
//   corrections before them (capped at 19, not rounded to even); then one symbol says which of the
//   other fields changed, each coded against its own last value: intensity, scan angle rank (a
//   byte, wrapping) and point source ID by integer compressors, the return byte, classification
//   and user data by a model per previous value. The second point's intensity is predicted from
//   the first's (version 2 starts from 0).
// - GPSTIME11: one time sequence, no switches. After a zero difference a symbol of 3 says
//   unchanged, a 32-bit difference, or a full 64-bit time; otherwise a symbol of 512: the
//   multiplier 0..509 of the last difference (0 predicts a quarter of it; 509 stands for 509 and
//   more), 510 a full 64-bit time, 511 unchanged. Four extreme multipliers in a row (0 or 509)
//   make the new difference the sequence's.
// - RGB12: a symbol says which of the six bytes changed; each one that did is an 8-bit integer
//   coded against its last value.
// - BYTE: each extra byte an 8-bit integer coded against its last value, a context per byte.
//
// Every decode step reads a bounded number of symbols: nothing in version 1 loops on the data.
// Only little-endian hosts, as laz_decode.cpp.
#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cstring>
#include <memory>
#include <vector>

#include "converters/laz_codec.h"
#include "converters/laz_item_decoder.h"
#include "core/bytes.h"

namespace dpoint {

static_assert(std::endian::native == std::endian::little, "LAZ fields are little-endian, copied as they are");

namespace {

// a + b and a · b with the 32-bit wrap-around of LASzip's int arithmetic, without signed overflow.
int32_t wrapPlus(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) + static_cast<uint32_t>(b));
}
int32_t wrapTimes(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) * static_cast<uint32_t>(b));
}

// The median of three (LASzip writes it as a tree of comparisons; ties give the same value).
int32_t median3(const std::array<int32_t, 3>& v) {
  return std::max(std::min(v[0], v[1]), std::min(std::max(v[0], v[1]), v[2]));
}

// POINT10, the 20 bytes formats 0–5 share (laz_decode_v2.cpp's Point10Decoder lists the fields).
class Point10V1Decoder final : public LazItemDecoder {
 public:
  explicit Point10V1Decoder(const uint8_t* first) {
    x_ = loadUnaligned<int32_t>(first);
    y_ = loadUnaligned<int32_t>(first + 4);
    z_ = loadUnaligned<int32_t>(first + 8);
    intensity_ = loadUnaligned<uint16_t>(first + 12);
    returns_ = first[14];
    classification_ = first[15];
    scan_angle_ = first[16];
    user_data_ = first[17];
    source_id_ = loadUnaligned<uint16_t>(first + 18);
  }

  void decode(LazDecoder& d, uint8_t* item) override {
    const int32_t dx = dx_decoder_.decode(d, median3(dx_history_));
    x_ = wrapPlus(x_, dx);
    uint32_t k = dx_decoder_.k();
    const int32_t dy = dy_decoder_.decode(d, median3(dy_history_), std::min(k, 19u));
    y_ = wrapPlus(y_, dy);
    k = (k + dy_decoder_.k()) / 2;
    z_ = z_decoder_.decode(d, z_, std::min(k, 19u));

    // Bits 5..0: intensity, the return byte, classification, scan angle rank, user data and point
    // source ID changed (not version 2's order).
    const uint32_t changed = d.decodeSymbol(changed_model_);
    if (changed & 32) intensity_ = static_cast<uint16_t>(intensity_decoder_.decode(d, intensity_));
    if (changed & 16) returns_ = static_cast<uint8_t>(d.decodeSymbol(returns_models_[returns_]));
    if (changed & 8)
      classification_ = static_cast<uint8_t>(d.decodeSymbol(class_models_[classification_]));
    if (changed & 4) scan_angle_ = static_cast<uint8_t>(scan_angle_decoder_.decode(d, scan_angle_, k < 3 ? 1u : 0u));
    if (changed & 2) user_data_ = static_cast<uint8_t>(d.decodeSymbol(user_models_[user_data_]));
    if (changed & 1) source_id_ = static_cast<uint16_t>(source_id_decoder_.decode(d, source_id_));

    dx_history_[next_] = dx;
    dy_history_[next_] = dy;
    next_ = next_ == 2 ? 0 : next_ + 1;

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
  std::array<int32_t, 3> dx_history_{}, dy_history_{};
  uint32_t next_ = 0;  // the history slot the next differences replace

  LazSymbolModel changed_model_{64};
  // The return byte, classification and user data each have a model per previous value.
  LazKeyedModels<256> returns_models_{256}, class_models_{256}, user_models_{256};
  LazIntegerDecoder dx_decoder_{32, 1};
  LazIntegerDecoder dy_decoder_{32, 20};
  LazIntegerDecoder z_decoder_{32, 20};
  LazIntegerDecoder intensity_decoder_{16, 1};
  LazIntegerDecoder scan_angle_decoder_{8, 2};  // by whether the x/y corrections were small
  LazIntegerDecoder source_id_decoder_{16, 1};
};

// GPS time (a double) as its 64-bit pattern, one sequence (top comment).
class GpsTimeV1Decoder final : public LazItemDecoder {
 public:
  explicit GpsTimeV1Decoder(const uint8_t* first) : time_(loadUnaligned<uint64_t>(first)) {}

  void decode(LazDecoder& d, uint8_t* item) override {
    if (diff_ == 0) {
      const uint32_t s = d.decodeSymbol(zero_diff_model_);
      if (s == 1) {
        diff_ = time_decoder_.decode(d, 0, 0);
        time_ += widen(diff_);
      } else if (s == 2) {
        time_ = readTime(d);
      }  // s == 0: unchanged
    } else {
      const uint32_t s = d.decodeSymbol(multi_model_);
      if (s < kFull) time_ += widen(multipleDifference(d, s));
      else if (s == kFull) time_ = readTime(d);
      // s == kUnchanged: unchanged
    }
    storeUnaligned(item, time_);
  }

 private:
  static constexpr uint32_t kMultiSymbols = 512;
  static constexpr uint32_t kMultiMax = kMultiSymbols - 3;  // 509: 509 times or more
  static constexpr uint32_t kFull = kMultiSymbols - 2;      // 510
  static constexpr uint32_t kUnchanged = kMultiSymbols - 1;  // 511
  static_assert(kUnchanged + 1 == kMultiSymbols, "the model's last symbol leaves the time unchanged");

  static uint64_t widen(int32_t v) { return static_cast<uint64_t>(static_cast<int64_t>(v)); }
  // A full time: two 32-bit halves, low first (LASzip's readInt64).
  static uint64_t readTime(LazDecoder& d) {
    const uint64_t low = d.readInt();
    return (uint64_t{d.readInt()} << 32) | low;
  }
  // A difference counted among the extreme multipliers (0 and 509): after four in a row it
  // becomes the sequence's difference.
  void countExtreme(int32_t difference) {
    if (++extreme_ > 3) {
      diff_ = difference;
      extreme_ = 0;
    }
  }

  int32_t multipleDifference(LazDecoder& d, uint32_t s) {
    if (s == 1) {
      diff_ = time_decoder_.decode(d, diff_, 1);
      extreme_ = 0;
      return diff_;
    }
    if (s == 0) {
      const int32_t difference = time_decoder_.decode(d, diff_ / 4, 2);  // truncated toward zero, as LASzip's
      countExtreme(difference);
      return difference;
    }
    const int32_t predicted = wrapTimes(static_cast<int32_t>(s), diff_);
    if (s < 10) return time_decoder_.decode(d, predicted, 3);
    if (s < 50) return time_decoder_.decode(d, predicted, 4);
    const int32_t difference = time_decoder_.decode(d, predicted, 5);
    if (s == kMultiMax) countExtreme(difference);
    return difference;
  }

  uint64_t time_ = 0;
  int32_t diff_ = 0;
  int32_t extreme_ = 0;
  LazSymbolModel multi_model_{kMultiSymbols};
  LazSymbolModel zero_diff_model_{3};  // unchanged, a 32-bit difference, a full time
  LazIntegerDecoder time_decoder_{32, 6};
};

// Red, green, blue (u16 each) as six bytes, low byte first.
class RgbV1Decoder final : public LazItemDecoder {
 public:
  explicit RgbV1Decoder(const uint8_t* first) { std::memcpy(last_.data(), first, last_.size()); }

  void decode(LazDecoder& d, uint8_t* item) override {
    const uint32_t used = d.decodeSymbol(used_model_);
    for (uint32_t b = 0; b < 6; ++b)
      if (used & (1u << b)) last_[b] = static_cast<uint8_t>(byte_decoder_.decode(d, last_[b], b));
    std::memcpy(item, last_.data(), last_.size());
  }

 private:
  std::array<uint8_t, 6> last_{};
  LazSymbolModel used_model_{64};
  LazIntegerDecoder byte_decoder_{8, 6};  // a context per byte
};

// Extra bytes: each an 8-bit integer predicted by the last, a context per byte.
class ByteV1Decoder final : public LazItemDecoder {
 public:
  ByteV1Decoder(const uint8_t* first, size_t size)
      : last_(first, first + size), byte_decoder_(8, static_cast<uint32_t>(size)) {}

  void decode(LazDecoder& d, uint8_t* item) override {
    for (size_t i = 0; i < last_.size(); ++i) {
      last_[i] = static_cast<uint8_t>(byte_decoder_.decode(d, last_[i], static_cast<uint32_t>(i)));
      item[i] = last_[i];
    }
  }

 private:
  std::vector<uint8_t> last_;
  LazIntegerDecoder byte_decoder_;
};

}  // namespace

std::unique_ptr<LazItemDecoder> makeLazItemDecoderV1(const LazItem& item, const uint8_t* first) {
  assert(item.version == 1);
  switch (item.type) {
    case kLazPoint10: return std::make_unique<Point10V1Decoder>(first);
    case kLazGpsTime11: return std::make_unique<GpsTimeV1Decoder>(first);
    case kLazRgb12: return std::make_unique<RgbV1Decoder>(first);
    case kLazByte: return std::make_unique<ByteV1Decoder>(first, item.size);
    default: break;
  }
  assert(false && "parseLaszipVlr refuses other version-1 item types");
  return nullptr;
}

}  // namespace dpoint
