#include "bench/montage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "image/picture_checks.h"

namespace dpoint {
namespace {

using namespace test;  // the pixel checks of image/picture_checks.h

constexpr double kLo = 1e-6, kHi = 100.0;

const uint32_t kBlack = rgba(0, 0, 0);
const uint32_t kMagenta = rgba(255, 0, 255);
const uint32_t kViridisLow = rgba(0x44, 0x01, 0x54);
const uint32_t kViridisHigh = rgba(0xfd, 0xe7, 0x25);
const uint32_t kMontageBackground = rgba(0x20, 0x20, 0x20);

WindowPoint at(double x, double y) { return {x, y, 0.5, true}; }

double luminance(uint32_t color) {
  return 0.2126 * double(color & 0xff) + 0.7152 * double(color >> 8 & 0xff) + 0.0722 * double(color >> 16 & 0xff);
}

TEST(Montage, heatMapPutsPointAtItsReferencePixel) {
  // (3.5, 2.25) lies inside pixel (3, 2); (5, 4) lies on a pixel corner, which ceil − 1 gives
  // to the pixel up and left, (4, 3), as rasterReference does.
  const Image heat = errorHeatMap({at(3.5, 2.25), at(5.0, 4.0)}, {0.01, 1.0}, 8, 6, kLo, kHi);
  ASSERT_EQ(heat.width, 8u);
  ASSERT_EQ(heat.height, 6u);
  EXPECT_EQ(pixel(heat, 3, 2), errorColor(0.01, kLo, kHi));
  EXPECT_EQ(pixel(heat, 4, 3), errorColor(1.0, kLo, kHi));
  EXPECT_NE(pixel(heat, 3, 2), pixel(heat, 4, 3));
  EXPECT_EQ(countColor(heat, kBlack), 8u * 6u - 2u);
}

TEST(Montage, heatMapLargestErrorWinsOnSharedPixel) {
  const std::vector<WindowPoint> shared = {at(1.5, 1.5), at(1.2, 1.7), at(1.9, 1.1)};
  EXPECT_EQ(pixel(errorHeatMap(shared, {0.1, 10.0, 1.0}, 4, 4, kLo, kHi), 1, 1), errorColor(10.0, kLo, kHi));
  EXPECT_EQ(pixel(errorHeatMap(shared, {10.0, 0.1, 1.0}, 4, 4, kLo, kHi), 1, 1), errorColor(10.0, kLo, kHi));
  EXPECT_EQ(pixel(errorHeatMap(shared, {1.0, 0.1, 10.0}, 4, 4, kLo, kHi), 1, 1), errorColor(10.0, kLo, kHi));
  // A lost point beats any number, before or after it.
  EXPECT_EQ(pixel(errorHeatMap(shared, {NAN, 1e9, 1.0}, 4, 4, kLo, kHi), 1, 1), kMagenta);
  EXPECT_EQ(pixel(errorHeatMap(shared, {1e9, 1.0, NAN}, 4, 4, kLo, kHi), 1, 1), kMagenta);
}

TEST(Montage, heatMapLostPointIsMagenta) {
  const Image heat = errorHeatMap({at(2.5, 0.5), at(0.5, 0.5)}, {NAN, 1e-3}, 3, 1, kLo, kHi);
  EXPECT_EQ(pixel(heat, 2, 0), kMagenta);
  EXPECT_EQ(errorColor(NAN, kLo, kHi), kMagenta);
  EXPECT_NE(pixel(heat, 0, 0), kMagenta);
  EXPECT_EQ(pixel(heat, 1, 0), kBlack);
}

TEST(Montage, heatMapClampsBelowLoAndAboveHi) {
  const Image heat = errorHeatMap({at(0.5, 0.5), at(1.5, 0.5), at(2.5, 0.5), at(3.5, 0.5), at(4.5, 0.5)},
                                  {0.0, -1.0, 1e-12, 1e6, INFINITY}, 5, 1, kLo, kHi);
  EXPECT_EQ(pixel(heat, 0, 0), kViridisLow);
  EXPECT_EQ(pixel(heat, 1, 0), kViridisLow);
  EXPECT_EQ(pixel(heat, 2, 0), kViridisLow);
  EXPECT_EQ(pixel(heat, 3, 0), kViridisHigh);
  EXPECT_EQ(pixel(heat, 4, 0), kViridisHigh);
  EXPECT_EQ(errorColor(kLo, kLo, kHi), kViridisLow);
  EXPECT_EQ(errorColor(kHi, kLo, kHi), kViridisHigh);
}

TEST(Montage, errorColorGetsBrighterWithEveryDecade) {
  double previous = -1.0;
  for (double e = kLo; e <= kHi * 1.0001; e *= 10.0) {
    const double y = luminance(errorColor(e, kLo, kHi));
    EXPECT_GT(y, previous) << "at " << e << " px";
    previous = y;
  }
  // Log scale: the middle decade of 1e-6..100 (1e-2) sits at the middle stop of viridis.
  EXPECT_EQ(errorColor(1e-2, kLo, kHi), rgba(0x21, 0x90, 0x8c));
}

TEST(Montage, heatMapSkipsInvisiblePoints) {
  WindowPoint hidden = at(1.5, 1.5);
  hidden.visible = false;
  // Visible but outside the image (a caller may pass a smaller image): skipped, not wrapped.
  const Image heat = errorHeatMap({hidden, at(5.5, 1.5), at(1.5, 9.0), at(0.0, 1.0)}, {NAN, NAN, NAN, NAN}, 4, 4,
                                  kLo, kHi);
  EXPECT_EQ(countColor(heat, kBlack), 16u);
}

// Tile i: a picture of one flat colour, and a heat map of one point at a mid-range error.
std::vector<MontageTile> syntheticTiles(size_t count, uint32_t width, uint32_t height) {
  std::vector<MontageTile> tiles;
  for (size_t i = 0; i < count; ++i) {
    MontageTile tile;
    tile.label = "mode " + std::to_string(i);
    tile.caption = "max " + std::to_string(i * 10) + " px, " + std::to_string(i) + " lost";
    tile.picture = filled(width, height, rgba(40 + uint32_t(i) * 30, 200, 90));
    tile.heat = errorHeatMap({at(width / 2.0, height / 2.0)}, {double(i + 1) * 1e-3}, width, height, kLo, kHi);
    tiles.push_back(std::move(tile));
  }
  return tiles;
}

TEST(Montage, montageIsWideEnoughForEveryTile) {
  const std::vector<MontageTile> tiles = syntheticTiles(3, 50, 40);
  const Image montage = composeMontage("t", tiles, kLo, kHi);
  EXPECT_GE(montage.width, 3u * 50u + 2u * 8u);
  EXPECT_GE(montage.height, 2u * 40u);
  // Every picture lands whole: no tile is cut or overlaps another.
  for (const MontageTile& tile : tiles) EXPECT_EQ(countColor(montage, pixel(tile.picture, 0, 0)), 50u * 40u);
}

// First row and column where `color` occurs, scanning rows from the top.
bool find(const Image& image, uint32_t color, uint32_t& x_out, uint32_t& y_out) {
  for (uint32_t y = 0; y < image.height; ++y) {
    for (uint32_t x = 0; x < image.width; ++x) {
      if (pixel(image, x, y) == color) {
        x_out = x, y_out = y;
        return true;
      }
    }
  }
  return false;
}

bool bandDiffers(const Image& a, const Image& b, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1) {
  for (uint32_t y = y0; y < y1; ++y) {
    for (uint32_t x = x0; x < x1; ++x) {
      if (pixel(a, x, y) != pixel(b, x, y)) return true;
    }
  }
  return false;
}

TEST(Montage, montageWrapsALongCaptionAfterItsCommaInsideItsColumn) {
  std::vector<MontageTile> tiles = syntheticTiles(3, 256, 64);
  const Image short_captions = composeMontage("t", tiles, kLo, kHi);
  // 23 characters at scale 2 are wider than 256 px: a second line, not a smaller font.
  tiles[1].caption = "max 9.95e-05 px, 0 lost";
  const Image long_caption = composeMontage("t", tiles, kLo, kHi);
  uint32_t x = 0, y_short = 0, y_long = 0;
  ASSERT_TRUE(find(short_captions, pixel(tiles[1].picture, 0, 0), x, y_short));
  ASSERT_TRUE(find(long_caption, pixel(tiles[1].picture, 0, 0), x, y_long));
  EXPECT_EQ(y_long, y_short + 24);  // one more line of 12 units at scale 2
  // The second line holds the text after the comma.
  std::vector<MontageTile> first_line_only = tiles;
  first_line_only[1].caption = "max 9.95e-05 px,";
  const Image first_line = composeMontage("t", first_line_only, kLo, kHi);
  EXPECT_TRUE(bandDiffers(long_caption, first_line, x, y_long - 24, x + 256, y_long));
  EXPECT_FALSE(bandDiffers(long_caption, first_line, x, y_long - 48, x + 256, y_long - 24));
  // Nothing spills into the gaps between the columns.
  for (uint32_t gap_x : {x - 8, x + 256}) {
    for (uint32_t y = 0; y < y_long; ++y) {
      for (uint32_t dx = 0; dx < 8; ++dx) ASSERT_EQ(pixel(long_caption, gap_x + dx, y), kMontageBackground);
    }
  }
}

TEST(Montage, montageOfSixTilesShowsTitleLabelsPicturesAndColourBar) {
  const std::vector<MontageTile> tiles = syntheticTiles(6, 160, 120);
  std::vector<MontageTile> unlabelled = tiles;
  for (MontageTile& tile : unlabelled) tile.label.clear(), tile.caption.clear();
  const Image montage = composeMontage("Menger sponge, 1e9 zoom", tiles, kLo, kHi);
  const Image blank = composeMontage("", unlabelled, kLo, kHi);
  ASSERT_EQ(montage.width, blank.width);
  ASSERT_EQ(montage.height, blank.height);
  EXPECT_GE(montage.width, 6u * 160u + 5u * 8u);
  EXPECT_GE(montage.height, 2u * 120u + 4u);
  EXPECT_EQ(pixel(montage, 0, 0), kMontageBackground);

  uint32_t first_x = 0, first_y = 0;
  ASSERT_TRUE(find(montage, pixel(tiles[0].picture, 0, 0), first_x, first_y));
  // The title sits above the tiles' text.
  EXPECT_TRUE(bandDiffers(montage, blank, 0, 0, montage.width, first_y - 24));
  for (const MontageTile& tile : tiles) {
    uint32_t x = 0, y = 0;
    ASSERT_TRUE(find(montage, pixel(tile.picture, 0, 0), x, y));
    EXPECT_EQ(y, first_y);  // one row
    // Label and caption in the two lines over the picture, inside the tile's column.
    EXPECT_TRUE(bandDiffers(montage, blank, x, y - 24, x + 160, y - 12)) << tile.label;
    EXPECT_TRUE(bandDiffers(montage, blank, x, y - 12, x + 160, y)) << tile.caption;
    EXPECT_FALSE(bandDiffers(montage, blank, x, y, x + 160, y + 2 * 120)) << "text over " << tile.label;
  }
  // The heat maps hold no lost point and neither end of the map, so these come from the
  // colour bar and its swatch.
  EXPECT_GT(countColor(montage, kMagenta), 0u);
  EXPECT_GT(countColor(montage, kViridisLow), 0u);
  EXPECT_GT(countColor(montage, kViridisHigh), 0u);
}

}  // namespace
}  // namespace dpoint
