#include "ops/colormap.h"

#include <algorithm>
#include <array>
#include <cmath>

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


}  // namespace

uint32_t viridis(double t) {
  const double u = (std::isnan(t) ? 0.0 : std::clamp(t, 0.0, 1.0)) * double(kViridis.size() - 1);
  const size_t i = std::min(size_t(u), kViridis.size() - 2);
  const double f = u - double(i);
  const auto mix = [f](uint8_t a, uint8_t b) { return uint32_t(std::lround(double(a) + (double(b) - double(a)) * f)); };
  const Rgb a = kViridis[i], b = kViridis[i + 1];
  return packRgb(mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b));
}

}  // namespace dpoint
