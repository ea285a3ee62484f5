#include "image/canvas.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <iterator>

#include <stb/stb_easy_font.h>  // a system include: its casts and unused statics stay quiet

namespace dpoint {
namespace {

constexpr int kMaxGlyphQuads = 64;

// stb_easy_font's 0 is a 4-unit oval with a 2-unit slash in its middle rows (#.## over ##.#),
// which at the montage's sizes fills the middle as 8's waist does: the numbers on the error scale
// read 8 for 0. This one is drawn instead: one unit wider (5 of the 6 units stb advances, so text
// widths do not change), its slash running corner to corner through an open middle, and its sides
// unbroken where 8 pinches in. '#': a unit drawn; rows from the top, as stb's glyphs start.
constexpr const char* kZeroRows[] = {".###.", "#...#", "#..##", "#.#.#", "##..#", "#...#", ".###."};

// stb's characters outside ' '..'~' would index past its glyph table.
char printable(char c) { return c >= ' ' && c <= '~' ? c : '?'; }

}  // namespace

void putPixel(Image& image, uint32_t x, uint32_t y, uint32_t rgba8) {
  uint8_t* p = &image.rgba[(size_t(y) * image.width + x) * 4];
  for (int c = 0; c < 4; ++c) p[c] = uint8_t(rgba8 >> (8 * c));
}


void fillRect(Image& image, Rect rect, Rect clip, uint32_t rgba8) {
  const int x0 = std::max({rect.x0, clip.x0, 0}), x1 = std::min({rect.x1, clip.x1, int(image.width)});
  const int y0 = std::max({rect.y0, clip.y0, 0}), y1 = std::min({rect.y1, clip.y1, int(image.height)});
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) putPixel(image, uint32_t(x), uint32_t(y), rgba8);
  }
}

Image blankImage(uint32_t width, uint32_t height, uint32_t rgba8) {
  Image image;
  image.width = width, image.height = height;
  image.rgba.resize(size_t(width) * height * 4);
  fillRect(image, wholeImage(image), wholeImage(image), rgba8);
  return image;
}

void blit(Image& dst, const Image& src, int x, int y) {
  for (uint32_t row = 0; row < src.height; ++row) {
    std::memcpy(&dst.rgba[((size_t(y) + row) * dst.width + size_t(x)) * 4], &src.rgba[size_t(row) * src.width * 4],
                size_t(src.width) * 4);
  }
}

// One character at a time, so that a fixed buffer always holds a glyph's quads.
int drawTextClipped(Image& image, Rect clip, int x, int y, const std::string& text, uint32_t rgba8, int scale) {
  assert(scale >= 1);
  int pen_x = 0, pen_y = 0, widest = 0;
  for (const char raw : text) {
    if (raw == '\n') {
      pen_x = 0, pen_y += kTextLineUnits;
      continue;
    }
    char glyph[2] = {printable(raw), 0};
    if (glyph[0] == '0') {
      for (int row = 0; row < int(std::size(kZeroRows)); ++row) {
        for (int col = 0; kZeroRows[row][col]; ++col) {
          if (kZeroRows[row][col] != '#') continue;
          const int ux = x + (pen_x + col) * scale, uy = y + (pen_y + row) * scale;
          fillRect(image, {ux, uy, ux + scale, uy + scale}, clip, rgba8);
        }
      }
      pen_x += stb_easy_font_width(glyph);
      widest = std::max(widest, pen_x);
      continue;
    }
    struct Vertex {
      float x, y, z;
      uint8_t color[4];
    };
    Vertex quads[kMaxGlyphQuads * 4];
    const int count = stb_easy_font_print(0.0f, 0.0f, glyph, nullptr, quads, int(sizeof(quads)));
    assert(count < kMaxGlyphQuads);  // a glyph that filled the buffer may have lost quads
    for (int q = 0; q < count; ++q) {
      // Vertices 0 and 2 are opposite corners, on whole units.
      const Vertex& a = quads[4 * q];
      const Vertex& b = quads[4 * q + 2];
      const Rect rect = {x + (pen_x + int(a.x)) * scale, y + (pen_y + int(a.y)) * scale,
                         x + (pen_x + int(b.x)) * scale, y + (pen_y + int(b.y)) * scale};
      fillRect(image, rect, clip, rgba8);
    }
    pen_x += stb_easy_font_width(glyph);
    widest = std::max(widest, pen_x);
  }
  return widest * scale;
}

int textWidth(const std::string& text, int scale) {
  assert(scale >= 1);
  int pen_x = 0, widest = 0;
  for (const char raw : text) {
    if (raw == '\n') {
      pen_x = 0;
      continue;
    }
    char glyph[2] = {printable(raw), 0};
    pen_x += stb_easy_font_width(glyph);
    widest = std::max(widest, pen_x);
  }
  return widest * scale;
}


