// Drawing into an RGBA8 Image (image/image.h): rectangles, copies, stb_easy_font text (no
// font files), and the contact sheet of `dpoint render --views`. Shared by
// the bench report's montage and the renderer's CLI.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ops/attribute_colors.h"
#include "ops/colormap.h"
#include "image/image.h"

namespace dpoint {

struct Rect {
  int x0, y0, x1, y1;  // [x0, x1) × [y0, y1)
};
inline Rect wholeImage(const Image& image) { return {0, 0, int(image.width), int(image.height)}; }


// Sets one pixel, which must be inside the image (not checked).
void putPixel(Image& image, uint32_t x, uint32_t y, uint32_t rgba8);
// An image of the given size filled with one colour.
Image blankImage(uint32_t width, uint32_t height, uint32_t rgba8);
// Fills rect ∩ clip ∩ the image.
void fillRect(Image& image, Rect rect, Rect clip, uint32_t rgba8);
// Copies src into dst with its top-left corner at (x, y); src must fit (asserted).
void blit(Image& dst, const Image& src, int x, int y);

// Draws `text` (ASCII) into `image` with its top-left corner at (x, y), each stb_easy_font unit
// `scale` pixels, clipped to `clip` and the image. Returns the width drawn in pixels: the widest
// line's advance, the same whether or not clipping cut it (as textWidth). '\n' starts a line 12
// units down; other characters outside ' '..'~' are drawn as '?'. scale ≥ 1 (asserted).
int drawTextClipped(Image& image, Rect clip, int x, int y, const std::string& text, uint32_t rgba8, int scale);
inline int drawText(Image& image, int x, int y, const std::string& text, uint32_t rgba8, int scale) {
  return drawTextClipped(image, wholeImage(image), x, y, text, rgba8, scale);
}
// The width drawText returns, without drawing.
int textWidth(const std::string& text, int scale);
inline constexpr int kTextLineUnits = 12;  // stb_easy_font's line step
inline constexpr int kTextGlyphUnits = 9;  // rows a line's glyphs cover, descenders included

struct LabelledView {
  std::string label;
  Image picture;
};
// The views in a grid of `columns` (rows as needed), each with its label on a dark strip over its
// top-left corner, separated by 2-pixel dark lines. Every picture must have the same size
// (asserted); views must not be empty and columns ≥ 1 (asserted).
Image composeContactSheet(const std::vector<LabelledView>& views, uint32_t columns);
// The same sheet at exactly `width` x `height`: the dark lines between the pictures take what the
// pictures leave (at least 2 px when the pictures are contactSheetCell's size), so a sheet is the
// size the user asked for. The pictures must fit (asserted).
Image composeContactSheet(const std::vector<LabelledView>& views, uint32_t columns, uint32_t width, uint32_t height);
inline constexpr uint32_t kContactSheetGap = 2;
// The size of each of `cells` pictures side by side in `total` pixels with 2-px lines between them
// (a pixel the cells cannot share evenly goes to the lines); 1 at least. The pictures and their
// lines fit in `total` when total >= cells + (cells - 1) * kContactSheetGap.
inline uint32_t contactSheetCell(uint32_t total, uint32_t cells) {
  const uint32_t gaps = (cells - 1) * kContactSheetGap;
  return total > gaps + cells ? (total - gaps) / cells : 1u;
}

// The legend of a picture coloured by a dimension (`render --color NAME`), on a dark box in the
// top-right corner: the dimension's name, then a swatch and a label per category (legendLines), or
// for a ramp a bar from its p99 colour at the top to its p1 colour at the bottom between the two
// values. Text is twice as large on pictures 800 px wide or more; a picture too small for the box
// gets what fits (clipped).
void drawLegend(Image& image, const AttributeColoring& plan);

}  // namespace dpoint
