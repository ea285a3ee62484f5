#include "ops/colormap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace dpoint {
namespace {

struct Rgb {
  uint8_t r, g, b;
};

// viridis at t = 0, 1/8, ..., 1.
constexpr std::array<Rgb, 9> kViridis = {{
    {0x44, 0x01, 0x54}, {0x47, 0x2d, 0x7b}, {0x3b, 0x52, 0x8b}, {0x2c, 0x72, 0x8e}, {0x21, 0x90, 0x8c},
    {0x27, 0xad, 0x81}, {0x5d, 0xc8, 0x63}, {0xaa, 0xdc, 0x32}, {0xfd, 0xe7, 0x25},
}};


struct NamedClass {
  Rgb rgb;
  const char* name;
};
constexpr std::array<NamedClass, 23> kClasses = {{
    {{128, 128, 128}, "never classified"},
    {{160, 160, 160}, "unclassified"},
    {{139, 90, 43}, "ground"},
    {{144, 238, 144}, "low vegetation"},
    {{60, 179, 60}, "medium vegetation"},
    {{0, 100, 0}, "high vegetation"},
    {{178, 34, 34}, "building"},
    {{255, 0, 255}, "low point (noise)"},
    {{200, 200, 200}, "reserved (key-point)"},
    {{30, 100, 255}, "water"},
    {{100, 50, 130}, "rail"},
    {{64, 64, 64}, "road surface"},
    {{200, 200, 200}, "reserved (overlap)"},
    {{255, 215, 0}, "wire, guard"},
    {{255, 255, 0}, "wire, conductor"},
    {{255, 140, 0}, "transmission tower"},
    {{255, 190, 120}, "wire connector"},
    {{210, 180, 140}, "bridge deck"},
    {{200, 0, 200}, "high noise"},
    {{0, 200, 200}, "overhead structure"},
    {{205, 170, 125}, "ignored ground"},
    {{255, 255, 255}, "snow"},
    {{255, 160, 200}, "temporal exclusion"},
}};
constexpr Rgb kOtherClass = {200, 200, 200};

// ColorBrewer "Paired", 12 classes.
constexpr std::array<Rgb, 12> kPaired = {{
    {0xa6, 0xce, 0xe3}, {0x1f, 0x78, 0xb4}, {0xb2, 0xdf, 0x8a}, {0x33, 0xa0, 0x2c}, {0xfb, 0x9a, 0x99},
    {0xe3, 0x1a, 0x1c}, {0xfd, 0xbf, 0x6f}, {0xff, 0x7f, 0x00}, {0xca, 0xb2, 0xd6}, {0x6a, 0x3d, 0x9a},
    {0xff, 0xff, 0x99}, {0xb1, 0x59, 0x28},
}};

}  // namespace

uint32_t asprsClassColor(uint8_t c) {
  const Rgb rgb = c < kClasses.size() ? kClasses[c].rgb : kOtherClass;
  return packRgb(rgb.r, rgb.g, rgb.b);
}

const char* asprsClassName(uint8_t c) { return c < kClasses.size() ? kClasses[c].name : nullptr; }

uint32_t categoryColor(size_t k) {
  const Rgb rgb = kPaired[k % kPaired.size()];
  return packRgb(rgb.r, rgb.g, rgb.b);
}

uint32_t viridis(double t) {
  const double u = (std::isnan(t) ? 0.0 : std::clamp(t, 0.0, 1.0)) * double(kViridis.size() - 1);
  const size_t i = std::min(size_t(u), kViridis.size() - 2);
  const double f = u - double(i);
  const auto mix = [f](uint8_t a, uint8_t b) { return uint32_t(std::lround(double(a) + (double(b) - double(a)) * f)); };
  const Rgb a = kViridis[i], b = kViridis[i + 1];
  return packRgb(mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b));
}

}  // namespace dpoint
