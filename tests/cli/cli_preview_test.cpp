// dpoint render's readable previews as a user gets them (issue #13): which sets are shaded and
// coloured by default, what --edl-strength does, and the labels of the --views 4 sheet. PNGs are
// decoded (stb_image) where a test looks at pixels; elsewhere whole files are compared.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "cli/cli_png.h"
#include "test_support.h"

// stb_image's implementation for cli_tests, after cli_png.h has declared it.
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

namespace dpoint {
namespace {

using test::concat;
using test::decodePng;
using test::Pixels;
using test::readFile;
using test::runDpoint;
using test::TempDir;
using test::writeFile;

// Renders `input` (200 x 160 unless asked) with the validation layer on; returns the PNG's bytes.
std::string render(const TempDir& dir, const std::string& input, const std::string& name,
                   const std::vector<std::string>& extra, int width = 200, int height = 160) {
  std::vector<std::string> args = {"render", input, "-o", dir.file(name), "--validate", "--width",
                                   std::to_string(width), "--height", std::to_string(height), "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  const test::CommandResult r = runDpoint(args);
  EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
  return readFile(dir.file(name));
}

// A 100 x 100 grid over the unit square, every z = 0: a 2D set (written as x,y).
std::string flatGrid() {
  std::string csv = "x,y\n";
  for (int i = 0; i < 100; ++i)
    for (int j = 0; j < 100; ++j) csv += std::to_string(i / 99.0) + "," + std::to_string(j / 99.0) + "\n";
  return csv;
}

// A 60 x 60 paraboloid y = x² + z² (y up, as the generators' sets), with white colours or none.
std::string paraboloid(bool white) {
  std::string csv = white ? "x,y,z,r,g,b\n" : "x,y,z\n";
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 60; ++j) {
      const double x = -1.0 + 2.0 * i / 59.0, z = -1.0 + 2.0 * j / 59.0;
      csv += std::to_string(x) + "," + std::to_string(x * x + z * z) + "," + std::to_string(z) + (white ? ",1,1,1\n" : "\n");
    }
  }
  return csv;
}

std::string mandelbulb(const TempDir& dir) {
  const std::string path = dir.file("mb.ply");
  EXPECT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "33", "--quiet", "-o", path}).exit_code, 0);
  return path;
}

// --shade auto follows the data: a 3D set keeps eye-dome lighting under --ortho (a survey seen from
// above still has relief), and --error still draws plain pixels there.
TEST(CliPreview, threeDimensionalSetSeenOrthographicallyIsShaded) {
  TempDir dir;
  const std::string mb = mandelbulb(dir);
  const std::vector<std::string> ortho = {"--ortho", "--point-size", "1"};
  // Binary PNGs compared with ==, so a failure does not print them.
  const std::string plain = render(dir, mb, "none.png", concat({"--shade", "none"}, ortho));
  const std::string edl = render(dir, mb, "edl.png", concat({"--shade", "edl"}, ortho));
  ASSERT_FALSE(edl == plain) << "EDL must show on this view for the test to mean anything";
  EXPECT_TRUE(render(dir, mb, "auto.png", ortho) == edl) << "--ortho on a 3D set: --shade auto is edl";
  EXPECT_TRUE(render(dir, mb, "error.png", concat({"--error"}, ortho)) == plain) << "--error draws plain pixels";
}

// A 2D set (every z = 0) is drawn plain by default: from the default view straight down and from
// an oblique --eye, where the tilted plane's depths would give EDL something to darken.
// (A 2D set is always drawn orthographically: no option asks for perspective on one.)
TEST(CliPreview, twoDimensionalSetIsPlainByDefaultFromAnyEye) {
  TempDir dir;
  writeFile(dir.file("flat.csv"), flatGrid());
  const std::string flat = dir.file("flat.csv");
  EXPECT_TRUE(render(dir, flat, "auto.png", {}) == render(dir, flat, "none.png", {"--shade", "none"}));
  const std::vector<std::string> eye = {"--eye", "0.5,-1.2,1.0", "--target", "0.5,0.5,0", "--up", "0,0,1"};
  const std::string plain = render(dir, flat, "eye_none.png", concat({"--shade", "none"}, eye));
  ASSERT_FALSE(render(dir, flat, "eye_edl.png", concat({"--shade", "edl"}, eye)) == plain)
      << "EDL must show on this view for the test to mean anything";
  EXPECT_TRUE(render(dir, flat, "eye_auto.png", eye) == plain) << "a 2D set from an oblique eye: --shade auto is none";
}

