// The picture room (image/): PNG output, pixel comparison, text and the --views contact sheet.
#include "image/canvas.h"
#include "image/image.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "image/picture_checks.h"
#include "test_support.h"

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

namespace dpoint {
namespace {

using namespace test;  // the pixel checks of image/picture_checks.h

const uint32_t kBlack = rgba(0, 0, 0);

TEST(Image, countDifferingPixelsCountsPixelsNotBytes) {
  Image a{3, 2, std::vector<uint8_t>(24, 7)};
  Image b = a;
  EXPECT_EQ(countDifferingPixels(a, b), 0u);
  b.rgba[0] = 1, b.rgba[3] = 1;  // two bytes of pixel 0
  b.rgba[23] = 1;                // alpha of the last pixel
  EXPECT_EQ(countDifferingPixels(a, b), 2u);
}

Image testImage() {
  Image image{5, 3, {}};
  for (uint32_t i = 0; i < 5 * 3 * 4; ++i) image.rgba.push_back(static_cast<uint8_t>(i * 37 + 11));
  return image;
}

TEST(Image, writePngRoundTripsEveryByte) {
  TempDir dir;
  const Image image = testImage();
  const std::string path = dir.file("out.png");
  const Status status = writePng(path, image);
  ASSERT_TRUE(status.ok()) << status.error().message;
  int width = 0, height = 0, channels = 0;
  unsigned char* pixels = stbi_load(path.c_str(), &width, &height, &channels, 4);
  ASSERT_NE(pixels, nullptr) << stbi_failure_reason();
  EXPECT_EQ(width, 5);
  EXPECT_EQ(height, 3);
  EXPECT_EQ(channels, 4);
  EXPECT_EQ(std::vector<uint8_t>(pixels, pixels + image.rgba.size()), image.rgba);
  stbi_image_free(pixels);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.png"});
}

// Pictures of many pieces (the encoder deflates about 64 KiB of rows a piece, on all cores, as
// one zlib stream): opaque (written as RGB) and with alpha, one row wider than a piece, every
// byte back through an independent decoder (stb_image, which checks the stream's Adler-32 only
// in part: the byte count and every pixel are checked here).
TEST(Image, writePngOfManyPiecesRoundTripsEveryByte) {
  TempDir dir;
  struct Case {
    uint32_t width, height;
    bool opaque;
  };
  for (const Case& c : {Case{1024, 768, true}, Case{333, 517, false}, Case{20000, 3, true}, Case{1, 70000, false}}) {
    SCOPED_TRACE(std::to_string(c.width) + "x" + std::to_string(c.height));
    Image image{c.width, c.height, std::vector<uint8_t>(size_t{c.width} * c.height * 4)};
    for (size_t i = 0; i < image.rgba.size(); ++i) {
      const size_t pixel = i / 4, x = pixel % c.width;
      // Runs (a render's background) beside noise, so both kinds of match and literal occur.
      image.rgba[i] = i % 4 == 3 ? (c.opaque ? 255 : static_cast<uint8_t>(pixel * 7))
                    : x < c.width / 2 ? static_cast<uint8_t>(x / 64)
                                      : static_cast<uint8_t>((i * 2654435761u) >> 13);
    }
    const std::string path = dir.file("many.png");
    ASSERT_TRUE(writePng(path, image).ok());
    int width = 0, height = 0, channels = 0;
    unsigned char* pixels = stbi_load(path.c_str(), &width, &height, &channels, 4);
    ASSERT_NE(pixels, nullptr) << stbi_failure_reason();
    EXPECT_EQ(uint32_t(width), c.width);
    EXPECT_EQ(uint32_t(height), c.height);
    EXPECT_EQ(channels, c.opaque ? 3 : 4);
    EXPECT_TRUE(std::vector<uint8_t>(pixels, pixels + image.rgba.size()) == image.rgba);
    stbi_image_free(pixels);
    // The same picture gives the same bytes (the pieces do not depend on the threads).
    Result<std::vector<unsigned char>> again = pngBytes(image, "again");
    ASSERT_TRUE(again.ok());
    const std::string file = readFile(path);
    EXPECT_TRUE(std::string(again->begin(), again->end()) == file);
  }
}

TEST(Image, writePngFailureNamesThePathAndLeavesNothing) {
  TempDir dir;
  const std::string missing = dir.file("no-such-folder/out.png");
  const Status status = writePng(missing, testImage());
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find(missing), std::string::npos) << status.error().message;
  EXPECT_TRUE(dir.entries().empty());
  const Status folder = writePng(dir.path(), testImage());
  ASSERT_FALSE(folder.ok());
  EXPECT_NE(folder.error().message.find(dir.path()), std::string::npos) << folder.error().message;
  EXPECT_TRUE(dir.entries().empty());
  // An empty image is refused before anything is created.
  const Status empty = writePng(dir.file("empty.png"), Image{});
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.error().message.find("empty.png"), std::string::npos);
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Canvas, drawTextMarksPixelsAndClipsAtEdges) {
  const uint32_t white = rgba(255, 255, 255);
  Image image = filled(40, 20, kBlack);
  const int width = drawText(image, 2, 3, "Hi", white, 1);
  EXPECT_EQ(width, textWidth("Hi", 1));
  const size_t marked = countColor(image, white);
  EXPECT_GT(marked, 10u);
  for (uint32_t y = 0; y < image.height; ++y) {
    for (uint32_t x = 0; x < image.width; ++x) {
      if (pixel(image, x, y) != white) continue;
      EXPECT_GE(x, 2u);
      EXPECT_LT(x, 2u + uint32_t(width));
      EXPECT_GE(y, 3u);
      EXPECT_LT(y, 3u + 12u);
    }
  }
  // Twice the scale, four times the pixels.
  Image doubled = filled(80, 40, kBlack);
  EXPECT_EQ(drawText(doubled, 4, 6, "Hi", white, 2), 2 * width);
  EXPECT_EQ(countColor(doubled, white), 4 * marked);

  // Across every edge: only what lies inside is drawn, and the width is the text's, not the cut.
  Image small = filled(6, 6, kBlack);
  EXPECT_EQ(drawText(small, -5, -4, "WWW", white, 2), textWidth("WWW", 2));
  EXPECT_GT(countColor(small, white), 0u);
  EXPECT_LT(countColor(small, white), 36u);
  Image outside = filled(6, 6, kBlack);
  drawText(outside, 7, 0, "W", white, 1);
  drawText(outside, 0, -30, "W", white, 1);
  drawText(outside, -100, 0, "W", white, 1);
  EXPECT_EQ(countColor(outside, kBlack), 36u);
}

