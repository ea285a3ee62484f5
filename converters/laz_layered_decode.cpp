// LAZ layered chunks, decoding side (converters/laz_layered.h says what and whence): the POINT14,
// RGB14/RGBNIR14 and BYTE14 decoders of item version 3 and the chunk's layout, each layer read
// from its own bytes. The contexts they share with the encoders (laz_layered_encode.cpp) are
// laz_layered_fields.h's. Only little-endian hosts: fields are copied out of the records with
// memcpy, as in laz_decode.cpp.
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
#include "converters/laz_layered_fields.h"
#include "core/bytes.h"

namespace dpoint {

static_assert(std::endian::native == std::endian::little, "LAZ fields are little-endian, copied as they are");

using namespace laz_layered;  // the shared contexts

namespace {

std::string str(uint64_t v) { return std::to_string(v); }

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

}  // namespace dpoint
