// The state both sides of LAZ's layered chunks share (laz_layered.h says what the chunks are):
// the POINT14 record as its coder sees it, one scanner channel's context (its last point,
// predictors, GPS time sequences and models, for the decoder's and the encoder's integer coder
// alike), the colour and extra-byte items' contexts and how a chunk's items are laid out. Internal
// to laz_layered_decode.cpp and laz_layered_encode.cpp: one definition of each context, so that the
// encoder updates exactly the models the decoder reads. Written from LASzip's laszip_common_v3 and
// lasreaditemcompressed_v3 (Apache 2.0), as laz_layered.h says.
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "converters/laz_codec.h"
#include "converters/laz_common.h"
#include "converters/laz_decode.h"
#include "core/bytes.h"
#include "core/result.h"

namespace dpoint::laz_layered {

inline constexpr uint16_t kVersion3 = 3;

// Contexts from the return number r and the number of returns n (laszip_common_v3.hpp), both
// 0..15 in LAS 1.4: kReturnMap6[n][r] picks one of 6 x/y difference histories; entries that
// well-formed files never use (r > n, r or n = 0) are filled in as LASzip fills them.
inline constexpr uint8_t kReturnMap6[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};
// The height history: LASzip's number_return_level_8ctx is |n − r| capped at 7.
inline uint32_t returnLevel(uint32_t n, uint32_t r) { return std::min<uint32_t>(n > r ? n - r : r - n, 7); }

// GPS time's symbols in version 3 (no "unchanged": the changed-values symbol says so). After a
// difference of 0: 0 (a 32-bit difference), 1 (a new sequence), 2..4 (switch by 1..3 sequences).
// Otherwise as version 2 up to 510, then 511 (a new sequence) and 512..514 (switches).
inline constexpr uint32_t kGpsFull = kLazGpsMulti - static_cast<uint32_t>(kLazGpsMultiMinus) + 1;  // 511
inline constexpr uint32_t kGpsMultiSymbols = kGpsFull + 4;                                           // 515
inline constexpr uint32_t kGpsZeroDiffSymbols = 5;

// A POINT14 record's fields as LASzip's coder sees them (LAS 1.4 R15, table 7). `flags` packs the
// classification flags (bits 0–3), scan direction (4) and edge of flight line (5): the symbol
// LASzip codes; the scanner channel is the context. Together they are all 30 bytes.
struct Point14 {
  int32_t x = 0, y = 0, z = 0;
  uint16_t intensity = 0;
  uint8_t r = 0, n = 0;  // return number, number of returns
  uint8_t flags = 0, channel = 0;
  uint8_t classification = 0, user_data = 0;
  int16_t scan_angle = 0;
  uint16_t source_id = 0;
  uint64_t gps = 0;          // the double's bits: compared and differenced as integers
  bool gps_changed = false;  // whether this point's time changed: part of the next point's context
};

inline Point14 loadPoint14(const uint8_t* p) {
  Point14 q;
  q.x = loadUnaligned<int32_t>(p);
  q.y = loadUnaligned<int32_t>(p + 4);
  q.z = loadUnaligned<int32_t>(p + 8);
  q.intensity = loadUnaligned<uint16_t>(p + 12);
  q.r = p[14] & 15;
  q.n = p[14] >> 4;
  q.flags = static_cast<uint8_t>((p[15] & 0x0F) | ((p[15] >> 2) & 0x30));
  q.channel = (p[15] >> 4) & 3;
  q.classification = p[16];
  q.user_data = p[17];
  q.scan_angle = loadUnaligned<int16_t>(p + 18);
  q.source_id = loadUnaligned<uint16_t>(p + 20);
  q.gps = loadUnaligned<uint64_t>(p + 22);
  return q;
}

inline void storePoint14(const Point14& q, uint8_t* p) {
  storeUnaligned(p, q.x);
  storeUnaligned(p + 4, q.y);
  storeUnaligned(p + 8, q.z);
  storeUnaligned(p + 12, q.intensity);
  p[14] = static_cast<uint8_t>(q.r | q.n << 4);
  p[15] = static_cast<uint8_t>((q.flags & 0x0F) | q.channel << 4 | (q.flags & 0x30) << 2);
  p[16] = q.classification;
  p[17] = q.user_data;
  storeUnaligned(p + 18, q.scan_angle);
  storeUnaligned(p + 20, q.source_id);
  storeUnaligned(p + 22, q.gps);
}

inline uint64_t widen(int32_t v) { return static_cast<uint64_t>(static_cast<int64_t>(v)); }
// a · b and a + b with the 32-bit wrap-around of LASzip's int arithmetic, without signed overflow.
inline int32_t wrapTimes(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) * static_cast<uint32_t>(b));
}
inline int32_t wrapPlus(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) + static_cast<uint32_t>(b));
}
inline int32_t wrapMinus(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) - static_cast<uint32_t>(b));
}

