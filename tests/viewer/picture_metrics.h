// Measures of a picture's fill, shared by the tests that pin how the default render looks
// (issue #24): how much of the data's closed outline shows background between the points.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "image/image.h"

namespace dpoint::test {

struct ClosingGap {
  size_t closed = 0;      // pixels of the closed drawn mask
  size_t gaps = 0;        // background pixels inside it
  double share = 0.0;     // gaps / closed (0 when nothing is drawn)
  uint32_t span_x = 0, span_y = 0;  // the drawn pixels' bounding box
  // Artefacts inside the closed mask (issue #36): outline pixels, drawn but under half the median
  // luminance of their 5 × 5 neighbourhood (the edge of a hollow square, a glyph's stroke, a dark
  // speck), and isolated background pixels, 6 or more of whose 8 neighbours are drawn.
  size_t artefacts = 0;
  double artefact_share = 0.0;  // artefacts / closed
};

// A pixel is drawn when its RGB is not the background's. The drawn mask is closed with a
// `size` × `size` square (dilated, then eroded; outside the picture counts as not drawn for the
// dilation and as drawn for the erosion, so the closing holds the mask); the background pixels the
// closing covers are the gaps a viewer sees between points.
inline ClosingGap closingGap(const Image& image, uint32_t background_rgba8, int size = 7) {
  const int w = static_cast<int>(image.width), h = static_cast<int>(image.height), r = size / 2;
  std::vector<uint8_t> drawn(size_t(w) * h), a(drawn.size()), b(drawn.size());
  ClosingGap out;
  int x0 = w, y0 = h, x1 = -1, y1 = -1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint8_t* p = &image.rgba[4 * (size_t(y) * w + x)];
      const uint32_t rgb = uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16;
      const bool d = rgb != (background_rgba8 & 0xffffffu);
      drawn[size_t(y) * w + x] = d;
      if (d) x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  if (x1 < 0) return out;
  out.span_x = uint32_t(x1 - x0 + 1), out.span_y = uint32_t(y1 - y0 + 1);
  // A square's max (min) filter is a row pass then a column pass; `outside` is the value beyond the picture.
  auto filter = [&](const std::vector<uint8_t>& in, std::vector<uint8_t>& result, bool dilate) {
    const uint8_t outside = dilate ? 0 : 1;
    std::vector<uint8_t> rows(in.size());
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        uint8_t v = dilate ? 0 : 1;
        for (int k = -r; k <= r; ++k) {
          const uint8_t s = (x + k < 0 || x + k >= w) ? outside : in[size_t(y) * w + x + k];
          v = dilate ? std::max(v, s) : std::min(v, s);
        }
        rows[size_t(y) * w + x] = v;
      }
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        uint8_t v = dilate ? 0 : 1;
        for (int k = -r; k <= r; ++k) {
          const uint8_t s = (y + k < 0 || y + k >= h) ? outside : rows[size_t(y + k) * w + x];
          v = dilate ? std::max(v, s) : std::min(v, s);
        }
        result[size_t(y) * w + x] = v;
      }
  };
  filter(drawn, a, true);
  filter(a, b, false);
  std::vector<int> luminance(drawn.size());
  for (size_t i = 0; i < luminance.size(); ++i) {
    const uint8_t* p = &image.rgba[4 * i];
    luminance[i] = 299 * p[0] + 587 * p[1] + 114 * p[2];
  }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      if (!b[i]) continue;
      ++out.closed;
      int window[25], n = 0, neighbours = 0;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int xx = std::clamp(x + dx, 0, w - 1), yy = std::clamp(y + dy, 0, h - 1);
          const size_t j = size_t(yy) * w + xx;
          window[n++] = luminance[j];
          if (std::max(std::abs(dx), std::abs(dy)) == 1) neighbours += drawn[j];
        }
      if (!drawn[i]) {
        ++out.gaps;
        out.artefacts += neighbours >= 6;
        continue;
      }
      std::nth_element(window, window + 12, window + 25);
      out.artefacts += 2 * luminance[i] < window[12];
    }
  out.share = out.closed ? double(out.gaps) / double(out.closed) : 0.0;
  out.artefact_share = out.closed ? double(out.artefacts) / double(out.closed) : 0.0;
  return out;
}

}  // namespace dpoint::test
