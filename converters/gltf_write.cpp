// GLB output. tinygltf serializes the JSON chunk from a tinygltf::Model; the BIN chunk is streamed
// by us straight from the PointSet. We do not hand the binary data to tinygltf: its GLB writer
// copies the buffer twice (into a temporary and into the stream) and writes 32-bit chunk lengths
// without checking them, and for 17M coloured points that is ~1 GB of needless copies.
//
// Precision: positions are stored as float32 offsets from a double origin (the centre of the
// bounding box) kept in the node translation. The centre minimizes the largest offset, so the
// rounding of each stored offset is at most 2^-24 · extent/2 per axis, whatever the absolute
// coordinate is (glTF 2.0 spec §3.5: node translation is a double JSON number).
#include "converters/gltf_write.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/common.hpp>
#include <limits>
#include <sstream>
#include <vector>

#include "core/atomic_file.h"

namespace dpoint {
namespace {

static_assert(std::endian::native == std::endian::little, "GLB is little-endian; so are we");
static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "colours are written as packed float32 VEC3");

constexpr uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr uint32_t kGlbVersion = 2;
constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"
constexpr size_t kPositionBlock = 1 << 16;   // points converted per write while streaming

// The one place a stored position is computed: the min/max pass and the writing pass must agree
// bit for bit (we build with -ffp-contract=off, so this is one double subtraction and one
// round-to-nearest conversion per axis).
inline glm::vec3 storedOffset(const glm::dvec3& p, const glm::dvec3& origin) {
  return glm::vec3(static_cast<float>(p.x - origin.x), static_cast<float>(p.y - origin.y),
                   static_cast<float>(p.z - origin.z));
}

size_t padTo4(size_t n) { return (n + 3) & ~size_t{3}; }

struct Layout {
  glm::dvec3 origin{0.0};
  glm::vec3 min{0.0f};
  glm::vec3 max{0.0f};
  size_t positions_bytes = 0;
  size_t colors_bytes = 0;
  size_t indices_bytes = 0;
  size_t bin_bytes = 0;  // all views, each 4-byte aligned
};

Result<Layout> planLayout(const PointSet& points) {
  const size_t n = points.size();
  // glTF requires accessor.count >= 1 (and buffer.byteLength >= 1): an empty set has no valid GLB.
  if (n == 0)
    return Error{"cannot write GLB: the point set is empty, and a glTF accessor must hold at least one element; "
                 "write .csv, .ply or .las, which hold an empty set"};
  if (points.hasColors() && points.colors.size() != n)
    return Error{"cannot write GLB: " + std::to_string(points.colors.size()) + " colours for " +
                 std::to_string(n) + " points"};
  if (points.triangles.size() % 3 != 0)
    return Error{"cannot write GLB: " + std::to_string(points.triangles.size()) +
                 " triangle indices is not a multiple of 3"};
  for (size_t i = 0; i < points.triangles.size(); ++i) {
    if (points.triangles[i] >= n)
      return Error{"cannot write GLB: triangle index " + std::to_string(i) + " is " +
                   std::to_string(points.triangles[i]) + ", but there are only " +
                   std::to_string(n) + " points"};
  }

  Layout layout;
  glm::dvec3 lo = points.positions[0], hi = points.positions[0];
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3& p = points.positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      return Error{"cannot write GLB: point " + std::to_string(i) + " has a non-finite coordinate"};
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  // 0.5*lo + 0.5*hi cannot overflow, unlike (lo + hi) / 2.
  layout.origin = 0.5 * lo + 0.5 * hi;

  layout.min = glm::vec3(std::numeric_limits<float>::infinity());
  layout.max = glm::vec3(-std::numeric_limits<float>::infinity());
  for (const glm::dvec3& p : points.positions) {
    const glm::vec3 f = storedOffset(p, layout.origin);
    layout.min = glm::min(layout.min, f);
    layout.max = glm::max(layout.max, f);
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(layout.min[axis]) || !std::isfinite(layout.max[axis]))
      return Error{"cannot write GLB: the extent of the points does not fit float32 offsets"};
  }

  layout.positions_bytes = n * sizeof(glm::vec3);
  layout.colors_bytes = points.hasColors() ? n * sizeof(glm::vec3) : 0;
  layout.indices_bytes = points.triangles.size() * sizeof(uint32_t);
  layout.bin_bytes =
      padTo4(layout.positions_bytes) + padTo4(layout.colors_bytes) + padTo4(layout.indices_bytes);
  return layout;
}

int addView(tinygltf::Model& model, size_t offset, size_t length, int target) {
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = offset;
  view.byteLength = length;
  view.target = target;
  model.bufferViews.push_back(view);
  return static_cast<int>(model.bufferViews.size() - 1);
}

int addAccessor(tinygltf::Model& model, int view, int component_type, int type, size_t count) {
  tinygltf::Accessor accessor;
  accessor.bufferView = view;
  accessor.byteOffset = 0;
  accessor.componentType = component_type;
  accessor.type = type;
  accessor.count = count;
  accessor.normalized = false;
  model.accessors.push_back(accessor);
  return static_cast<int>(model.accessors.size() - 1);
}

