// The bench report's montage: per-point error heat maps, stb_easy_font text and the layout of
// tiles, title and colour bar in one RGBA8 image.
//
// The heat map's colours are viridis (image/canvas.h): perceptually ordered from dark to bright,
// so a larger error reads as brighter at a glance and in grey print.
#include "bench/montage.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace dpoint {
namespace {

constexpr uint32_t pack(uint32_t r, uint32_t g, uint32_t b) { return packRgb(r, g, b); }

constexpr uint32_t kLostColor = pack(255, 0, 255);
constexpr uint32_t kBackground = pack(0x20, 0x20, 0x20);
constexpr uint32_t kTitleColor = pack(0xf2, 0xf2, 0xf2);
constexpr uint32_t kLabelColor = pack(0xff, 0xff, 0xff);
constexpr uint32_t kCaptionColor = pack(0xb4, 0xb4, 0xb4);
constexpr uint32_t kLegendColor = pack(0xd0, 0xd0, 0xd0);
constexpr uint32_t kTickColor = pack(0xa0, 0xa0, 0xa0);

constexpr int kLineUnits = kTextLineUnits;
constexpr int kGlyphUnits = kTextGlyphUnits;
constexpr int kCapUnits = 7;     // rows of a capital or a digit
constexpr int kMargin = 10;      // around everything
constexpr int kTileGap = 8;      // between tiles, and between the tile row and the colour bar
constexpr int kPictureGap = 4;   // between a picture and its heat map

// The largest scale from `preferred` down to 1 at which `text` fits in `width`; 1 if none does.
int fittingScale(const std::string& text, int preferred, int width) {
  int scale = preferred;
  while (scale > 1 && textWidth(text, scale) > width) --scale;
  return scale;
}

struct WrappedText {
  std::string text;  // lines joined by '\n'
  int scale = 1;
  int lines = 1;
  bool fits = true;  // no line wider than asked
};

// Pieces of `text` cut after each `separator` (which they keep), e.g. the clauses of "a, b".
std::vector<std::string> splitAfter(const std::string& text, char separator) {
  std::vector<std::string> pieces;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(separator, start);
    end = end == std::string::npos ? text.size() : end + 1;
    while (end < text.size() && text[end] == ' ') ++end;  // the space after "," goes with it
    pieces.push_back(text.substr(start, end - start));
    start = end;
  }
  return pieces;
}

// Greedy: each line takes pieces while they fit in `width`; a line ends without its trailing space.
WrappedText joinLines(const std::vector<std::string>& pieces, int scale, int width) {
  const auto trimmed = [](std::string line) { return line.erase(line.find_last_not_of(' ') + 1); };
  WrappedText wrapped{"", scale, 1, true};
  std::string current;
  for (const std::string& piece : pieces) {
    if (!current.empty() && textWidth(trimmed(current + piece), scale) > width) {
      wrapped.text += trimmed(current) + '\n';
      ++wrapped.lines;
      current.clear();
    }
    current += piece;
    wrapped.fits = wrapped.fits && textWidth(trimmed(current), scale) <= width;
  }
  wrapped.text += trimmed(current);
  return wrapped;
}

// `text` broken into lines no wider than `width`, after a comma where that is enough ("max 3 px,"
// over "2 lost"), else after any space: at the largest scale from `preferred` down where it takes
// at most two lines, since a second line reads better than a smaller font. At scale 1 it takes
// as many lines as it needs, and a word wider than `width` is left to clipping.
WrappedText wrapText(const std::string& text, int preferred, int width) {
  for (int scale = preferred;; --scale) {
    WrappedText wrapped = joinLines(splitAfter(text, ','), scale, width);
    if (!wrapped.fits) wrapped = joinLines(splitAfter(text, ' '), scale, width);
    if (scale <= 1 || (wrapped.fits && wrapped.lines <= 2)) return wrapped;
  }
}

// "1e-06", "0.01", "1", "100", "1e+06": %g keeps short decades plain and long ones exponential.
std::string decadeLabel(int decade) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", std::pow(10.0, decade));
  return text;
}

// Under the colour bar: ticks, a gap, a line of labels.
int belowBarHeight(int scale) { return 3 * scale + 2 * scale + kGlyphUnits * scale; }

