#include <gtest/gtest.h>
#include <mpfr.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <thread>
#include <utility>

#include "generators/mandelbrot2d.h"

namespace dpoint {
namespace {

// Exact reference: every pixel iterated in MPFR at kMpfrBits from c = centre + offset (the exact
// sum of two doubles, which 256 bits hold for any centre and offset used here). 256 bits gave the
// same counts as 512 bits on these grids when this test was written.
constexpr mpfr_prec_t kMpfrBits = 256;

uint32_t mpfrCount(double center_x, double offset_x, double center_y, double offset_y, int max_iter,
                   mpfr_prec_t bits = kMpfrBits) {
  mpfr_t cx, cy, x, y, x2, y2, t;
  for (mpfr_ptr v : {cx, cy, x, y, x2, y2, t}) mpfr_init2(v, bits);
  mpfr_set_d(cx, center_x, MPFR_RNDN);
  mpfr_add_d(cx, cx, offset_x, MPFR_RNDN);
  mpfr_set_d(cy, center_y, MPFR_RNDN);
  mpfr_add_d(cy, cy, offset_y, MPFR_RNDN);
  for (mpfr_ptr v : {x, y, x2, y2}) mpfr_set_zero(v, 1);
  uint32_t count = static_cast<uint32_t>(max_iter);
  for (int n = 0; n < max_iter; ++n) {
    mpfr_mul(t, x, y, MPFR_RNDN);
    mpfr_mul_2ui(t, t, 1, MPFR_RNDN);
    mpfr_add(y, t, cy, MPFR_RNDN);
    mpfr_sub(x, x2, y2, MPFR_RNDN);
    mpfr_add(x, x, cx, MPFR_RNDN);
    mpfr_sqr(x2, x, MPFR_RNDN);
    mpfr_sqr(y2, y, MPFR_RNDN);
    mpfr_add(t, x2, y2, MPFR_RNDN);
    if (mpfr_cmp_ui(t, 4) > 0) {
      count = static_cast<uint32_t>(n);
      break;
    }
  }
  for (mpfr_ptr v : {cx, cy, x, y, x2, y2, t}) mpfr_clear(v);
  return count;
}

void mpfrRows(const Mandelbrot2dParams& p, int row_begin, int row_end, std::vector<uint32_t>& counts) {
  const double spacing = p.width / p.resolution;
  for (int row = row_begin; row < row_end; ++row) {
    for (int col = 0; col < p.resolution; ++col) {
      counts[static_cast<size_t>(row) * static_cast<size_t>(p.resolution) + static_cast<size_t>(col)] =
          mpfrCount(p.center_x, (col + 0.5 - p.resolution / 2.0) * spacing, p.center_y,
                    (row + 0.5 - p.resolution / 2.0) * spacing, *p.max_iter);
    }
  }
  mpfr_free_cache();
}

// Same layout as mandelbrot2dCounts; two threads, halves of the rows.
std::vector<uint32_t> mpfrCounts(const Mandelbrot2dParams& p) {
  std::vector<uint32_t> counts(static_cast<size_t>(p.resolution) * static_cast<size_t>(p.resolution));
  const int half = p.resolution / 2;
  std::thread other(mpfrRows, std::cref(p), 0, half, std::ref(counts));
  mpfrRows(p, half, p.resolution, counts);
  other.join();
  return counts;
}

double agreement(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
  size_t equal = 0;
  for (size_t i = 0; i < a.size(); ++i) equal += a[i] == b[i];
  return static_cast<double>(equal) / static_cast<double>(a.size());
}

struct Agreement {
  double perturbation = 0.0;
  double plain_double = 0.0;
};

// Shares of a 64² grid (max_iter 2000, the old default) whose counts equal the exact ones, for both
// methods. The exact grid costs up to a second on two cores.
Agreement compareWithMpfr(double center_x, double center_y, double width) {
  Mandelbrot2dParams p;
  p.center_x = center_x;
  p.center_y = center_y;
  p.width = width;
  p.resolution = 64;
  p.max_iter = 2000;
  const std::vector<uint32_t> exact = mpfrCounts(p);
  Result<std::vector<uint32_t>> perturbed = mandelbrot2dCounts(p);
  p.method = Mandelbrot2dMethod::kDouble;
  Result<std::vector<uint32_t>> plain = mandelbrot2dCounts(p);
  EXPECT_TRUE(perturbed.ok() && plain.ok());
  if (!perturbed.ok() || !plain.ok()) return {};
  const Agreement a{agreement(*perturbed, exact), agreement(*plain, exact)};
  std::printf("[ mandelbrot2d ] centre %.17g,%.17g width %g: counts equal to MPFR: perturbation %.2f%%, "
              "plain double %.2f%%\n",
              center_x, center_y, width, 100.0 * a.perturbation, 100.0 * a.plain_double);
  return a;
}

constexpr double kStudyX = -0.7436450, kStudyY = 0.1318259;  // the study's deep-zoom centre

TEST(Mandelbrot2d, matchesMpfrAtWidth1em6) {
  const Agreement a = compareWithMpfr(kStudyX, kStudyY, 1e-6);
  EXPECT_GE(a.perturbation, 0.99);
  // Why perturbation is used at every width: plain double already falls short here (98.6%).
  EXPECT_LT(a.plain_double, 0.99);
}

TEST(Mandelbrot2d, matchesMpfrAtWidth1em9) {
  const Agreement a = compareWithMpfr(kStudyX, kStudyY, 1e-9);
  EXPECT_GE(a.perturbation, 0.99);
  EXPECT_LT(a.plain_double, 0.99);
}

TEST(Mandelbrot2d, matchesMpfrAtWidth1em12) {
  // At this width the study's centre lies far from the set's boundary (counts 420..421), so plain
  // double gets this view right too; the next test has detail at 1e-12.
  EXPECT_GE(compareWithMpfr(kStudyX, kStudyY, 1e-12).perturbation, 0.99);
}

TEST(Mandelbrot2d, doubleIterationFailsAtWidth1em12WithDetail) {
  // A centre near the boundary (counts 654..1658 in view): pixel spacing 1.6e-14 is 140 ulps of
  // the centre, and plain double gets 18% of the counts wrong.
  const Agreement a = compareWithMpfr(-0.7436450004729, 0.131825899748, 1e-12);
  EXPECT_GE(a.perturbation, 0.99);
  EXPECT_LT(a.plain_double, 0.99);
}

TEST(Mandelbrot2d, matchesMpfrBelowTheCentresUlp) {
  // Pixel spacing 1.6e-18, 1/70 of an ulp of the centre: the positions collapse onto a few
  // doubles, plain double sees almost one point, the exact offsets still separate every pixel.
  const Agreement a = compareWithMpfr(-0.74364500047299253, 0.13182589974829875, 1e-16);
  EXPECT_GE(a.perturbation, 0.99);
  EXPECT_LT(a.plain_double, 0.5);
}

TEST(Mandelbrot2d, handlesACentreOutsideTheSet) {
  // The centre escapes within a few steps while much of the view is inside: the reference moves to
  // a probe that lasts. Then a centre with |c| > 4 (its orbit is not iterated in fixed point) and a
  // view that reaches the set.
  Mandelbrot2dParams p;
  p.center_x = -0.75;
  p.center_y = 0.3;
  p.width = 0.5;
  p.resolution = 32;
  p.max_iter = 300;
  Result<std::vector<uint32_t>> counts = mandelbrot2dCounts(p);
  ASSERT_TRUE(counts.ok());
  EXPECT_LT((*counts)[16 * 32 + 16], 20u);
  EXPECT_GT(std::count(counts->begin(), counts->end(), 300u), 100);
  EXPECT_GE(agreement(*counts, mpfrCounts(p)), 0.99);

  p.center_x = 5.0;
  p.center_y = 0.0;
  p.width = 16.0;
  counts = mandelbrot2dCounts(p);
  ASSERT_TRUE(counts.ok());
  EXPECT_GT(std::count(counts->begin(), counts->end(), 300u), 0);
  EXPECT_GE(agreement(*counts, mpfrCounts(p)), 0.99);

  // A view whose only pixel in the set is 100 away from the centre: c = (100 − 100.125)·(1 + i).
  p.center_x = 100.0;
  p.center_y = 100.0;
  p.width = 400.5;
  p.resolution = 2;
  counts = mandelbrot2dCounts(p);
  ASSERT_TRUE(counts.ok());
  EXPECT_EQ(*counts, (std::vector<uint32_t>{300, 0, 0, 0}));
  p.center_y = 0.0;
  p.resolution = 32;

  // The widest view allowed: every pixel is far outside and escapes at once (no overflow to NaN).
  p.center_x = 0.0;
  p.width = 1e300;
  counts = mandelbrot2dCounts(p);
  ASSERT_TRUE(counts.ok());
  EXPECT_EQ(*counts, std::vector<uint32_t>(32 * 32, 0u));
}

TEST(Mandelbrot2d, deepestWidthKeepsTheCentresCount) {
  // Width 1e-300: offsets near 1e-302, a 1088-bit reference. The view is far inside one count band
  // of the centre (the 420/421 boundary passes within 1e-12 of it, not within 1e-300).
  Mandelbrot2dParams p;
  p.width = 1e-300;
  p.resolution = 16;
  p.max_iter = 2000;
  Result<std::vector<uint32_t>> counts = mandelbrot2dCounts(p);
  ASSERT_TRUE(counts.ok());
  const uint32_t centre = mpfrCount(p.center_x, 0.0, p.center_y, 0.0, *p.max_iter);
  EXPECT_EQ(centre, 421u);
  EXPECT_EQ(*counts, std::vector<uint32_t>(256, centre));
}

TEST(Mandelbrot2d, countsFollowTheDefinition) {
  // c near 0.5: z = 0.5, 0.75, 1.06, 1.63, 3.15: |z_5|² > 4 first, so count 4 (0-based: the n
  // with z_{n+1} outside). c near 3: count 0. Near 0 and -1.75 (in the set): max_iter.
  for (Mandelbrot2dMethod method : {Mandelbrot2dMethod::kDouble, Mandelbrot2dMethod::kPerturbation}) {
    for (auto [cx, expected] : {std::pair{0.5, 4u}, {3.0, 0u}, {0.0, 50u}, {-1.75, 50u}}) {
      Mandelbrot2dParams p;
      p.center_x = cx;
      p.center_y = 0.0;
      p.width = 1e-9;
      p.resolution = 2;
      p.max_iter = 50;
      p.method = method;
      Result<std::vector<uint32_t>> counts = mandelbrot2dCounts(p);
      ASSERT_TRUE(counts.ok());
      EXPECT_EQ(*counts, std::vector<uint32_t>(4, expected)) << "c = " << cx;
    }
  }
}

TEST(Mandelbrot2d, identicalForOneAndTwoThreads) {
  for (double width : {1e-6, 1e-12}) {
    Mandelbrot2dParams p;
    p.width = width;
    p.resolution = 96;
    p.max_iter = 500;
    p.threads = 1;
    Result<PointSet> one = generateMandelbrot2d(p);
    p.threads = 2;
    Result<PointSet> two = generateMandelbrot2d(p);
    ASSERT_TRUE(one.ok() && two.ok());
    EXPECT_TRUE(one->positions == two->positions);
    EXPECT_TRUE(one->colors == two->colors);
  }
}

TEST(Mandelbrot2d, gridIsCentredRowMajorAndCorrectlyRounded) {
  Mandelbrot2dParams p;
  p.width = 1e-12;
  p.resolution = 16;
  p.max_iter = 100;
  Result<PointSet> set = generateMandelbrot2d(p);
  ASSERT_TRUE(set.ok());
  ASSERT_EQ(set->size(), 256u);
  ASSERT_EQ(set->colors.size(), 256u);
  EXPECT_TRUE(set->isPlanar());
  EXPECT_TRUE(set->triangles.empty());
  const double spacing = 1e-12 / 16;
  for (int row = 0; row < 16; ++row) {
    for (int col = 0; col < 16; ++col) {
      const glm::dvec3& q = set->positions[static_cast<size_t>(row * 16 + col)];
      EXPECT_EQ(q.x, p.center_x + (col - 7.5) * spacing);
      EXPECT_EQ(q.y, p.center_y + (row - 7.5) * spacing);
    }
  }
  // Symmetric about the centre to within the rounding of the sums (half an ulp each).
  const glm::dvec3 first = set->positions.front(), last = set->positions.back();
  EXPECT_NEAR((first.x + last.x) / 2, p.center_x, 2e-16);
  EXPECT_NEAR((first.y + last.y) / 2, p.center_y, 2e-16);
  EXPECT_NEAR(last.x - first.x, 15 * spacing, 2e-16);
}

TEST(Mandelbrot2d, paletteIsInRangeSmoothAndSpansItsStops) {
  for (int i = 0; i <= 1000; ++i) {
    const float f = static_cast<float>(i) / 1000.0f;
    const glm::vec3 c = mandelbrot2dPalette(f);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(c[k], 0.0f);
      EXPECT_LE(c[k], 1.0f);
    }
    EXPECT_GT(c.r + c.g + c.b, 0.0f) << f;  // only points inside are black
    // Nearby positions get nearby colours (piecewise linear: at most 4 stops' steps per unit).
    const glm::vec3 d = mandelbrot2dPalette(std::min(1.0f, f + 0.001f)) - c;
    EXPECT_LT(std::abs(d.r) + std::abs(d.g) + std::abs(d.b), 0.02f) << f;
  }
  // From dark blue to dark red, not cyclic: the ends differ.
  EXPECT_EQ(mandelbrot2dPalette(0.0f), glm::vec3(0.02f, 0.05f, 0.35f));
  const glm::vec3 top = mandelbrot2dPalette(1.0f);
  EXPECT_NEAR(top.r, 0.30f, 1e-6f);
  EXPECT_NEAR(top.g, 0.05f, 1e-6f);
  EXPECT_NEAR(top.b, 0.10f, 1e-6f);
  EXPECT_EQ(mandelbrot2dPalette(-1.0f), mandelbrot2dPalette(0.0f));
  EXPECT_EQ(mandelbrot2dPalette(2.0f), mandelbrot2dPalette(1.0f));
}

TEST(Mandelbrot2d, insideIsBlackAndOutsideIsNot) {
  Mandelbrot2dParams p;
  p.resolution = 64;
  p.max_iter = 300;
  Result<Mandelbrot2dEscapes> escapes = mandelbrot2dEscapes(p);
  Result<PointSet> set = generateMandelbrot2d(p);
  ASSERT_TRUE(escapes.ok() && set.ok());
  size_t inside = 0;
  for (size_t i = 0; i < set->size(); ++i) {
    const glm::vec3 c = set->colors[i];
    if (escapes->counts[i] == 300u) {
      ++inside;
      EXPECT_EQ(c, glm::vec3(0.0f)) << i;
      EXPECT_EQ(escapes->tails[i].z2, 0.0);
    } else {
      EXPECT_GT(c.r + c.g + c.b, 0.0f) << i;
      EXPECT_GT(escapes->tails[i].z2, kTailRadius2) << i;  // the tails all reach the radius here
    }
  }
  EXPECT_GT(inside, 100u);
}

TEST(Mandelbrot2d, autoMaxIterGrowsWithDepthFromTheOldDefault) {
  // Never below the old default 2000 at shallow widths; 2000 exactly down to 1.9e-6.
  for (double width : {1e3, 4.0, 3.0, 1.0, 1e-3, 1.9e-6})
    EXPECT_EQ(autoMaxIter(width), 2000) << width;
  // max(2000, 50·d²), d = log10(4 / width): the values the header and --help name.
  EXPECT_EQ(autoMaxIter(1e-6), 2179);
  EXPECT_EQ(autoMaxIter(1e-9), 4610);
  EXPECT_EQ(autoMaxIter(1e-12), 7941);
  EXPECT_EQ(autoMaxIter(1e-15), 12171);
  EXPECT_NEAR(autoMaxIter(1e-300), 4518081, 1);
  int previous = 0;
  for (double width = 4.0; width >= 1e-300; width /= 10.0) {
    const int iter = autoMaxIter(width);
    EXPECT_GE(iter, previous) << width;
    if (width < 1e-6) {
      EXPECT_GT(iter, previous) << width;
    }
    previous = iter;
  }
  // Where 4 / width overflows (subnormal widths, below what a generation accepts) it stays finite.
  EXPECT_GT(autoMaxIter(1e-320), 4700000);
  EXPECT_LT(autoMaxIter(1e-320), 4800000);
}

TEST(Mandelbrot2d, maxIterResolvesAutoAndChecksTheRest) {
  Mandelbrot2dParams p;
  p.width = 1e-12;
  EXPECT_FALSE(p.max_iter.has_value()) << "auto is the default";
  Result<int> chosen = mandelbrot2dMaxIter(p);
  ASSERT_TRUE(chosen.ok());
  EXPECT_EQ(*chosen, autoMaxIter(1e-12));
  p.max_iter = 500;
  EXPECT_EQ(*mandelbrot2dMaxIter(p), 500);
  p.max_iter = 0;
  EXPECT_NE(mandelbrot2dMaxIter(p).error().message.find("--max-iter"), std::string::npos);
  p.max_iter.reset();
  p.width = 0.0;
  EXPECT_NE(mandelbrot2dMaxIter(p).error().message.find("--width"), std::string::npos);
  // --grid-out holds counts up to 65535: auto past that (width 1e-37: 70k) is an error naming both.
  p.width = 1e-37;
  p.grid_out = "unused.grid";
  Result<int> refused = mandelbrot2dMaxIter(p);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("--max-iter is auto, " + std::to_string(autoMaxIter(1e-37))),
            std::string::npos)
      << refused.error().message;
}