// One scanner channel's POINT14 context (LAScontextPOINT14): its last point, predictors, GPS time
// sequences and models. `IntegerCoder` is LazIntegerDecoder or LazIntegerEncoder.
template <class IntegerCoder>
struct Point14Channel {
  // A channel starts from `from`, the first point of the chunk or the last point of the channel
  // before it: every history of heights and intensities holds its value, its time is sequence 0.
  explicit Point14Channel(const Point14& from) : last(from) {
    last.gps_changed = false;
    last_z.fill(from.z);
    last_intensity.fill(from.intensity);
    time[0] = from.gps;
  }

  Point14 last;
  std::array<int32_t, 8> last_z{};
  std::array<uint16_t, 8> last_intensity{};
  std::array<LazMedian5, 12> dx_median, dy_median;
  // Up to four interleaved GPS time sequences, each with its last time and integer difference.
  std::array<uint64_t, 4> time{};
  std::array<int32_t, 4> time_diff{};
  std::array<int32_t, 4> extreme{};
  uint32_t seq = 0, next_seq = 0;

  std::array<LazSymbolModel, 8> changed{LazSymbolModel(128), LazSymbolModel(128), LazSymbolModel(128),
                                        LazSymbolModel(128), LazSymbolModel(128), LazSymbolModel(128),
                                        LazSymbolModel(128), LazSymbolModel(128)};
  LazSymbolModel channel_model{3};
  LazKeyedModels<16> returns_count{16}, return_number{16};
  LazSymbolModel return_gps_same{13};
  LazKeyedModels<64> classification{256}, flags{64}, user_data{256};
  LazSymbolModel gps_multi{kGpsMultiSymbols}, gps_zero_diff{kGpsZeroDiffSymbols};
  IntegerCoder dx{32, 2}, dy{32, 22}, z{32, 20}, intensity{16, 4}, scan_angle{16, 2}, source_id{16}, gps{32, 9};

  // A difference counted among the extreme multipliers (0, ≥ 500, ≤ −10): after four in a row it
  // becomes the sequence's difference.
  void countExtreme(int32_t difference) {
    if (++extreme[seq] > 3) {
      time_diff[seq] = difference;
      extreme[seq] = 0;
    }
  }
};

// The single (3) / first (1) / last (2) / intermediate (0) return context of LASzip, plus 4 when
// the point's time changed: which changed-values model codes the next point.
inline uint32_t changedContext(const Point14& last) {
  return (last.r == 1 ? 1u : 0u) + (last.r >= last.n ? 2u : 0u) + (last.gps_changed ? 4u : 0u);
}

// The layers of POINT14, in the chunk's order.
enum Point14Layer : size_t {
  kXy, kZ, kClass, kFlags, kIntensity, kScanAngle, kUserData, kSource, kGps, kPoint14Layers
};
inline constexpr const char* kPoint14LayerNames[kPoint14Layers] = {
    "channel/returns/XY", "Z", "classification", "flags", "intensity", "scan angle", "user data",
    "point source ID", "GPS time"};