Image composeContactSheet(const std::vector<LabelledView>& views, uint32_t columns) {
  assert(!views.empty() && columns >= 1);
  const uint32_t w = views[0].picture.width, h = views[0].picture.height;
  const uint32_t used_columns = std::min<uint32_t>(columns, uint32_t(views.size()));
  const uint32_t rows = (uint32_t(views.size()) + used_columns - 1) / used_columns;
  return composeContactSheet(views, columns, used_columns * w + (used_columns - 1) * kContactSheetGap,
                             rows * h + (rows - 1) * kContactSheetGap);
}

Image composeContactSheet(const std::vector<LabelledView>& views, uint32_t columns, uint32_t width, uint32_t height) {
  assert(!views.empty() && columns >= 1);
  constexpr uint32_t kGapColor = packRgb(0x20, 0x20, 0x20), kStripColor = packRgb(0x10, 0x10, 0x10);
  constexpr uint32_t kLabelColor = packRgb(0xf2, 0xf2, 0xf2);
  const uint32_t w = views[0].picture.width, h = views[0].picture.height;
  columns = std::min<uint32_t>(columns, uint32_t(views.size()));
  const uint32_t rows = (uint32_t(views.size()) + columns - 1) / columns;
  assert(width >= columns * w && height >= rows * h);
  // The lines take the pixels the pictures leave: cell i starts after i pictures and i lines, the
  // line pixels shared out in order (floor), so the last cell ends at the sheet's edge.
  const auto start = [](uint32_t i, uint32_t cells, uint32_t cell, uint32_t total) {
    return cells == 1 ? 0 : int(i * cell + (i * (total - cells * cell)) / (cells - 1));
  };
  Image sheet = blankImage(width, height, kGapColor);
  const int scale = w >= 400 ? 2 : 1;
  for (size_t i = 0; i < views.size(); ++i) {
    const Image& picture = views[i].picture;
    assert(picture.width == w && picture.height == h);
    const int x = start(uint32_t(i % columns), columns, w, width), y = start(uint32_t(i / columns), rows, h, height);
    blit(sheet, picture, x, y);
    const Rect tile = {x, y, x + int(w), y + int(h)};
    const int pad = 3 * scale;
    fillRect(sheet, {x, y, x + textWidth(views[i].label, scale) + 2 * pad, y + kTextGlyphUnits * scale + 2 * pad}, tile,
             kStripColor);
    drawTextClipped(sheet, tile, x + pad, y + pad, views[i].label, kLabelColor, scale);
  }
  return sheet;
}

void drawLegend(Image& image, const AttributeColoring& plan) {
  constexpr uint32_t kBoxColor = packRgb(0x10, 0x10, 0x10), kTextColor = packRgb(0xf2, 0xf2, 0xf2);
  const int scale = image.width >= 800 ? 2 : 1;
  const int pad = 4 * scale, line = kTextLineUnits * scale, swatch = kTextGlyphUnits * scale;
  const std::vector<LegendLine> lines = legendLines(plan);
  const bool ramp = plan.kind == AttributeColoring::Kind::kRamp;
  const int bar = ramp ? 6 * line : 0;  // the ramp's height between its two labels
  int width = textWidth(plan.name, scale);
  for (const LegendLine& l : lines) width = std::max(width, swatch + pad + textWidth(l.label, scale));
  const int height = line * (1 + int(lines.size())) + bar;
  const Rect all = wholeImage(image);
  const int x0 = int(image.width) - width - 3 * pad, y0 = pad;
  const Rect box = {x0, y0, x0 + width + 2 * pad, y0 + height + 2 * pad};
  fillRect(image, box, all, kBoxColor);
  int y = y0 + pad;
  const int x = x0 + pad;
  drawTextClipped(image, box, x, y, plan.name, kTextColor, scale);
  y += line;
  for (size_t k = 0; k < lines.size(); ++k) {
    if (ramp && k == 1) {  // the bar between p99 (above) and p1 (below)
      for (int row = 0; row < bar; ++row) {
        const double t = 1.0 - (double(row) + 0.5) / double(bar);
        fillRect(image, {x, y + row, x + swatch, y + row + 1}, box, plan.colorOf(plan.low + t * (plan.high - plan.low)));
      }
      y += bar;
    }
    fillRect(image, {x, y, x + swatch, y + swatch}, box, lines[k].rgba8);
    drawTextClipped(image, box, x + swatch + pad, y, lines[k].label, kTextColor, scale);
    y += line;
  }
}

}  // namespace dpoint