TEST(Mandelbrot2d, smoothCountIsContinuousAcrossCountBands) {
  // The default view at 1e-12 holds the 420/421 boundary: along each row the count jumps by one
  // where ν moves by a pixel's share of the view.
  Mandelbrot2dParams p;
  p.width = 1e-12;
  p.resolution = 128;
  Result<Mandelbrot2dEscapes> e = mandelbrot2dEscapes(p);
  ASSERT_TRUE(e.ok());
  size_t jumps = 0;
  double largest_step = 0.0, lowest = 1e9, highest = -1e9;
  for (size_t row = 0; row < 128; ++row) {
    for (size_t col = 0; col + 1 < 128; ++col) {
      const size_t i = row * 128 + col;
      ASSERT_LT(e->counts[i], 7941u);
      const double nu = mandelbrot2dSmoothCount(e->counts[i], e->tails[i]);
      const double next = mandelbrot2dSmoothCount(e->counts[i + 1], e->tails[i + 1]);
      jumps += e->counts[i] != e->counts[i + 1];
      largest_step = std::max(largest_step, std::abs(next - nu));
      lowest = std::min(lowest, nu - e->counts[i]);
      highest = std::max(highest, nu - e->counts[i]);
    }
  }
  std::printf("[ mandelbrot2d ] 1e-12: %zu count jumps along rows, largest step of nu %.3g, nu - count in [%.3f, %.3f]\n",
              jumps, largest_step, lowest, highest);
  EXPECT_GT(jumps, 20u);
  EXPECT_LT(largest_step, 0.02);  // the count itself jumps by 1
  EXPECT_GT(lowest, 0.0);
  EXPECT_LT(highest, 1.5);
}