// Colour bar from lo_px to hi_px at (x, y), ticks under it at every decade and labels under every
// `step`-th decade, chosen so that neighbouring labels keep a gap.
void drawColourBar(Image& image, int x, int y, int width, int bar_height, int scale, double lo_px, double hi_px) {
  const double log_lo = std::log10(lo_px), log_hi = std::log10(hi_px);
  for (int i = 0; i < width; ++i) {
    const uint32_t color = viridis(width > 1 ? double(i) / double(width - 1) : 0.0);
    fillRect(image, {x + i, y, x + i + 1, y + bar_height}, wholeImage(image), color);
  }
  const auto x_of = [&](double log_e) {
    return x + int(std::lround((log_e - log_lo) / (log_hi - log_lo) * double(width - 1)));
  };
  // log10 of a decade may land a hair off the integer; the tolerance keeps lo = 1e-6 a tick.
  const int first = int(std::ceil(log_lo - 1e-9)), last = int(std::floor(log_hi + 1e-9));
  const int tick_y = y + bar_height, tick_length = 3 * scale, label_y = tick_y + tick_length + 2 * scale;
  if (first > last) {
    // No decade inside the range: label its ends instead.
    char text[32];
    std::snprintf(text, sizeof(text), "%.2g", lo_px);
    drawTextClipped(image, wholeImage(image), x, label_y, text, kLegendColor, scale);
    std::snprintf(text, sizeof(text), "%.2g", hi_px);
    drawTextClipped(image, wholeImage(image), x + width - textWidth(text, scale), label_y, text, kLegendColor, scale);
    return;
  }
  int widest = 0;
  for (int k = first; k <= last; ++k) widest = std::max(widest, textWidth(decadeLabel(k), scale));
  const double decade_px = double(width - 1) / (log_hi - log_lo);
  int step = 1;
  while (double(step) * decade_px < double(widest + 6 * scale)) ++step;
  for (int k = first; k <= last; ++k) {
    const int tick_x = x_of(double(k));
    const bool labelled = k % step == 0;
    const int length = labelled ? tick_length : tick_length / 2 + 1;
    fillRect(image, {tick_x, tick_y, tick_x + 1, tick_y + length}, wholeImage(image), kTickColor);
    if (!labelled) continue;
    const std::string label = decadeLabel(k);
    const int label_x = std::clamp(tick_x - textWidth(label, scale) / 2, 0, int(image.width) - textWidth(label, scale));
    drawTextClipped(image, wholeImage(image), label_x, label_y, label, kLegendColor, scale);
  }
}

}  // namespace

uint32_t errorColor(double error_px, double lo_px, double hi_px) {
  assert(lo_px > 0.0 && hi_px > lo_px);
  if (std::isnan(error_px)) return kLostColor;
  if (!(error_px > lo_px)) return viridis(0.0);  // also 0 and negatives, whose log is no number
  const double t = (std::log10(error_px) - std::log10(lo_px)) / (std::log10(hi_px) - std::log10(lo_px));
  return viridis(t);
}

Image errorHeatMap(const std::vector<WindowPoint>& reference, const std::vector<double>& error_px, uint32_t width,
                   uint32_t height, double lo_px, double hi_px) {
  assert(reference.size() == error_px.size());
  assert(lo_px > 0.0 && hi_px > lo_px);
  enum : uint8_t { kEmpty, kValue, kLost };
  std::vector<uint8_t> state(size_t(width) * height, kEmpty);
  std::vector<double> largest(size_t(width) * height, 0.0);
  for (size_t i = 0; i < reference.size(); ++i) {
    const WindowPoint& p = reference[i];
    if (!p.visible) continue;
    // As rasterReference: ceil − 1, checked as a double so that no out-of-range value is converted.
    const double px = std::ceil(p.x) - 1.0, py = std::ceil(p.y) - 1.0;
    if (!(px >= 0.0 && px < double(width) && py >= 0.0 && py < double(height))) continue;
    const size_t pixel = size_t(py) * width + size_t(px);
    const double e = error_px[i];
    if (std::isnan(e)) {
      state[pixel] = kLost;  // a lost point is the largest error there is
    } else if (state[pixel] == kEmpty || (state[pixel] == kValue && e > largest[pixel])) {
      state[pixel] = kValue, largest[pixel] = e;
    }
  }
  Image image = blankImage(width, height, pack(0, 0, 0));
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      const size_t pixel = size_t(y) * width + x;
      if (state[pixel] == kLost) putPixel(image, x, y, kLostColor);
      if (state[pixel] == kValue) putPixel(image, x, y, errorColor(largest[pixel], lo_px, hi_px));
    }
  }
  return image;
}