// A 3D set without colours is coloured by elevation by default, not left white.
TEST(CliPreview, threeDimensionalSetWithoutColoursDefaultsToElevation) {
  TempDir dir;
  writeFile(dir.file("bare.csv"), paraboloid(false));
  writeFile(dir.file("white.csv"), paraboloid(true));
  const std::vector<std::string> plain = {"--shade", "none", "--point-size", "1"};
  const std::string elevation = render(dir, dir.file("bare.csv"), "elevation.png", concat({"--color", "elevation"}, plain));
  EXPECT_TRUE(render(dir, dir.file("bare.csv"), "auto.png", plain) == elevation);
  EXPECT_FALSE(render(dir, dir.file("white.csv"), "white.png", plain) == elevation) << "elevation is not white";
}

// --edl-strength scales the darkening: every pixel is as dark or darker as the strength grows,
// and some strictly (the hole filling before it is the same at every strength). 0 (no darkening)
// is refused as a usage error.
TEST(CliPreview, edlStrengthDarkensMoreAsItGrows) {
  TempDir dir;
  const std::string mb = mandelbulb(dir);
  std::vector<Pixels> pictures;  // strengths 0.01, 0.25, 1 (the default), 4
  pictures.push_back(decodePng(render(dir, mb, "faint.png", {"--edl-strength", "0.01", "--point-size", "1"})));
  pictures.push_back(decodePng(render(dir, mb, "weak.png", {"--edl-strength", "0.25", "--point-size", "1"})));
  pictures.push_back(decodePng(render(dir, mb, "default.png", {"--point-size", "1"})));
  pictures.push_back(decodePng(render(dir, mb, "strong.png", {"--edl-strength", "4", "--point-size", "1"})));
  for (size_t k = 1; k < pictures.size(); ++k) {
    ASSERT_EQ(pictures[k].rgba.size(), pictures[0].rgba.size());
    size_t darker = 0;
    for (size_t i = 0; i < pictures[k].rgba.size(); ++i) {
      ASSERT_LE(pictures[k].rgba[i], pictures[k - 1].rgba[i]) << "picture " << k << " byte " << i;
      darker += pictures[k].rgba[i] < pictures[k - 1].rgba[i];
    }
    EXPECT_GT(darker, 0u) << "picture " << k << " is darker than the one before it";
  }
  const test::CommandResult zero = runDpoint({"render", mb, "-o", dir.file("zero.png"), "--edl-strength", "0"});
  EXPECT_EQ(zero.exit_code, 1);
  EXPECT_TRUE(test::contains(zero.err, "--edl-strength 0: must be in (0, 100]"));
  EXPECT_FALSE(test::fileExists(dir.file("zero.png")));
}

// Each quarter of the --views 4 sheet carries its label: the three-quarter view (bottom right)
// equals the same view drawn alone except on a dark strip at its top-left corner, whose light text
// is the label.
TEST(CliPreview, fourViewSheetLabelsEachViewOverItsPicture) {
  TempDir dir;
  const std::string mb = mandelbulb(dir);
  // --views 4 at 322 x 242 gives four 160 x 120 views and 2-px lines; the single view is drawn at that size.
  const Pixels sheet = decodePng(render(dir, mb, "views.png", {"--views", "4"}, 322, 242));
  const Pixels alone = decodePng(render(dir, mb, "alone.png", {}, 160, 120));
  ASSERT_EQ(sheet.width, 322) << "the size asked for";
  ASSERT_EQ(sheet.height, 242);
  const uint32_t strip = 0xff101010u, label = 0xfff2f2f2u;
  // Every quarter: a dark strip at its top-left corner with light glyphs on it.
  for (int quarter = 0; quarter < 4; ++quarter) {
    const int x0 = (quarter % 2) * (160 + 2), y0 = (quarter / 2) * (120 + 2);
    size_t strip_pixels = 0, label_pixels = 0;
    for (int y = y0; y < y0 + 15; ++y) {
      for (int x = x0; x < x0 + 40; ++x) {
        strip_pixels += sheet.at(x, y) == strip;
        label_pixels += sheet.at(x, y) == label;
      }
    }
    EXPECT_GT(strip_pixels, 100u) << "quarter " << quarter;
    EXPECT_GT(label_pixels, 20u) << "quarter " << quarter;
  }
  // The three-quarter view: what differs from the view alone is the label, on its strip.
  const int x0 = 160 + 2, y0 = 120 + 2;
  int right = 0, bottom = 0;
  size_t label_pixels = 0;
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      const uint32_t got = sheet.at(x0 + x, y0 + y);
      if (got == alone.at(x, y)) continue;
      EXPECT_TRUE(got == strip || got == label) << x << "," << y;
      label_pixels += got == label;
      right = std::max(right, x + 1), bottom = std::max(bottom, y + 1);
    }
  }
  EXPECT_GT(label_pixels, 100u) << "'three-quarter (MODE)' is a long label";
  EXPECT_LE(bottom, 15) << "the strip is one line of text high";
  EXPECT_GT(right, 60);
}

}  // namespace
}  // namespace dpoint