// The share of the most common colour and the number of distinct colours (as the PLY writes them,
// 8 bits per channel).
std::pair<double, size_t> colourSpread(const PointSet& set) {
  std::map<uint32_t, size_t> histogram;
  for (const glm::vec3& c : set.colors) {
    uint32_t key = 0;
    for (int k = 0; k < 3; ++k) key = key << 8 | static_cast<uint32_t>(std::lround(c[k] * 255.0f));
    ++histogram[key];
  }
  size_t most = 0;
  for (const auto& [key, count] : histogram) most = std::max(most, count);
  return {static_cast<double>(most) / static_cast<double>(set.size()), histogram.size()};
}

TEST(Mandelbrot2d, deepZoomsAtTheDefaultCentreAreNotOneColour) {
  // Issue #24: at 1e-12 the counts are 420 and 421 only, and the old palette over the count gave
  // 97.5% of the points one colour; at 1e-15 every count is 421 (100%). The smooth count, spread
  // by its distribution, uses the whole palette.
  for (double width : {1e-12, 1e-15}) {
    Mandelbrot2dParams p;
    p.width = width;
    p.resolution = 256;
    Result<PointSet> set = generateMandelbrot2d(p);
    ASSERT_TRUE(set.ok());
    const auto [most, distinct] = colourSpread(*set);
    std::printf("[ mandelbrot2d ] width %g: most common colour %.2f%% of the points, %zu colours\n", width,
                100.0 * most, distinct);
    EXPECT_LT(most, 0.05) << width;
    EXPECT_GT(distinct, 500u) << width;
  }
}

