#include "generators/perlin.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/memory.h"
#include "core/parallel.h"

namespace dpoint {
namespace {

// Ken Perlin's reference permutation of 0..255 (improved noise, 2002). Lookups index up to 511,
// so the table is used as if written twice (kPermutation[i & 255]).
constexpr uint8_t kPermutation[256] = {
    151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,  103, 30,
    69,  142, 8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,  0,   26,  197, 62,
    94,  252, 219, 203, 117, 35,  11,  32,  57,  177, 33,  88,  237, 149, 56,  87,  174, 20,  125, 136,
    171, 168, 68,  175, 74,  165, 71,  134, 139, 48,  27,  166, 77,  146, 158, 231, 83,  111, 229, 122,
    60,  211, 133, 230, 220, 105, 92,  41,  55,  46,  245, 40,  244, 102, 143, 54,  65,  25,  63,  161,
    1,   216, 80,  73,  209, 76,  132, 187, 208, 89,  18,  169, 200, 196, 135, 130, 116, 188, 159, 86,
    164, 100, 109, 198, 173, 186, 3,   64,  52,  217, 226, 250, 124, 123, 5,   202, 38,  147, 118, 126,
    255, 82,  85,  212, 207, 206, 59,  227, 47,  16,  58,  17,  182, 189, 28,  42,  223, 183, 170, 213,
    119, 248, 152, 2,   44,  154, 163, 70,  221, 153, 101, 155, 167, 43,  172, 9,   129, 22,  39,  253,
    19,  98,  108, 110, 79,  113, 224, 232, 178, 185, 112, 104, 218, 246, 97,  228, 251, 34,  242, 193,
    238, 210, 144, 12,  191, 179, 162, 241, 81,  51,  145, 235, 249, 14,  239, 107, 49,  192, 214, 31,
    181, 199, 106, 157, 184, 84,  204, 176, 115, 121, 50,  45,  127, 4,   150, 254, 138, 236, 205, 93,
    222, 114, 67,  29,  24,  72,  243, 141, 128, 195, 78,  66,  215, 61,  156, 180};

// The noise package's gradients: the 12 edge midpoints of the cube, then 4 of them again so a
// 4-bit hash can pick one without a modulo.
constexpr float kGradients[16][3] = {
    {1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1}, {1, 0, -1}, {-1, 0, -1},
    {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}, {1, 0, -1}, {-1, 0, -1}, {0, -1, 1}, {0, 1, 1}};

constexpr int kRepeat = 1024;  // the package's default repeatx/y/z

int perm(int index) { return kPermutation[index & 255]; }

// Every component is 0 or ±1, so the products are exact and the sum rounds once, as in C.
float gradient(int hash, float x, float y, float z) {
  const float* g = kGradients[hash & 15];
  return x * g[0] + y * g[1] + z * g[2];
}

float lerp(float t, float a, float b) { return a + t * (b - a); }

float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }

// floorf(v) for |v| < 2^31 without a call to libm (six a pnoise3 were much of the colouring's
// time): the truncation, one less below a negative non-integer, and v's sign on a zero
// (floorf(-0) is -0). Every float in that range takes this path exactly.
float floorSmall(float v) {
  const float t = static_cast<float>(static_cast<int>(v));
  return t > v ? t - 1.0f : std::copysign(t, v);
}

// The lattice cell along one axis, wrapped like the package: floor of fmod(v, repeat) (which
// keeps the sign of v), and the next cell as fmod(cell + 1, repeat) in float; floor_v = floor(v),
// unwrapped. fmod is exact, so inside (−repeat, repeat), where a generated set's coordinates lie,
// it is v itself, and of the integer cell + 1 (within ±repeat) it is the C remainder: the same
// cells without the two fmod calls, which were most of the colouring's time (18 a colour), and
// the cell is floor(v) itself.
void cellIndices(float v, int& lo, int& hi, float& floor_v) {
  const float repeat = static_cast<float>(kRepeat);
  if (std::fabs(v) < repeat) {
    floor_v = floorSmall(v);
    lo = static_cast<int>(floor_v);
  } else {  // and NaN
    floor_v = std::floor(v);
    lo = static_cast<int>(std::floor(std::fmod(v, repeat)));
  }
  hi = (lo + 1) % kRepeat;
  lo &= 255;
  hi &= 255;
}

}  // namespace

float pnoise3(float x, float y, float z) {
  int i, ii, j, jj, k, kk;
  float floor_x, floor_y, floor_z;
  cellIndices(x, i, ii, floor_x);
  cellIndices(y, j, jj, floor_y);
  cellIndices(z, k, kk, floor_z);
  // The fractional parts come from the unwrapped coordinates, as in the package.
  x -= floor_x;
  y -= floor_y;
  z -= floor_z;
  const float fx = fade(x), fy = fade(y), fz = fade(z);

  const int a = perm(i), aa = perm(a + j), ab = perm(a + jj);
  const int b = perm(ii), ba = perm(b + j), bb = perm(b + jj);
  const float x1 = x - 1.0f, y1 = y - 1.0f, z1 = z - 1.0f;
  const float near_z = lerp(fy, lerp(fx, gradient(perm(aa + k), x, y, z), gradient(perm(ba + k), x1, y, z)),
                            lerp(fx, gradient(perm(ab + k), x, y1, z), gradient(perm(bb + k), x1, y1, z)));
  const float far_z = lerp(fy, lerp(fx, gradient(perm(aa + kk), x, y, z1), gradient(perm(ba + kk), x1, y, z1)),
                           lerp(fx, gradient(perm(ab + kk), x, y1, z1), gradient(perm(bb + kk), x1, y1, z1)));
  return lerp(fz, near_z, far_z);
}

glm::vec3 seedColor(const glm::dvec3& p) {
  // A coordinate beyond float's range (a Menger sponge of size 1e40) was infinite as a float, its
  // noise NaN: it is taken modulo the noise's period of 1024 first (float's own coordinates, the
  // seed's, are left as they were).
  const auto toFloat = [](double v) {
    return static_cast<float>(std::fabs(v) <= double(std::numeric_limits<float>::max()) ? v : std::fmod(v, 1024.0));
  };
  glm::vec3 color;
  for (int c = 0; c < 3; ++c) {
    const double offset = 100.0 * c;
    const double n = pnoise3(toFloat(p.x + offset), toFloat(p.y + offset), toFloat(p.z + offset));
    color[c] = static_cast<float>(0.5 + 0.5 * n);
  }
  return color;
}

void seedColors(const glm::dvec3* positions, size_t n, glm::vec3* colors) {
  for (size_t i = 0; i < n; ++i) colors[i] = seedColor(positions[i]);
}

const uint8_t* perlinPermutation() { return kPermutation; }
const float* perlinGradients() { return &kGradients[0][0]; }

void colorByNoise(PointSet& points, unsigned threads) {
  constexpr size_t kPointsPerChunk = size_t{1} << 14;
  resizePrefaulted(points.colors, points.positions.size(), threads);
  const size_t chunks = (points.positions.size() + kPointsPerChunk - 1) / kPointsPerChunk;
  parallelFor(chunks, threads, [&](size_t chunk, unsigned) {
    const size_t begin = chunk * kPointsPerChunk, end = std::min(points.positions.size(), begin + kPointsPerChunk);
    seedColors(&points.positions[begin], end - begin, &points.colors[begin]);
  });
}

}  // namespace dpoint
