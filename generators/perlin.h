// Colours from noise: a port of `noise.pnoise3` (the Python `noise` package, Casey Duncan), the
// function the seed study coloured every vertex with.
//
// The port is exact, not approximate: it repeats the package's C arithmetic operation for
// operation in float32 (Ken Perlin's improved noise, SIGGRAPH 2002: his 256-entry permutation
// doubled, the quintic fade t³(t(6t − 15) + 10), lerp a + t(b − a), and the package's table of
// 12 + 4 gradient vectors), with floorf and the repeat wrap by fmodf as the package does. Each
// operation is a correctly rounded IEEE float operation, so with -ffp-contract=off (no FMA
// contraction) the result is the same bits the package returns; the test checks all 805 rows of
// reference/pnoise3_samples.csv for equality.
#pragma once

#include <cstddef>

#include <glm/vec3.hpp>

#include "core/point_set.h"

namespace dpoint {

// noise.pnoise3(x, y, z) with the package's default arguments (octaves 1, repeat 1024 on every
// axis, base 0). The package parses its arguments as C floats, so callers holding doubles convert
// each coordinate to float first (round to nearest), as Python does.
float pnoise3(float x, float y, float z);

// The seed's colour of a point: channel c = 0.5 + 0.5·pnoise3(p + offset_c) with offsets 0, 100,
// 200. The seed added the offsets to Python floats (double) and the package then rounded the sums
// to float, so here p + offset is formed in double and rounded to float once; 0.5 + 0.5·n is
// formed in double (exact: n is a float) and rounded to float once for storage.
glm::vec3 seedColor(const glm::dvec3& p);
// colors[i] = seedColor(positions[i]) for i < n.
void seedColors(const glm::dvec3* positions, size_t n, glm::vec3* colors);

// Sets points.colors to seedColor of every position (replacing any colours), split over
// `threads` (0: all cores); the result does not depend on the thread count.
void colorByNoise(PointSet& points, unsigned threads);

// The noise's tables, for a device that makes seedColor too (shaders/generate/mesh_slab.comp): the
// permutation of 0..255, and the 16 gradients, x, y, z each.
const uint8_t* perlinPermutation();
const float* perlinGradients();

}  // namespace dpoint