// The colour and extra-byte items' contexts (LASzip 3's rule): the POINT14 coder hands them the
// channel on a point where it changed, else channel 0; a context new to the chunk starts from the
// last values of the context before; on a switch to a context that exists, the point is still
// coded against the previous context's last values (and they, not the new context's, take it).
template <class Channel>
class ItemChannels {
 public:
  template <class Values>
  ItemChannels(uint32_t context, const Values& first) : current_(context) {
    channels_[context] = std::make_unique<Channel>(first);
  }
  // Moves to `context`; returns the channel whose last values the point is coded against.
  Channel& enter(uint32_t context) {
    Channel* last = channels_[current_].get();
    if (context != current_) {
      current_ = context;
      if (!channels_[current_]) {
        channels_[current_] = std::make_unique<Channel>(last->last);
        last = channels_[current_].get();
      }
    }
    return *last;
  }
  Channel& models() { return *channels_[current_]; }

 private:
  uint32_t current_;
  std::array<std::unique_ptr<Channel>, 4> channels_;
};

// RGB14 and RGBNIR14's context: red, green, blue (and NIR) last, the byte-used and byte-difference
// models. An RGB14 item leaves the NIR part unused.
struct ColourChannel {
  explicit ColourChannel(const std::array<uint16_t, 4>& from) : last(from) {}
  std::array<uint16_t, 4> last;
  LazSymbolModel rgb_used{128};
  std::array<LazSymbolModel, 6> rgb_diff{LazSymbolModel(256), LazSymbolModel(256), LazSymbolModel(256),
                                         LazSymbolModel(256), LazSymbolModel(256), LazSymbolModel(256)};
  LazSymbolModel nir_used{4};
  std::array<LazSymbolModel, 2> nir_diff{LazSymbolModel(256), LazSymbolModel(256)};
};

// BYTE14's context: the last bytes and a model per byte.
struct BytesChannel {
  explicit BytesChannel(const std::vector<uint8_t>& from) : last(from) {
    models.reserve(from.size());
    for (size_t i = 0; i < from.size(); ++i) models.emplace_back(256);
  }
  std::vector<uint8_t> last;
  std::vector<LazSymbolModel> models;
};

inline int lo(uint16_t v) { return v & 0xFF; }
inline int hi(uint16_t v) { return v >> 8; }
inline int clampByte(int v) { return std::clamp(v, 0, 255); }
inline uint8_t byteOf(int v) { return static_cast<uint8_t>(v & 0xFF); }  // LASzip's U8_FOLD: mod 256

inline std::array<uint16_t, 4> loadColour(const uint8_t* p, bool nir) {
  std::array<uint16_t, 4> c{};
  for (size_t i = 0; i < (nir ? 4u : 3u); ++i) c[i] = loadUnaligned<uint16_t>(p + 2 * i);
  return c;
}

// The items of a layered chunk: POINT14, then RGB14 or RGBNIR14, then BYTE14, each optional but
// the first (what LASzip writes for formats 6–8).
struct Plan {
  bool rgb = false, nir = false;
  size_t extra = 0;      // extra bytes (BYTE14's size)
  size_t layers = 0;     // the layer sizes after the point count
};

inline Result<Plan> planOf(const LazInfo& info) {
  Plan plan;
  const std::vector<LazItem>& items = info.items;
  size_t i = 0;
  const auto next = [&](uint16_t type) {
    return i < items.size() && items[i].type == type && items[i].version == kVersion3;
  };
  bool ok = next(kLazPoint14) && items[i++].size == 30;
  if (ok && (next(kLazRgb14) || next(kLazRgbNir14))) {
    plan.rgb = true;
    plan.nir = items[i].type == kLazRgbNir14;
    ok = items[i++].size == (plan.nir ? 8 : 6);
  }
  if (ok && next(kLazByte14)) {
    plan.extra = items[i++].size;
    ok = plan.extra != 0;
  }
  if (!ok || i != items.size())
    return Error{"a layered LAZ chunk's items must be POINT14 (30 bytes), then RGB14 (6) or RGBNIR14 (8), then "
                 "BYTE14, all version 3"};
  plan.layers = kPoint14Layers + (plan.rgb ? 1 : 0) + (plan.nir ? 1 : 0) + plan.extra;
  return plan;
}

}  // namespace dpoint::laz_layered