// Everything but `buffers`, which describes the BIN chunk we stream ourselves.
tinygltf::Model describe(const PointSet& points, const Layout& layout) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "dpoint";

  tinygltf::Primitive primitive;
  size_t offset = 0;
  const int position_view =
      addView(model, offset, layout.positions_bytes, TINYGLTF_TARGET_ARRAY_BUFFER);
  offset += padTo4(layout.positions_bytes);
  const int position_accessor = addAccessor(model, position_view, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                            TINYGLTF_TYPE_VEC3, points.size());
  // Spec §5.1.1: POSITION needs min and max; they must be the stored float values exactly.
  model.accessors[size_t(position_accessor)].minValues = {layout.min.x, layout.min.y, layout.min.z};
  model.accessors[size_t(position_accessor)].maxValues = {layout.max.x, layout.max.y, layout.max.z};
  primitive.attributes["POSITION"] = position_accessor;

  if (points.hasColors()) {
    const int color_view =
        addView(model, offset, layout.colors_bytes, TINYGLTF_TARGET_ARRAY_BUFFER);
    offset += padTo4(layout.colors_bytes);
    primitive.attributes["COLOR_0"] = addAccessor(model, color_view, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                                  TINYGLTF_TYPE_VEC3, points.size());
  }
  if (points.isMesh()) {
    const int index_view =
        addView(model, offset, layout.indices_bytes, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    primitive.indices = addAccessor(model, index_view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                    TINYGLTF_TYPE_SCALAR, points.triangles.size());
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
  } else {
    primitive.mode = TINYGLTF_MODE_POINTS;
  }

  tinygltf::Mesh mesh;
  mesh.primitives.push_back(primitive);
  model.meshes.push_back(mesh);

  tinygltf::Node node;
  node.mesh = 0;
  node.translation = {layout.origin.x, layout.origin.y, layout.origin.z};
  model.nodes.push_back(node);

  tinygltf::Scene scene;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  return model;
}

// tinygltf's JSON for the model, with the one buffer (the BIN chunk, no uri) added.
Result<std::string> jsonChunk(const tinygltf::Model& model, size_t bin_bytes) {
  std::ostringstream stream;
  tinygltf::TinyGLTF gltf;
  if (!gltf.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/false, /*writeBinary=*/false))
    return Error{"cannot write GLB: tinygltf failed to serialize the scene"};
  std::string json = std::move(stream).str();
  while (!json.empty() && (json.back() == '\n' || json.back() == ' ')) json.pop_back();
  // The serialized model is one JSON object without a "buffers" member (model.buffers is empty).
  assert(!json.empty() && json.back() == '}' && json.find("\"buffers\"") == std::string::npos);
  json.pop_back();
  json += ",\"buffers\":[{\"byteLength\":" + std::to_string(bin_bytes) + "}]}";
  json.resize(padTo4(json.size()), ' ');  // spec: the JSON chunk is padded with spaces
  return json;
}

Status writeU32(AtomicFile& file, uint32_t value) { return file.write(&value, sizeof(value)); }

Status writeBin(AtomicFile& file, const PointSet& points, const Layout& layout) {
  std::vector<glm::vec3> block;
  block.reserve(std::min(kPositionBlock, points.size()));
  for (size_t begin = 0; begin < points.size(); begin += kPositionBlock) {
    const size_t end = std::min(points.size(), begin + kPositionBlock);
    block.clear();
    for (size_t i = begin; i < end; ++i)
      block.push_back(storedOffset(points.positions[i], layout.origin));
    if (Status s = file.write(block.data(), block.size() * sizeof(glm::vec3)); !s) return s;
  }
  // Colours and indices are already float32 VEC3 / uint32 little-endian in memory.
  if (points.hasColors()) {
    if (Status s = file.write(points.colors.data(), layout.colors_bytes); !s) return s;
  }
  if (points.isMesh()) {
    if (Status s = file.write(points.triangles.data(), layout.indices_bytes); !s) return s;
  }
  // Every view length is a multiple of 4 (12-byte and 4-byte elements): no padding is needed.
  static_assert(sizeof(glm::vec3) % 4 == 0 && sizeof(uint32_t) % 4 == 0);
  return okStatus();
}

}  // namespace

Status writeGlb(const std::string& path, const PointSet& points) {
  Result<Layout> layout = planLayout(points);
  if (!layout) return layout.error();
  Result<std::string> json = jsonChunk(describe(points, *layout), layout->bin_bytes);
  if (!json) return json.error();

  // GLB stores every length in 32 bits (spec §4.4.3); refuse rather than wrap around.
  const uint64_t total = 12 + 8 + uint64_t{json->size()} + 8 + uint64_t{layout->bin_bytes};
  if (total > std::numeric_limits<uint32_t>::max())
    return Error{"cannot write '" + path + "': " + std::to_string(points.size()) + " points need " +
                     std::to_string(total) + " bytes, over the 4 GiB GLB limit",
                 ExitCode::kResourceLimit};

  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  for (uint32_t word : {kGlbMagic, kGlbVersion, static_cast<uint32_t>(total),
                        static_cast<uint32_t>(json->size()), kChunkJson}) {
    if (Status s = writeU32(*file, word); !s) return s;
  }
  if (Status s = file->write(*json); !s) return s;
  if (Status s = writeU32(*file, static_cast<uint32_t>(layout->bin_bytes)); !s) return s;
  if (Status s = writeU32(*file, kChunkBin); !s) return s;
  if (Status s = writeBin(*file, points, *layout); !s) return s;
  assert(file->bytesWritten() == total);
  return file->commit();
}

}  // namespace dpoint
