// LAZ layered chunks (converters/laz_layered.h says what and whence): the POINT14, RGB14/RGBNIR14
// and BYTE14 coders of item version 3, decoding and encoding side by side so that each encoder can
// be read against its decoder (the same models, updated in the same order), then the chunk layout.
// Only little-endian hosts: fields are copied out of the records with memcpy, as in laz_decode.cpp.
#include "converters/laz_layered.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "converters/laz_codec.h"
#include "converters/laz_common.h"
#include "converters/laz_encoder.h"
#include "core/bytes.h"

namespace dpoint {

static_assert(std::endian::native == std::endian::little, "LAZ fields are little-endian, copied as they are");

namespace {

std::string str(uint64_t v) { return std::to_string(v); }

constexpr uint16_t kPoint14 = 10, kRgb14 = 11, kRgbNir14 = 12, kByte14 = 14;  // LASzip's item types
constexpr uint16_t kVersion3 = 3;

// --- Contexts and state shared by both directions --------------------------------------------------

// Contexts from the return number r and the number of returns n (laszip_common_v3.hpp), both
// 0..15 in LAS 1.4: kReturnMap6[n][r] picks one of 6 x/y difference histories; entries that
// well-formed files never use (r > n, r or n = 0) are filled in as LASzip fills them.
constexpr uint8_t kReturnMap6[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};
// The height history: LASzip's number_return_level_8ctx is |n − r| capped at 7.
uint32_t returnLevel(uint32_t n, uint32_t r) { return std::min<uint32_t>(n > r ? n - r : r - n, 7); }

// GPS time's symbols in version 3 (no "unchanged": the changed-values symbol says so). After a
// difference of 0: 0 (a 32-bit difference), 1 (a new sequence), 2..4 (switch by 1..3 sequences).
// Otherwise as version 2 up to 510, then 511 (a new sequence) and 512..514 (switches).
constexpr uint32_t kGpsFull = kLazGpsMulti - static_cast<uint32_t>(kLazGpsMultiMinus) + 1;  // 511
constexpr uint32_t kGpsMultiSymbols = kGpsFull + 4;                                           // 515
constexpr uint32_t kGpsZeroDiffSymbols = 5;

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

Point14 loadPoint14(const uint8_t* p) {
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

void storePoint14(const Point14& q, uint8_t* p) {
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

// Models keyed by a previous value, created when first needed, as LASzip creates them: most
// files use a few of the keys. A new model starts in its reset state, so when it is created does
// not change the code.
template <size_t N>
class LazyModels {
 public:
  explicit LazyModels(uint32_t symbols) : symbols_(symbols) {}
  LazSymbolModel& operator[](size_t key) {
    assert(key < N);
    if (!models_[key]) models_[key] = std::make_unique<LazSymbolModel>(symbols_);
    return *models_[key];
  }

 private:
  uint32_t symbols_;
  std::array<std::unique_ptr<LazSymbolModel>, N> models_;
};

uint64_t widen(int32_t v) { return static_cast<uint64_t>(static_cast<int64_t>(v)); }
// a · b and a + b with the 32-bit wrap-around of LASzip's int arithmetic, without signed overflow.
int32_t wrapTimes(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) * static_cast<uint32_t>(b));
}
int32_t wrapPlus(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) + static_cast<uint32_t>(b));
}
int32_t wrapMinus(int32_t a, int32_t b) {
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
  LazyModels<16> returns_count{16}, return_number{16};
  LazSymbolModel return_gps_same{13};
  LazyModels<64> classification{256}, flags{64}, user_data{256};
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
uint32_t changedContext(const Point14& last) {
  return (last.r == 1 ? 1u : 0u) + (last.r >= last.n ? 2u : 0u) + (last.gps_changed ? 4u : 0u);
}

// The layers of POINT14, in the chunk's order.
enum Point14Layer : size_t {
  kXy, kZ, kClass, kFlags, kIntensity, kScanAngle, kUserData, kSource, kGps, kPoint14Layers
};
constexpr const char* kPoint14LayerNames[kPoint14Layers] = {
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

int lo(uint16_t v) { return v & 0xFF; }
int hi(uint16_t v) { return v >> 8; }
int clampByte(int v) { return std::clamp(v, 0, 255); }
uint8_t byteOf(int v) { return static_cast<uint8_t>(v & 0xFF); }  // LASzip's U8_FOLD: mod 256

std::array<uint16_t, 4> loadColour(const uint8_t* p, bool nir) {
  std::array<uint16_t, 4> c{};
  for (size_t i = 0; i < (nir ? 4u : 3u); ++i) c[i] = loadUnaligned<uint16_t>(p + 2 * i);
  return c;
}

// --- Decoding --------------------------------------------------------------------------------------

class Point14Decoder {
 public:
  // `layers[k]`: layer k's decoder, null when the layer is empty (its values never change).
  Point14Decoder(const uint8_t* first, const std::array<LazDecoder*, kPoint14Layers>& layers) : layers_(layers) {
    const Point14 p = loadPoint14(first);
    current_ = p.channel;
    channels_[current_] = std::make_unique<Channel>(p);
  }
  uint32_t firstContext() const { return current_; }
  bool corrupt() const { return corrupt_; }

  // Decodes the next point into `item`; returns the context for the other items (the channel
  // when it changed at this point, else 0).
  uint32_t decode(uint8_t* item) {
    LazDecoder& xy = *layers_[kXy];
    Channel* c = channels_[current_].get();
    const uint32_t changed = xy.decodeSymbol(c->changed[changedContext(c->last)]);
    uint32_t context = 0;
    if (changed & 64) {  // the channel is current + 1 + symbol, mod 4
      const uint32_t channel = (current_ + xy.decodeSymbol(c->channel_model) + 1) & 3;
      if (!channels_[channel]) channels_[channel] = std::make_unique<Channel>(c->last);
      current_ = context = channel;
      c = channels_[channel].get();
      c->last.channel = static_cast<uint8_t>(channel);
    }
    Point14& last = c->last;
    const bool gps_changed = (changed & 16) != 0;

    if (changed & 4) last.n = static_cast<uint8_t>(xy.decodeSymbol(c->returns_count[last.n]));
    switch (changed & 3) {
      case 1: last.r = (last.r + 1) & 15; break;
      case 2: last.r = (last.r + 15) & 15; break;
      case 3:  // a bigger step: the number itself when the time changed, else the step (2..14)
        if (gps_changed) last.r = static_cast<uint8_t>(xy.decodeSymbol(c->return_number[last.r]));
        else last.r = static_cast<uint8_t>((last.r + xy.decodeSymbol(c->return_gps_same) + 2) & 15);
        break;
      default: break;
    }
    const uint32_t n = last.n, r = last.r;
    const uint32_t single = n == 1 ? 1 : 0;
    const uint32_t cpr = (r == 1 ? 2u : 0u) + (r >= n ? 1u : 0u);  // first (2) and last (1) return

    // x and y: the difference from the last point, predicted by the history's median; y's and z's
    // contexts grow with the magnitude classes (k) of the corrections before them.
    const uint32_t history = (uint32_t{kReturnMap6[n][r]} << 1) | (gps_changed ? 1 : 0);
    const int32_t dx = c->dx.decode(xy, c->dx_median[history].get(), single);
    last.x = wrapPlus(last.x, dx);
    c->dx_median[history].add(dx);
    uint32_t k = c->dx.k();
    const int32_t dy = c->dy.decode(xy, c->dy_median[history].get(), single + (k < 20 ? k & ~1u : 20));
    last.y = wrapPlus(last.y, dy);
    c->dy_median[history].add(dy);

    if (LazDecoder* d = layers_[kZ]) {
      k = (c->dx.k() + c->dy.k()) / 2;
      const uint32_t l = returnLevel(n, r);
      last.z = c->z.decode(*d, c->last_z[l], single + (k < 18 ? k & ~1u : 18));
      c->last_z[l] = last.z;
    }
    if (LazDecoder* d = layers_[kClass]) {
      const uint32_t key = ((last.classification & 0x1Fu) << 1) + (cpr == 3 ? 1 : 0);
      last.classification = static_cast<uint8_t>(d->decodeSymbol(c->classification[key]));
    }
    if (LazDecoder* d = layers_[kFlags]) last.flags = static_cast<uint8_t>(d->decodeSymbol(c->flags[last.flags]));
    if (LazDecoder* d = layers_[kIntensity]) {
      const uint32_t h = (cpr << 1) | (gps_changed ? 1 : 0);
      last.intensity = static_cast<uint16_t>(c->intensity.decode(*d, c->last_intensity[h], cpr));
      c->last_intensity[h] = last.intensity;
    }
    if (LazDecoder* d = layers_[kScanAngle]; d && (changed & 8)) {
      last.scan_angle = static_cast<int16_t>(c->scan_angle.decode(*d, last.scan_angle, gps_changed ? 1 : 0));
    }
    if (LazDecoder* d = layers_[kUserData])
      last.user_data = static_cast<uint8_t>(d->decodeSymbol(c->user_data[last.user_data / 4u]));
    if (LazDecoder* d = layers_[kSource]; d && (changed & 32))
      last.source_id = static_cast<uint16_t>(c->source_id.decode(*d, last.source_id));
    if (LazDecoder* d = layers_[kGps]; d && gps_changed) {
      decodeTime(*d, *c);
      last.gps = c->time[c->seq];
    }
    storePoint14(last, item);
    last.gps_changed = gps_changed;
    return context;
  }

 private:
  using Channel = Point14Channel<LazIntegerDecoder>;

  // The point's time in its channel's sequences. An encoder switches sequence at most once per
  // point (to one where the difference fits 32 bits, then codes it there), so a second switch is
  // corrupt data: refusing it also bounds the loop.
  void decodeTime(LazDecoder& d, Channel& c) {
    for (int switches = 0; switches < 2; ++switches) {
      if (c.time_diff[c.seq] == 0) {
        const uint32_t s = d.decodeSymbol(c.gps_zero_diff);
        if (s == 0) {
          c.time_diff[c.seq] = c.gps.decode(d, 0, 0);
          c.time[c.seq] += widen(c.time_diff[c.seq]);
          c.extreme[c.seq] = 0;
          return;
        }
        if (s == 1) return startSequence(d, c);
        c.seq = (c.seq + s - 1) & 3;
        continue;
      }
      const uint32_t s = d.decodeSymbol(c.gps_multi);
      if (s == 1) {
        c.time[c.seq] += widen(c.gps.decode(d, c.time_diff[c.seq], 1));
        c.extreme[c.seq] = 0;
        return;
      }
      if (s < kGpsFull) {
        c.time[c.seq] += widen(multipleDifference(d, c, s));
        return;
      }
      if (s == kGpsFull) return startSequence(d, c);
      c.seq = (c.seq + s - kGpsFull) & 3;
    }
    corrupt_ = true;
  }

  // s: 0 (unrelated to the last difference), 2..499 (that many times it), 500 (500 or more
  // times), 501..510 (−1..−10 times, −10 meaning −10 or less).
  static int32_t multipleDifference(LazDecoder& d, Channel& c, uint32_t s) {
    const int32_t last = c.time_diff[c.seq];
    if (s == 0) {
      const int32_t difference = c.gps.decode(d, 0, 7);
      c.countExtreme(difference);
      return difference;
    }
    if (s < kLazGpsMulti) return c.gps.decode(d, wrapTimes(static_cast<int32_t>(s), last), s < 10 ? 2 : 3);
    if (s == kLazGpsMulti) {
      const int32_t difference = c.gps.decode(d, wrapTimes(static_cast<int32_t>(kLazGpsMulti), last), 4);
      c.countExtreme(difference);
      return difference;
    }
    const int32_t multiple = static_cast<int32_t>(kLazGpsMulti) - static_cast<int32_t>(s);  // −1..−10
    if (multiple > kLazGpsMultiMinus) return c.gps.decode(d, wrapTimes(multiple, last), 5);
    const int32_t difference = c.gps.decode(d, wrapTimes(kLazGpsMultiMinus, last), 6);
    c.countExtreme(difference);
    return difference;
  }

  // A new sequence: the high 32 bits predicted by the current sequence's, the low 32 raw.
  static void startSequence(LazDecoder& d, Channel& c) {
    const int32_t high = c.gps.decode(d, static_cast<int32_t>(c.time[c.seq] >> 32), 8);
    c.next_seq = (c.next_seq + 1) & 3;
    c.time[c.next_seq] = (uint64_t{static_cast<uint32_t>(high)} << 32) | d.readInt();
    c.seq = c.next_seq;
    c.time_diff[c.seq] = 0;
    c.extreme[c.seq] = 0;
  }

  std::array<LazDecoder*, kPoint14Layers> layers_;
  std::array<std::unique_ptr<Channel>, 4> channels_;
  uint32_t current_ = 0;
  bool corrupt_ = false;
};

// RGB14 (nir false) and RGBNIR14. Which of red's, green's and blue's bytes changed is one symbol
// (bit 6: green and blue differ from red at all); red's bytes are coded against the last red,
// green's and blue's against the last value moved by red's change (blue's by the mean of red's and
// green's), clamped to a byte; NIR's two bytes against the last NIR. Byte sums are mod 256.
class ColourDecoder {
 public:
  ColourDecoder(const uint8_t* first, uint32_t context, bool nir, LazDecoder* rgb, LazDecoder* nir_layer)
      : nir_(nir), rgb_(rgb), nir_layer_(nir_layer), channels_(context, loadColour(first, nir)) {}

  void decode(uint8_t* item, uint32_t context) {
    ColourChannel& l = channels_.enter(context);
    ColourChannel& m = channels_.models();
    if (rgb_) decodeRgb(*rgb_, l.last, m);
    for (size_t c = 0; c < 3; ++c) storeUnaligned(item + 2 * c, l.last[c]);
    if (!nir_) return;
    if (nir_layer_) {
      LazDecoder& d = *nir_layer_;
      const uint32_t used = d.decodeSymbol(m.nir_used);
      int low = lo(l.last[3]), high = hi(l.last[3]);
      if (used & 1) low = byteOf(static_cast<int>(d.decodeSymbol(m.nir_diff[0])) + low);
      if (used & 2) high = byteOf(static_cast<int>(d.decodeSymbol(m.nir_diff[1])) + high);
      l.last[3] = static_cast<uint16_t>(low | high << 8);
    }
    storeUnaligned(item + 6, l.last[3]);
  }

 private:
  static void decodeRgb(LazDecoder& d, std::array<uint16_t, 4>& last, ColourChannel& m) {
    const uint32_t used = d.decodeSymbol(m.rgb_used);
    const auto next = [&](size_t model, int base) {
      return byteOf(static_cast<int>(d.decodeSymbol(m.rgb_diff[model])) + base);
    };
    const int red_lo = (used & 1) ? next(0, lo(last[0])) : lo(last[0]);
    const int red_hi = (used & 2) ? next(1, hi(last[0])) : hi(last[0]);
    int green_lo = red_lo, green_hi = red_hi, blue_lo = red_lo, blue_hi = red_hi;
    if (used & 64) {
      int change = red_lo - lo(last[0]);
      green_lo = (used & 4) ? next(2, clampByte(change + lo(last[1]))) : lo(last[1]);
      if (used & 16) {
        change = (change + green_lo - lo(last[1])) / 2;  // truncated toward zero, as LASzip's
        blue_lo = next(4, clampByte(change + lo(last[2])));
      } else {
        blue_lo = lo(last[2]);
      }
      change = red_hi - hi(last[0]);
      green_hi = (used & 8) ? next(3, clampByte(change + hi(last[1]))) : hi(last[1]);
      if (used & 32) {
        change = (change + green_hi - hi(last[1])) / 2;
        blue_hi = next(5, clampByte(change + hi(last[2])));
      } else {
        blue_hi = hi(last[2]);
      }
    }
    last[0] = static_cast<uint16_t>(red_lo | red_hi << 8);
    last[1] = static_cast<uint16_t>(green_lo | green_hi << 8);
    last[2] = static_cast<uint16_t>(blue_lo | blue_hi << 8);
  }

  bool nir_;
  LazDecoder* rgb_;
  LazDecoder* nir_layer_;
  ItemChannels<ColourChannel> channels_;
};

// BYTE14: each extra byte in its own layer, the last byte plus a symbol of its context's model.
class BytesDecoder {
 public:
  BytesDecoder(const uint8_t* first, size_t size, uint32_t context, std::vector<LazDecoder*> layers)
      : layers_(std::move(layers)), channels_(context, std::vector<uint8_t>(first, first + size)) {}

  void decode(uint8_t* item, uint32_t context) {
    BytesChannel& l = channels_.enter(context);
    BytesChannel& m = channels_.models();
    for (size_t i = 0; i < layers_.size(); ++i) {
      if (LazDecoder* d = layers_[i]) l.last[i] = static_cast<uint8_t>(l.last[i] + d->decodeSymbol(m.models[i]));
      item[i] = l.last[i];
    }
  }

 private:
  std::vector<LazDecoder*> layers_;
  ItemChannels<BytesChannel> channels_;
};

// --- Encoding --------------------------------------------------------------------------------------

// A layer being written: its encoder and whether some value in it changed (else it is left out).
struct LayerOut {
  LazEncoder encoder;
  bool changed = false;
};

class Point14Encoder {
 public:
  explicit Point14Encoder(const uint8_t* first) {
    const Point14 p = loadPoint14(first);
    current_ = p.channel;
    channels_[current_] = std::make_unique<Channel>(p);
    // LASzip writes these two whatever the points hold.
    layers_[kXy].changed = layers_[kZ].changed = true;
  }
  uint32_t firstContext() const { return current_; }
  std::array<LayerOut, kPoint14Layers>& layers() { return layers_; }

  // Codes the next point; returns the context for the other items, as Point14Decoder::decode.
  uint32_t encode(const uint8_t* item) {
    const Point14 p = loadPoint14(item);
    LazEncoder& xy = layers_[kXy].encoder;
    Channel* c = channels_[current_].get();
    // The point is compared with the last point of its own channel; a channel new to the chunk
    // will start from the current channel's last point.
    const Point14& before = p.channel != current_ && channels_[p.channel] ? channels_[p.channel]->last : c->last;
    const bool gps_changed = p.gps != before.gps;
    uint32_t changed = (p.channel != current_ ? 64u : 0u) | (p.source_id != before.source_id ? 32u : 0u) |
                       (gps_changed ? 16u : 0u) | (p.scan_angle != before.scan_angle ? 8u : 0u) |
                       (p.n != before.n ? 4u : 0u);
    if (p.r == ((before.r + 1) & 15)) changed |= 1;
    else if (p.r == ((before.r + 15) & 15)) changed |= 2;
    else if (p.r != before.r) changed |= 3;
    xy.encodeSymbol(c->changed[changedContext(c->last)], changed);
    uint32_t context = 0;
    if (changed & 64) {
      xy.encodeSymbol(c->channel_model, (p.channel - current_ + 3u) & 3);  // channel = current + 1 + symbol
      if (!channels_[p.channel]) channels_[p.channel] = std::make_unique<Channel>(c->last);
      current_ = context = p.channel;
      c = channels_[current_].get();
    }
    Point14& last = c->last;  // holds `before`'s values

    if (changed & 4) xy.encodeSymbol(c->returns_count[last.n], p.n);
    if ((changed & 3) == 3) {
      if (gps_changed) xy.encodeSymbol(c->return_number[last.r], p.r);
      else xy.encodeSymbol(c->return_gps_same, (p.r - last.r + 14u) & 15);  // r = last + 2 + symbol
    }
    const uint32_t n = p.n, r = p.r;
    const uint32_t single = n == 1 ? 1 : 0;
    const uint32_t cpr = (r == 1 ? 2u : 0u) + (r >= n ? 1u : 0u);

    const uint32_t history = (uint32_t{kReturnMap6[n][r]} << 1) | (gps_changed ? 1 : 0);
    const int32_t dx = wrapMinus(p.x, last.x);
    c->dx.encode(xy, c->dx_median[history].get(), dx, single);
    c->dx_median[history].add(dx);
    uint32_t k = c->dx.k();
    const int32_t dy = wrapMinus(p.y, last.y);
    c->dy.encode(xy, c->dy_median[history].get(), dy, single + (k < 20 ? k & ~1u : 20));
    c->dy_median[history].add(dy);

    k = (c->dx.k() + c->dy.k()) / 2;
    const uint32_t l = returnLevel(n, r);
    c->z.encode(layers_[kZ].encoder, c->last_z[l], p.z, single + (k < 18 ? k & ~1u : 18));
    c->last_z[l] = p.z;

    const uint32_t key = ((last.classification & 0x1Fu) << 1) + (cpr == 3 ? 1 : 0);
    layers_[kClass].changed |= p.classification != last.classification;
    layers_[kClass].encoder.encodeSymbol(c->classification[key], p.classification);

    layers_[kFlags].changed |= p.flags != last.flags;
    layers_[kFlags].encoder.encodeSymbol(c->flags[last.flags], p.flags);

    const uint32_t h = (cpr << 1) | (gps_changed ? 1 : 0);
    layers_[kIntensity].changed |= p.intensity != last.intensity;
    c->intensity.encode(layers_[kIntensity].encoder, c->last_intensity[h], p.intensity, cpr);
    c->last_intensity[h] = p.intensity;

    if (changed & 8) {
      layers_[kScanAngle].changed = true;
      c->scan_angle.encode(layers_[kScanAngle].encoder, last.scan_angle, p.scan_angle, gps_changed ? 1 : 0);
    }

    layers_[kUserData].changed |= p.user_data != last.user_data;
    layers_[kUserData].encoder.encodeSymbol(c->user_data[last.user_data / 4u], p.user_data);

    if (changed & 32) {
      layers_[kSource].changed = true;
      c->source_id.encode(layers_[kSource].encoder, last.source_id, p.source_id);
    }
    if (gps_changed) {
      layers_[kGps].changed = true;
      encodeTime(layers_[kGps].encoder, *c, p.gps);
    }
    last = p;
    last.gps_changed = gps_changed;
    return context;
  }

 private:
  using Channel = Point14Channel<LazIntegerEncoder>;

  // The inverse of Point14Decoder::decodeTime, with LASzip's choices where the code allows several:
  // the current sequence when the difference fits 32 bits, else the first other sequence it fits,
  // else a new one; the multiplier LASzip's single-precision quotient rounds to.
  static void encodeTime(LazEncoder& e, Channel& c, uint64_t time) {
    const auto fits = [&](uint32_t seq, int32_t& difference) {
      const int64_t d = static_cast<int64_t>(time - c.time[seq]);
      difference = static_cast<int32_t>(d);
      return d == difference;
    };
    for (;;) {
      int32_t d = 0;
      const bool here = fits(c.seq, d);
      if (!here) {
        uint32_t other = 1;
        int32_t unused = 0;
        while (other < 4 && !fits((c.seq + other) & 3, unused)) ++other;
        if (other < 4) {  // switch, then code it there
          e.encodeSymbol(c.time_diff[c.seq] == 0 ? c.gps_zero_diff : c.gps_multi,
                         c.time_diff[c.seq] == 0 ? other + 1 : kGpsFull + other);
          c.seq = (c.seq + other) & 3;
          continue;
        }
        e.encodeSymbol(c.time_diff[c.seq] == 0 ? c.gps_zero_diff : c.gps_multi, c.time_diff[c.seq] == 0 ? 1 : kGpsFull);
        c.gps.encode(e, static_cast<int32_t>(c.time[c.seq] >> 32), static_cast<int32_t>(time >> 32), 8);
        e.writeInt(static_cast<uint32_t>(time));
        c.next_seq = (c.next_seq + 1) & 3;
        c.seq = c.next_seq;
        c.time_diff[c.seq] = 0;
        c.extreme[c.seq] = 0;
      } else if (c.time_diff[c.seq] == 0) {
        e.encodeSymbol(c.gps_zero_diff, 0);
        c.gps.encode(e, 0, d, 0);
        c.time_diff[c.seq] = d;
        c.extreme[c.seq] = 0;
      } else {
        encodeMultiple(e, c, d);
      }
      c.time[c.seq] = time;
      return;
    }
  }

  static void encodeMultiple(LazEncoder& e, Channel& c, int32_t d) {
    const int32_t last = c.time_diff[c.seq];
    // LASzip's I32_QUANTIZE of a float quotient (half away from zero). Any multiplier decodes; this
    // one gives LASzip's bytes. Quotients past ±10^6 are clamped first (a float past the int range
    // converts undefined); they code the same as LASzip's 500 or −10 class.
    const float quotient = std::clamp(static_cast<float>(d) / static_cast<float>(last), -1e6f, 1e6f);
    const int32_t multi = static_cast<int32_t>(quotient >= 0 ? quotient + 0.5f : quotient - 0.5f);
    const int32_t multi_minus = kLazGpsMultiMinus, multi_max = static_cast<int32_t>(kLazGpsMulti);
    if (multi == 1) {
      e.encodeSymbol(c.gps_multi, 1);
      c.gps.encode(e, last, d, 1);
      c.extreme[c.seq] = 0;
    } else if (multi > 0 && multi < multi_max) {
      e.encodeSymbol(c.gps_multi, static_cast<uint32_t>(multi));
      c.gps.encode(e, wrapTimes(multi, last), d, multi < 10 ? 2 : 3);
    } else if (multi >= multi_max) {
      e.encodeSymbol(c.gps_multi, kLazGpsMulti);
      c.gps.encode(e, wrapTimes(multi_max, last), d, 4);
      c.countExtreme(d);
    } else if (multi < 0 && multi > multi_minus) {
      e.encodeSymbol(c.gps_multi, static_cast<uint32_t>(multi_max - multi));
      c.gps.encode(e, wrapTimes(multi, last), d, 5);
    } else if (multi <= multi_minus) {
      e.encodeSymbol(c.gps_multi, static_cast<uint32_t>(multi_max - multi_minus));
      c.gps.encode(e, wrapTimes(multi_minus, last), d, 6);
      c.countExtreme(d);
    } else {  // 0
      e.encodeSymbol(c.gps_multi, 0);
      c.gps.encode(e, 0, d, 7);
      c.countExtreme(d);
    }
  }

  std::array<LayerOut, kPoint14Layers> layers_;
  std::array<std::unique_ptr<Channel>, 4> channels_;
  uint32_t current_ = 0;
};

class ColourEncoder {
 public:
  ColourEncoder(const uint8_t* first, uint32_t context, bool nir)
      : nir_(nir), channels_(context, loadColour(first, nir)) {}
  LayerOut& rgb() { return rgb_; }
  LayerOut& nir() { return nir_layer_; }

  void encode(const uint8_t* item, uint32_t context) {
    ColourChannel& l = channels_.enter(context);
    ColourChannel& m = channels_.models();
    const std::array<uint16_t, 4> colour = loadColour(item, nir_);
    rgb_.changed |= encodeRgb(rgb_.encoder, colour, l.last, m);
    if (nir_) {
      const uint16_t v = colour[3], before = l.last[3];
      const uint32_t used = (lo(v) != lo(before) ? 1u : 0u) | (hi(v) != hi(before) ? 2u : 0u);
      nir_layer_.encoder.encodeSymbol(m.nir_used, used);
      if (used & 1) nir_layer_.encoder.encodeSymbol(m.nir_diff[0], byteOf(lo(v) - lo(before)));
      if (used & 2) nir_layer_.encoder.encodeSymbol(m.nir_diff[1], byteOf(hi(v) - hi(before)));
      nir_layer_.changed |= used != 0;
    }
    l.last = colour;
  }

 private:
  // Returns whether the symbol was not 0 (LASzip's test for writing the layer).
  static bool encodeRgb(LazEncoder& e, const std::array<uint16_t, 4>& v, const std::array<uint16_t, 4>& last,
                        ColourChannel& m) {
    uint32_t used = 0;
    for (uint32_t c = 0; c < 3; ++c) {
      if (lo(v[c]) != lo(last[c])) used |= 1u << (2 * c);
      if (hi(v[c]) != hi(last[c])) used |= 2u << (2 * c);
    }
    if (v[1] != v[0] || v[2] != v[0]) used |= 64;
    e.encodeSymbol(m.rgb_used, used);
    int diff_lo = 0, diff_hi = 0;
    if (used & 1) {
      diff_lo = lo(v[0]) - lo(last[0]);
      e.encodeSymbol(m.rgb_diff[0], byteOf(diff_lo));
    }
    if (used & 2) {
      diff_hi = hi(v[0]) - hi(last[0]);
      e.encodeSymbol(m.rgb_diff[1], byteOf(diff_hi));
    }
    if (used & 64) {
      if (used & 4) e.encodeSymbol(m.rgb_diff[2], byteOf(lo(v[1]) - clampByte(diff_lo + lo(last[1]))));
      if (used & 16) {
        diff_lo = (diff_lo + lo(v[1]) - lo(last[1])) / 2;
        e.encodeSymbol(m.rgb_diff[4], byteOf(lo(v[2]) - clampByte(diff_lo + lo(last[2]))));
      }
      if (used & 8) e.encodeSymbol(m.rgb_diff[3], byteOf(hi(v[1]) - clampByte(diff_hi + hi(last[1]))));
      if (used & 32) {
        diff_hi = (diff_hi + hi(v[1]) - hi(last[1])) / 2;
        e.encodeSymbol(m.rgb_diff[5], byteOf(hi(v[2]) - clampByte(diff_hi + hi(last[2]))));
      }
    }
    return used != 0;
  }

  bool nir_;
  LayerOut rgb_, nir_layer_;
  ItemChannels<ColourChannel> channels_;
};

class BytesEncoder {
 public:
  BytesEncoder(const uint8_t* first, size_t size, uint32_t context)
      : layers_(size), channels_(context, std::vector<uint8_t>(first, first + size)) {}
  std::vector<LayerOut>& layers() { return layers_; }

  void encode(const uint8_t* item, uint32_t context) {
    BytesChannel& l = channels_.enter(context);
    BytesChannel& m = channels_.models();
    for (size_t i = 0; i < layers_.size(); ++i) {
      layers_[i].encoder.encodeSymbol(m.models[i], static_cast<uint8_t>(item[i] - l.last[i]));
      if (item[i] != l.last[i]) {
        layers_[i].changed = true;
        l.last[i] = item[i];
      }
    }
  }

 private:
  std::vector<LayerOut> layers_;
  ItemChannels<BytesChannel> channels_;
};

// --- The chunk -------------------------------------------------------------------------------------

// The items of a layered chunk: POINT14, then RGB14 or RGBNIR14, then BYTE14, each optional but
// the first (what LASzip writes for formats 6–8).
struct Plan {
  bool rgb = false, nir = false;
  size_t extra = 0;      // extra bytes (BYTE14's size)
  size_t layers = 0;     // the layer sizes after the point count
};

Result<Plan> planOf(const LazInfo& info) {
  Plan plan;
  const std::vector<LazItem>& items = info.items;
  size_t i = 0;
  const auto next = [&](uint16_t type) {
    return i < items.size() && items[i].type == type && items[i].version == kVersion3;
  };
  bool ok = next(kPoint14) && items[i++].size == 30;
  if (ok && (next(kRgb14) || next(kRgbNir14))) {
    plan.rgb = true;
    plan.nir = items[i].type == kRgbNir14;
    ok = items[i++].size == (plan.nir ? 8 : 6);
  }
  if (ok && next(kByte14)) {
    plan.extra = items[i++].size;
    ok = plan.extra != 0;
  }
  if (!ok || i != items.size())
    return Error{"a layered LAZ chunk's items must be POINT14 (30 bytes), then RGB14 (6) or RGBNIR14 (8), then "
                 "BYTE14, all version 3"};
  plan.layers = kPoint14Layers + (plan.rgb ? 1 : 0) + (plan.nir ? 1 : 0) + plan.extra;
  return plan;
}

std::string layerName(const Plan& plan, size_t layer) {
  if (layer < kPoint14Layers) return kPoint14LayerNames[layer];
  layer -= kPoint14Layers;
  if (plan.rgb && layer == 0) return "RGB";
  if (plan.rgb) --layer;
  if (plan.nir && layer == 0) return "NIR";
  if (plan.nir) --layer;
  return "extra byte " + str(layer);
}

}  // namespace

Status decodeLayeredChunk(const LazInfo& info, const char* data, size_t bytes, uint64_t points, char* records) {
  Result<Plan> planned = planOf(info);
  if (!planned) return planned.error();
  const Plan& plan = *planned;
  const size_t length = info.recordLength();
  if (points == 0) return Error{"a chunk of 0 points"};
  const size_t header = length + 4 + 4 * plan.layers;
  if (bytes < header)
    return Error{"the chunk's " + str(bytes) + " bytes are fewer than the " + str(header) + " of its first point (" +
                 str(length) + " raw bytes), point count and " + str(plan.layers) + " layer sizes"};
  std::memcpy(records, data, length);
  const uint8_t* p = reinterpret_cast<const uint8_t*>(data);
  const uint32_t count = loadUnaligned<uint32_t>(p + length);
  if (count != points)
    return Error{"the chunk holds " + str(count) + " points by its own count, " + str(points) +
                 " by the chunk table (corrupt chunk or chunk table)"};
  std::vector<uint32_t> sizes(plan.layers);
  uint64_t total = 0;
  for (size_t i = 0; i < plan.layers; ++i) {
    sizes[i] = loadUnaligned<uint32_t>(p + length + 4 + 4 * i);
    total += sizes[i];
  }
  if (total > bytes - header)
    return Error{"the chunk's layer sizes add up to " + str(total) + " bytes, but only " + str(bytes - header) +
                 " follow them (truncated or corrupt chunk)"};
  if (total < bytes - header)
    return Error{str(bytes - header - total) + " of the chunk's " + str(bytes) +
                 " bytes are left over after its layers (corrupt chunk or chunk table)"};
  if (points > 1 && sizes[kXy] == 0)
    return Error{"the chunk's channel/returns/XY layer is empty, but it holds " + str(points) + " points"};

  // Each layer's decoder reads its own bytes only; an empty layer has none (its values never change).
  std::vector<std::optional<LazDecoder>> layers(plan.layers);
  std::vector<LazDecoder*> active;
  const auto decoderOf = [&](size_t i) { return layers[i] ? &*layers[i] : nullptr; };
  size_t at = header;
  for (size_t i = 0; i < plan.layers; ++i) {
    if (sizes[i] != 0) {
      layers[i].emplace(p + at, sizes[i]);
      active.push_back(&*layers[i]);
    }
    at += sizes[i];
  }
  const auto failure = [&](uint64_t point, bool corrupt_time) {
    const std::string where = "point " + str(point) + " of " + str(points) + ": ";
    if (corrupt_time) return Error{where + "the GPS time layer switches time sequence twice (corrupt data)"};
    for (size_t i = 0; i < plan.layers; ++i) {
      const LazDecoder* d = decoderOf(i);
      if (!d || d->ok()) continue;
      const std::string layer = "the " + layerName(plan, i) + " layer (" + str(sizes[i]) + " bytes)";
      if (d->invalid()) return Error{where + "invalid arithmetic code in " + layer + " (corrupt data)"};
      return Error{where + layer + " ends early (its decoder needs " + str(d->overrun()) +
                   " bytes past it; truncated or corrupt)"};
    }
    return Error{where + "corrupt data"};  // not reached: some decoder failed
  };
  const auto allOk = [&] {
    for (const LazDecoder* d : active)
      if (!d->ok()) return false;
    return true;
  };
  if (!allOk()) return failure(0, false);

  std::array<LazDecoder*, kPoint14Layers> point_layers{};
  for (size_t i = 0; i < kPoint14Layers; ++i) point_layers[i] = decoderOf(i);
  uint8_t* out = reinterpret_cast<uint8_t*>(records);
  Point14Decoder point(out, point_layers);
  const uint32_t first_context = point.firstContext();
  std::optional<ColourDecoder> colour;
  if (plan.rgb)
    colour.emplace(out + 30, first_context, plan.nir, decoderOf(kPoint14Layers),
                   plan.nir ? decoderOf(kPoint14Layers + 1) : nullptr);
  const size_t extra_at = 30 + (plan.rgb ? (plan.nir ? 8 : 6) : 0);
  std::optional<BytesDecoder> extra;
  if (plan.extra != 0) {
    const size_t first_layer = plan.layers - plan.extra;
    std::vector<LazDecoder*> byte_layers(plan.extra);
    for (size_t i = 0; i < plan.extra; ++i) byte_layers[i] = decoderOf(first_layer + i);
    extra.emplace(out + extra_at, plan.extra, first_context, std::move(byte_layers));
  }

  for (uint64_t i = 1; i < points; ++i) {
    uint8_t* record = out + i * length;
    const uint32_t context = point.decode(record);
    if (colour) colour->decode(record + 30, context);
    if (extra) extra->decode(record + extra_at, context);
    if (point.corrupt() || !allOk()) return failure(i, point.corrupt());
  }
  // LASzip's encoder pads each layer so that its decoder ends exactly at the layer's end.
  for (size_t i = 0; i < plan.layers; ++i) {
    const LazDecoder* d = decoderOf(i);
    if (d && d->consumed() != sizes[i])
      return Error{"the " + layerName(plan, i) + " layer: " + str(sizes[i] - d->consumed()) + " of its " +
                   str(sizes[i]) + " bytes are left over after the chunk's " + str(points) +
                   " points (corrupt chunk)"};
  }
  return okStatus();
}

std::vector<uint8_t> encodeLayeredChunk(const LazInfo& info, const char* records, uint64_t points) {
  Result<Plan> planned = planOf(info);
  assert(planned.ok() && points >= 1 && points <= UINT32_MAX);
  const Plan& plan = *planned;
  const size_t length = info.recordLength();
  const uint8_t* in = reinterpret_cast<const uint8_t*>(records);

  Point14Encoder point(in);
  const uint32_t first_context = point.firstContext();
  std::optional<ColourEncoder> colour;
  if (plan.rgb) colour.emplace(in + 30, first_context, plan.nir);
  const size_t extra_at = 30 + (plan.rgb ? (plan.nir ? 8 : 6) : 0);
  std::optional<BytesEncoder> extra;
  if (plan.extra != 0) extra.emplace(in + extra_at, plan.extra, first_context);
  for (uint64_t i = 1; i < points; ++i) {
    const uint8_t* record = in + i * length;
    const uint32_t context = point.encode(record);
    if (colour) colour->encode(record + 30, context);
    if (extra) extra->encode(record + extra_at, context);
  }

  // The layers in the chunk's order; one whose values never changed is left out (size 0).
  std::vector<LayerOut*> layers;
  for (LayerOut& l : point.layers()) layers.push_back(&l);
  if (colour) layers.push_back(&colour->rgb());
  if (colour && plan.nir) layers.push_back(&colour->nir());
  if (extra)
    for (LayerOut& l : extra->layers()) layers.push_back(&l);
  assert(layers.size() == plan.layers);
  std::vector<uint8_t> out(in, in + length);
  const auto put32 = [&](uint64_t v) {
    const uint32_t v32 = static_cast<uint32_t>(v);
    const uint8_t* b = reinterpret_cast<const uint8_t*>(&v32);
    out.insert(out.end(), b, b + 4);
  };
  put32(points);
  for (LayerOut* l : layers) {
    if (l->changed) l->encoder.done();
    put32(l->changed ? l->encoder.bytes().size() : 0);
  }
  for (LayerOut* l : layers)
    if (l->changed) out.insert(out.end(), l->encoder.bytes().begin(), l->encoder.bytes().end());
  return out;
}

}  // namespace dpoint