// Which units of a 6×7 cell one character lights at scale 1, row by row ('#': lit).
std::vector<std::string> glyphRows(char c) {
  const uint32_t white = rgba(255, 255, 255);
  Image image = filled(6, 7, kBlack);
  drawText(image, 0, 0, std::string(1, c), white, 1);
  std::vector<std::string> rows(7, std::string(6, '.'));
  for (uint32_t y = 0; y < 7; ++y)
    for (uint32_t x = 0; x < 6; ++x)
      if (pixel(image, x, y) == white) rows[y][x] = '#';
  return rows;
}

TEST(Canvas, zeroDiffersFromEightInItsSidesAndMiddle) {
  // stb_easy_font's own 0 differs from its 8 in 4 units, all in the middle: it read as 8.
  const std::vector<std::string> zero = glyphRows('0'), eight = glyphRows('8');
  size_t differing = 0;
  for (size_t y = 0; y < 7; ++y)
    for (size_t x = 0; x < 6; ++x) differing += zero[y][x] != eight[y][x];
  EXPECT_GE(differing, 10u) << ::testing::PrintToString(zero) << " against " << ::testing::PrintToString(eight);
  // Its sides run unbroken from the second row to the sixth, where 8 pinches in at its waist.
  for (size_t y = 1; y <= 5; ++y) EXPECT_EQ(zero[y][0], '#') << "row " << y;
  EXPECT_EQ(eight[3][0], '.');
  // Still the same advance, so labels keep their widths.
  EXPECT_EQ(textWidth("0", 1), textWidth("8", 1));
  // And not the letter O, which has no slash through its middle.
  EXPECT_NE(zero, glyphRows('O'));
}

TEST(Canvas, textWidthTakesTheWidestLineAndDrawsUnprintableAsQuestionMark) {
  EXPECT_EQ(textWidth("ab\nabcd", 1), textWidth("abcd", 1));
  EXPECT_EQ(textWidth("abcd", 3), 3 * textWidth("abcd", 1));
  EXPECT_EQ(textWidth("", 1), 0);
  EXPECT_EQ(textWidth("a\tb", 1), textWidth("a?b", 1));
  Image tab = filled(30, 12, kBlack), question = filled(30, 12, kBlack);
  drawText(tab, 0, 0, "\t\x80", rgba(255, 255, 255), 1);
  drawText(question, 0, 0, "??", rgba(255, 255, 255), 1);
  EXPECT_EQ(tab.rgba, question.rgba);
}