TEST(Mandelbrot2d, rejectsBadParametersNamingTheFlag) {
  struct Case {
    void (*edit)(Mandelbrot2dParams&);
    const char* flag;
  };
  const Case cases[] = {
      {[](Mandelbrot2dParams& p) { p.resolution = 1; }, "--resolution"},
      {[](Mandelbrot2dParams& p) { p.resolution = 65537; }, "--resolution"},
      {[](Mandelbrot2dParams& p) { p.max_iter = 0; }, "--max-iter"},
      {[](Mandelbrot2dParams& p) { p.width = 0.0; }, "--width"},
      {[](Mandelbrot2dParams& p) { p.width = -1.0; }, "--width"},
      {[](Mandelbrot2dParams& p) { p.width = 1e-301; }, "--width"},
      {[](Mandelbrot2dParams& p) { p.width = INFINITY; }, "--width"},
      {[](Mandelbrot2dParams& p) { p.width = NAN; }, "--width"},
      {[](Mandelbrot2dParams& p) { p.center_x = NAN; }, "--center"},
      {[](Mandelbrot2dParams& p) { p.center_y = -INFINITY; }, "--center"},
      {[](Mandelbrot2dParams& p) { p.center_x = 1e301; }, "--center"},
      {[](Mandelbrot2dParams& p) { p.center_y = 9e299; p.width = 2e299; }, "--width"},
      {[](Mandelbrot2dParams& p) { p.width = 1.7e308; }, "--width"},
  };
  for (const Case& c : cases) {
    Mandelbrot2dParams p;
    p.resolution = 8;
    c.edit(p);
    Result<PointSet> set = generateMandelbrot2d(p);
    ASSERT_FALSE(set.ok()) << c.flag;
    EXPECT_EQ(set.error().code, ExitCode::kUsage);
    EXPECT_NE(set.error().message.find(c.flag), std::string::npos) << set.error().message;
    EXPECT_FALSE(mandelbrot2dCounts(p).ok());
  }
  Mandelbrot2dParams p;
  p.resolution = 0;
  EXPECT_NE(generateMandelbrot2d(p).error().message.find("65536"), std::string::npos);
}

TEST(Mandelbrot2d, refusesOverTheMemoryLimit) {
  Mandelbrot2dParams p;
  p.resolution = 65536;
  p.max_memory = 1u << 30;
  Result<PointSet> set = generateMandelbrot2d(p);
  ASSERT_FALSE(set.ok());
  EXPECT_EQ(set.error().code, ExitCode::kResourceLimit);
  EXPECT_NE(set.error().message.find("--max-memory"), std::string::npos) << set.error().message;
  EXPECT_NE(set.error().message.find("needs about"), std::string::npos) << set.error().message;
  // A small grid, but two 3.2 GB reference orbits.
  p.resolution = 16;
  p.width = 1e-20;
  p.max_iter = 200000000;
  EXPECT_EQ(mandelbrot2dCounts(p).error().code, ExitCode::kResourceLimit);
}

}  // namespace
}  // namespace dpoint