Image composeMontage(const std::string& title, const std::vector<MontageTile>& tiles, double lo_px, double hi_px) {
  assert(lo_px > 0.0 && hi_px > lo_px);
  const int tile_w = tiles.empty() ? 0 : int(tiles[0].picture.width);
  const int tile_h = tiles.empty() ? 0 : int(tiles[0].picture.height);
  for ([[maybe_unused]] const MontageTile& tile : tiles) {
    assert(int(tile.picture.width) == tile_w && int(tile.picture.height) == tile_h);
    assert(tile.heat.width == tile.picture.width && tile.heat.height == tile.picture.height);
  }
  const int scale = tile_w >= 200 ? 2 : 1;
  const int line = kLineUnits * scale;
  const int tiles_w = int(tiles.size()) * tile_w + std::max(0, int(tiles.size()) - 1) * kTileGap;

  // Legend: "lost" swatch right of the bar; the bar gets what the tiles leave, at least enough
  // for a few readable decades, at most what the eye follows in one sweep.
  const std::string legend = "per-point error in pixels (log scale)";
  const int bar_h = 8 * scale + 4, swatch_gap = 16 * scale;
  const int lost_w = swatch_gap + bar_h + 4 * scale + textWidth("lost", scale);
  const int min_bar_w = std::max(160 * scale, textWidth(legend, scale) - lost_w);
  // Inset by half the first decade's label, which is centred on the bar's left end.
  const int bar_x = kMargin + textWidth(decadeLabel(int(std::ceil(std::log10(lo_px) - 1e-9))), scale) / 2;
  const int title_scale = scale + 1;
  const int content_w = std::max({tiles_w, bar_x - kMargin + min_bar_w + lost_w, textWidth(title, 1)});
  const int bar_w = std::clamp(content_w - (bar_x - kMargin) - lost_w, min_bar_w, std::max(min_bar_w, 384 * scale));

  // Every tile gets as many label and caption lines as the tile that needs most, so that the
  // pictures stay in one row.
  std::vector<WrappedText> labels, captions;
  int label_lines = 1, caption_lines = 1;
  for (const MontageTile& tile : tiles) {
    labels.push_back(wrapText(tile.label, scale, tile_w));
    captions.push_back(wrapText(tile.caption, scale, tile_w));
    label_lines = std::max(label_lines, labels.back().lines);
    caption_lines = std::max(caption_lines, captions.back().lines);
  }

  const int title_h = kGlyphUnits * title_scale;
  const int tiles_top = kMargin + title_h + kMargin;
  const int caption_top = tiles_top + label_lines * line;
  const int picture_top = caption_top + caption_lines * line;
  const int tiles_h = tiles.empty() ? 0 : picture_top - tiles_top + tile_h + kPictureGap + tile_h + 2 * kTileGap;
  const int legend_top = tiles_top + tiles_h;
  const int bar_top = legend_top + line;
  const int bar_block_h = bar_h + belowBarHeight(scale);

  Image image = blankImage(uint32_t(content_w + 2 * kMargin), uint32_t(bar_top + bar_block_h + kMargin), kBackground);
  drawText(image, kMargin, kMargin, title, kTitleColor, fittingScale(title, title_scale, content_w));

  for (size_t i = 0; i < tiles.size(); ++i) {
    const int x = kMargin + int(i) * (tile_w + kTileGap);
    // Text stays inside its own column so that a long word never runs into the next tile.
    const Rect column = {x, tiles_top, x + tile_w, picture_top};
    drawTextClipped(image, column, x, tiles_top, labels[i].text, kLabelColor, labels[i].scale);
    drawTextClipped(image, column, x, caption_top, captions[i].text, kCaptionColor, captions[i].scale);
    blit(image, tiles[i].picture, x, picture_top);
    blit(image, tiles[i].heat, x, picture_top + tile_h + kPictureGap);
  }

  drawText(image, bar_x, legend_top, legend, kLegendColor, scale);
  drawColourBar(image, bar_x, bar_top, bar_w, bar_h, scale, lo_px, hi_px);
  const int swatch_x = bar_x + bar_w + swatch_gap;
  fillRect(image, {swatch_x, bar_top, swatch_x + bar_h, bar_top + bar_h}, wholeImage(image), kLostColor);
  const int lost_y = bar_top + (bar_h - kCapUnits * scale) / 2;
  drawText(image, swatch_x + bar_h + 4 * scale, lost_y, "lost", kLegendColor, scale);
  return image;
}

}  // namespace dpoint