// dpoint render --views 4's sheet: each view's label is drawn, pixel for pixel as drawText draws it,
// on a dark strip over its picture's top-left corner; the rest of each picture and the 2-px gaps
// between them are untouched.
TEST(Canvas, contactSheetDrawsEachLabelOnAStripOverItsPicture) {
  const uint32_t strip = rgba(0x10, 0x10, 0x10), label = rgba(0xf2, 0xf2, 0xf2), gap = rgba(0x20, 0x20, 0x20);
  const uint32_t w = 120, h = 80;
  std::vector<LabelledView> views = {{"front (fp32)", filled(w, h, rgba(200, 0, 0))},
                                     {"side (native)", filled(w, h, rgba(0, 200, 0))},
                                     {"top (df64)", filled(w, h, rgba(0, 0, 200))},
                                     {"three-quarter (rte)", filled(w, h, rgba(200, 200, 0))}};
  const Image sheet = composeContactSheet(views, 2);
  ASSERT_EQ(sheet.width, 2 * w + 2);
  ASSERT_EQ(sheet.height, 2 * h + 2);
  for (size_t i = 0; i < views.size(); ++i) {
    SCOPED_TRACE(views[i].label);
    // Pictures under 400 px wide get scale-1 text, 3 px in from the corner and the strip's edges.
    Image glyphs = filled(w, h, kBlack);
    drawText(glyphs, 3, 3, views[i].label, label, 1);
    const uint32_t strip_w = uint32_t(textWidth(views[i].label, 1)) + 6, strip_h = kTextGlyphUnits + 6;
    const uint32_t x0 = uint32_t(i % 2) * (w + 2), y0 = uint32_t(i / 2) * (h + 2);
    size_t label_pixels = 0;
    for (uint32_t y = 0; y < h; ++y) {
      for (uint32_t x = 0; x < w; ++x) {
        const uint32_t want = pixel(glyphs, x, y) == label     ? label
                              : x < strip_w && y < strip_h ? strip
                                                            : pixel(views[i].picture, x, y);
        ASSERT_EQ(pixel(sheet, x0 + x, y0 + y), want) << x << "," << y;
        label_pixels += want == label;
      }
    }
    EXPECT_GT(label_pixels, views[i].label.size()) << "several pixels a glyph";
  }
  for (uint32_t y = 0; y < sheet.height; ++y) EXPECT_EQ(pixel(sheet, w, y), gap) << y;
  for (uint32_t x = 0; x < sheet.width; ++x) EXPECT_EQ(pixel(sheet, x, h + 1), gap) << x;
}


// A sheet asked for at a size is that size: the lines take the pixels the pictures leave, so an
// odd width or height widens one line, and each picture sits whole at its place.
TEST(Canvas, contactSheetAtASizeIsThatSizeAndKeepsEveryPicture) {
  const uint32_t gap = rgba(0x20, 0x20, 0x20);
  EXPECT_EQ(contactSheetCell(800, 2), 399u);
  EXPECT_EQ(contactSheetCell(801, 2), 399u);
  EXPECT_EQ(contactSheetCell(4, 2), 1u);
  const uint32_t w = contactSheetCell(81, 2), h = contactSheetCell(60, 2);
  std::vector<LabelledView> views;
  for (int i = 0; i < 4; ++i) views.push_back({"", filled(w, h, rgba(uint8_t(50 * (i + 1)), 0, 0))});
  const Image sheet = composeContactSheet(views, 2, 81, 60);
  ASSERT_EQ(sheet.width, 81u);
  ASSERT_EQ(sheet.height, 60u);
  for (int i = 0; i < 4; ++i) {
    const uint32_t x0 = (i % 2) ? 81 - w : 0, y0 = (i / 2) ? 60 - h : 0;  // the last cell ends at the edge
    EXPECT_EQ(pixel(sheet, x0 + w / 2, y0 + h / 2), rgba(uint8_t(50 * (i + 1)), 0, 0)) << i;
    EXPECT_EQ(pixel(sheet, x0 + w - 1, y0 + h - 1), rgba(uint8_t(50 * (i + 1)), 0, 0)) << i;
  }
  for (uint32_t x = w; x < 81 - w; ++x) EXPECT_EQ(pixel(sheet, x, 0), gap) << "a 3-px line: " << x;
  EXPECT_EQ(81 - 2 * w, 3u);
}

}  // namespace
}  // namespace dpoint
