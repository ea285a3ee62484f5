// glTF 2.0 / GLB input (DESIGN §9). tinygltf parses; pre-checks, accessor decoding, transforms
// and every bounds check are ours (gltf_load.h, gltf_accessor.h).
//
// What a file turns into:
// - World-space positions in double: the default scene (else scene 0; with no scenes, every node
//   that has no parent), node `matrix` or T·R·S composed in double, quaternions normalised.
//   A mesh used by several nodes is emitted once per node, and once per instance of a node with
//   EXT_mesh_gpu_instancing (node world matrix · instance T·R·S). Skins are ignored (bind pose:
//   the node transform applies); morph targets are ignored.
// - A primitive with dpoint's _POSITION_LOW (and _POSITION_LOW2) float VEC3 residuals of its
//   float POSITION has local positions (POSITION + LOW) + LOW2 in double, exact for files dpoint
//   wrote (gltf_position.h); other files are read from POSITION alone.
// - Per primitive, the vertices it references: all of POSITION when not indexed, else each
//   vertex some index names, once, in vertex order. Triangle modes keep their triangles
//   (TRIANGLE_STRIP and TRIANGLE_FAN become triangle lists); points and lines are points.
// - Colours (linear 0..1) when any primitive has COLOR_0 (float, unorm8 or unorm16, VEC3/VEC4,
//   alpha dropped) or a material whose baseColorFactor rgb is not white; primitives without
//   COLOR_0 then take their material's baseColorFactor rgb (white without a material).
//   Textures are read only when asked (GltfReadOptions::texture), for sampling the surface.
// - Required extensions: KHR_mesh_quantization, EXT_meshopt_compression (gltf_meshopt.h),
//   KHR_draco_mesh_compression (gltf_draco.h) and EXT_mesh_gpu_instancing are decoded;
//   shading-only ones are accepted; any other is refused by name.
// Errors are one line: "PATH: /json/pointer: what" (ExitCode::kBadInput), or kResourceLimit for
// the size and point limits.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/input_file.h"
#include "core/point_set.h"
#include "core/result.h"
#include "ops/mesh_texture.h"

namespace dpoint {

// GLB stores lengths in 32 bits; 2 GiB keeps every size in tinygltf's int-typed fields.
constexpr uint64_t kGltfDefaultMaxFileBytes = uint64_t(1) << 31;

struct GltfReadOptions {
  int scene = -1;            // -1: the default scene (else scene 0)
  bool all_scenes = false;   // every scene in order; a node in several scenes is emitted per scene
  bool allow_nonfinite = false;
  uint64_t max_points = 0;   // 0: no limit; else more points is kResourceLimit, checked before allocating
  std::string max_points_name = "--max-points";  // how the caller names max_points in messages
  uint64_t max_file_bytes = kGltfDefaultMaxFileBytes;  // the file and each external buffer
  // Bytes for the model, what is decoded from it and the point set (--max-memory), each part
  // checked before it is allocated; over it is kResourceLimit. 0: defaultMemoryLimit().
  uint64_t max_memory = 0;
  bool triangles = true;     // false: points only (CSV output stores no triangles; saves 12 B/triangle)
  // When not null (and with triangles): receives the set's base-colour textures, for the mesh
  // sampler (ops/mesh_texture.h): each vertex's TEXCOORD (float or normalized (u)byte/(u)short
  // VEC2, through KHR_texture_transform) and each triangle's image, decoded (gltf_texture.h).
  MeshTexture* texture = nullptr;
  unsigned threads = 0;      // cores for a large primitive's vertices, indices and triangles (0: all)
  // When not null, gets a note naming the vertex attributes no dimension holds (NORMAL, TEXCOORD_n
  // where no texture is sampled, a VEC3 `_NAME`), once the scene is read.
  std::vector<std::string>* notices = nullptr;
};

Result<PointSet> readGltf(const std::string& path, const GltfReadOptions& options = {});
// The same from an opened file or from bytes in memory (InputFile::fromMemory: external URIs fail).
Result<PointSet> readGltf(const InputFile& input, const GltfReadOptions& options = {});

// What readGltf's set would be, found by streamGltf's first walk without keeping points.
struct GltfSummary {
  uint64_t points = 0;
  bool colors = false;  // some primitive has COLOR_0 or a non-white material colour (then every point has a colour)
  bool flat = false;    // the asset says dpoint wrote it from a 2D set (gltfSaysFlat): its z are 0
  // The dimensions every block carries (gltf_dimensions.h), in their order: name and type.
  std::vector<std::pair<std::string, DimType>> dimensions;
};

// Receives streamGltf's points: begin() once, after the checking walk, then points() with
// consecutive blocks of at most kGltfStreamBlockPoints, in readGltf's order and with readGltf's
// colours (a block has colours exactly when summary.colors). An error from either stops the walk
// and is what streamGltf returns.
class GltfPointSink {
 public:
  virtual ~GltfPointSink() = default;
  virtual Status begin(const GltfSummary& summary) = 0;
  // The block is the sink's to change; the walk clears it afterwards. No triangles.
  virtual Status points(PointSet& block) = 0;
};

constexpr size_t kGltfStreamBlockPoints = size_t(1) << 16;

// readGltf without the point set: the model is loaded once and walked twice. The first walk makes
// every check readGltf makes, in its order and with its errors (--max-points included), and keeps
// only the summary; sink.begin() is called only when it succeeds. The second walk hands the
// points to the sink. Memory: the model, one primitive's vertex map, one block. Triangles are not
// produced (options.triangles is ignored).
Status streamGltf(const std::string& path, const GltfReadOptions& options, GltfPointSink& sink);
Status streamGltf(const InputFile& input, const GltfReadOptions& options, GltfPointSink& sink);

// Every component of accessor `index` decoded as the spec defines it (normalisation and sparse
// substitution applied), element after element. For tests and tools that check the decoder.
Result<std::vector<double>> readGltfAccessor(const std::string& path, int index);

}  // namespace dpoint
