// LAZ layered chunks, encoding side (converters/laz_layered.h says what and whence): the POINT14,
// RGB14/RGBNIR14 and BYTE14 encoders of item version 3 and the chunk's layout as LASzip 3.x writes
// it. Each encoder mirrors its decoder in laz_layered_decode.cpp step for step, on the contexts of
// laz_layered_fields.h (the same models, updated in the same order). Only little-endian hosts.
#include "converters/laz_layered.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cstring>
#include <memory>
#include <optional>

#include "converters/laz_common.h"
#include "converters/laz_encoder.h"
#include "converters/laz_layered_fields.h"
#include "core/bytes.h"

namespace dpoint {

static_assert(std::endian::native == std::endian::little, "LAZ fields are little-endian, copied as they are");

using namespace laz_layered;  // the shared contexts

namespace {

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

}  // namespace

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
