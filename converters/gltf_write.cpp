// GLB output. tinygltf serializes the JSON chunk from a tinygltf::Model; the BIN chunk is streamed
// by us straight from the PointSet. We do not hand the binary data to tinygltf: its GLB writer
// copies the buffer twice (into a temporary and into the stream) and writes 32-bit chunk lengths
// without checking them, and for 17M coloured points that is ~1 GB of needless copies.
//
// Precision: POSITION is float32 offsets from a double origin kept in the node translation (glTF
// 2.0 spec §3.5: a double JSON number). The origin is the centre of the bounding box wherever the
// offsets from it are exact (it minimizes the largest offset, so other readers get each offset to
// 2^-24 · extent/2), else 0. Two float32 residuals (_POSITION_LOW, _POSITION_LOW2) make the
// positions exact for dpoint; when and why is in gltf_position.h, and every point is checked.
#include "converters/gltf_write.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/common.hpp>
#include <glm/mat4x4.hpp>
#include <limits>
#include <optional>
#include <iterator>
#include <sstream>
#include <utility>
#include <vector>

#include "converters/gltf_dimensions.h"
#include "converters/gltf_position.h"
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

// The parts of one coordinate (gltf_position.h): hi, mid, lo of (p − origin) · 2^-k. The one place
// they are computed: the planning, min/max and writing passes agree bit for bit (we build with
// -ffp-contract=off: one subtraction, one exact power-of-two product, exact residuals).
struct Parts {
  float hi, mid, lo;
};
inline Parts splitCoordinate(double p, double origin, double inv_scale) {
  const double ds = (p - origin) * inv_scale;
  const float hi = static_cast<float>(ds);
  const double r1 = ds - static_cast<double>(hi);
  const float mid = static_cast<float>(r1);
  return Parts{hi, mid, static_cast<float>(r1 - static_cast<double>(mid))};
}

// The scale exponent is clamped so both 2^k and 2^-k are normal doubles; a set at 1e-310 still
// gets |ds| < 2^24.
constexpr int kMaxScaleExponent = 1000;

// Where one axis is stored: node translation `origin`, node scale 2^exponent.
struct AxisPlan {
  double origin = 0.0;
  int exponent = 0;
  uint64_t inexact = 0;  // points whose coordinate on this axis does not rebuild (scalar check)
  bool finite = true;    // every hi part is a finite float (else the plan is unusable)
};

// The scalar form of the reader's arithmetic, s·(hi + mid + lo) + t; it differs from the matrix
// product only in the sign of a zero, which the final check (placeGltfVertex) sees.
AxisPlan tryAxis(const PointSet& points, int axis, double origin, int exponent) {
  AxisPlan plan{origin, exponent};
  const double scale = std::ldexp(1.0, exponent), inv_scale = std::ldexp(1.0, -exponent);
  for (const glm::dvec3& point : points.positions) {
    const double p = point[axis];
    const Parts parts = splitCoordinate(p, origin, inv_scale);
    if (!std::isfinite(parts.hi)) {
      plan.finite = false;
      return plan;
    }
    const double local = joinGltfPositionParts(parts.hi, parts.mid, parts.lo);
    if (std::bit_cast<uint64_t>(local * scale + origin) != std::bit_cast<uint64_t>(p)) ++plan.inexact;
  }
  return plan;
}

// The first of these that rebuilds every point exactly, else the one that rebuilds the most:
// the box centre (today's origin: other readers keep float precision of the extent), the centre
// with a scale bringing offsets near 1 (data beyond float32's range), then the origin 0 (offsets
// are the coordinates themselves, exact by construction: data near zero, whose bits reach far
// below the extent's), with and without a scale.
AxisPlan planAxis(const PointSet& points, int axis, double lo, double hi) {
  const double centre = 0.5 * lo + 0.5 * hi;  // cannot overflow, unlike (lo + hi) / 2
  const auto exponentFor = [](double largest) {
    return largest == 0.0 ? 0 : std::clamp(std::ilogb(largest), -kMaxScaleExponent, kMaxScaleExponent);
  };
  const int centre_exponent = exponentFor(std::max(hi - centre, centre - lo));
  const int zero_exponent = exponentFor(std::max(std::fabs(lo), std::fabs(hi)));
  const std::pair<double, int> candidates[] = {
      {centre, 0}, {centre, centre_exponent}, {0.0, 0}, {0.0, zero_exponent}};
  std::optional<AxisPlan> best;
  for (size_t i = 0; i < std::size(candidates); ++i) {
    const auto [origin, exponent] = candidates[i];
    if (i > 0 && (std::find(candidates, candidates + i, candidates[i]) != candidates + i)) continue;
    const AxisPlan plan = tryAxis(points, axis, origin, exponent);
    if (!plan.finite) continue;
    if (plan.inexact == 0) return plan;
    if (!best || plan.inexact < best->inexact) best = plan;
  }
  // The centre with its scale keeps |ds| < 2, so some plan always has finite parts.
  assert(best);
  return *best;
}

size_t padTo4(size_t n) { return (n + 3) & ~size_t{3}; }

struct Layout {
  glm::dvec3 origin{0.0};
  glm::ivec3 exponent{0};  // node scale 2^exponent per axis
  glm::vec3 min{0.0f};
  glm::vec3 max{0.0f};
  bool low2 = false;        // some point needs the third part (_POSITION_LOW2)
  uint64_t inexact = 0;     // points that do not rebuild bit-exactly
  size_t positions_bytes = 0;  // each of POSITION, _POSITION_LOW and (if low2) _POSITION_LOW2
  size_t colors_bytes = 0;
  size_t indices_bytes = 0;
  size_t dimensions_bytes = 0;  // every dimension's view (gltf_dimensions.h), each a multiple of 4
  size_t bin_bytes = 0;  // all views, each 4-byte aligned

  glm::dvec3 invScale() const {
    return glm::dvec3(std::ldexp(1.0, -exponent.x), std::ldexp(1.0, -exponent.y), std::ldexp(1.0, -exponent.z));
  }
  // The node's world matrix as gltf_read composes it (identity · T·R·S, R the identity).
  glm::dmat4 world() const {
    glm::dmat4 t(1.0), s(1.0);
    t[3] = glm::dvec4(origin, 1.0);
    for (int axis = 0; axis < 3; ++axis) s[axis][axis] = std::ldexp(1.0, exponent[axis]);
    return glm::dmat4(1.0) * (t * glm::dmat4(1.0) * s);
  }
};

struct PointParts {
  glm::vec3 hi, mid, lo;
};
inline PointParts splitPoint(const glm::dvec3& p, const Layout& layout, const glm::dvec3& inv_scale) {
  PointParts out;
  for (int axis = 0; axis < 3; ++axis) {
    const Parts parts = splitCoordinate(p[axis], layout.origin[axis], inv_scale[axis]);
    out.hi[axis] = parts.hi;
    out.mid[axis] = parts.mid;
    out.lo[axis] = parts.lo;
  }
  return out;
}

bool sameBits(const glm::dvec3& a, const glm::dvec3& b) {
  return std::memcmp(&a, &b, sizeof(glm::dvec3)) == 0;
}

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
  if (const size_t i = points.firstBadTriangleIndex(); i < points.triangles.size())
    return Error{"cannot write GLB: triangle index " + std::to_string(i) + " is " +
                 std::to_string(points.triangles[i]) + ", but there are only " + std::to_string(n) + " points"};

  Layout layout;
  glm::dvec3 lo = points.positions[0], hi = points.positions[0];
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3& p = points.positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      return Error{"cannot write GLB: point " + std::to_string(i) + " has a non-finite coordinate"};
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  for (int axis = 0; axis < 3; ++axis) {
    const AxisPlan plan = planAxis(points, axis, lo[axis], hi[axis]);
    layout.origin[axis] = plan.origin;
    layout.exponent[axis] = plan.exponent;
  }

  // The final check, with the reader's matrix arithmetic; min/max of the stored POSITION floats.
  layout.min = glm::vec3(std::numeric_limits<float>::infinity());
  layout.max = glm::vec3(-std::numeric_limits<float>::infinity());
  const glm::dvec3 inv_scale = layout.invScale();
  const glm::dmat4 world = layout.world();
  for (const glm::dvec3& p : points.positions) {
    const PointParts parts = splitPoint(p, layout, inv_scale);
    layout.min = glm::min(layout.min, parts.hi);
    layout.max = glm::max(layout.max, parts.hi);
    if (parts.lo != glm::vec3(0.0f) || std::signbit(parts.lo.x) || std::signbit(parts.lo.y) ||
        std::signbit(parts.lo.z))
      layout.low2 = true;
  }
  for (const glm::dvec3& p : points.positions) {
    const PointParts parts = splitPoint(p, layout, inv_scale);
    glm::dvec3 local;
    for (int axis = 0; axis < 3; ++axis)
      local[axis] = joinGltfPositionParts(parts.hi[axis], parts.mid[axis], layout.low2 ? parts.lo[axis] : 0.0f);
    if (!sameBits(placeGltfVertex(world, local), p)) ++layout.inexact;
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(layout.min[axis]) || !std::isfinite(layout.max[axis]))
      return Error{"cannot write GLB: the extent of the points does not fit float32 offsets"};
  }

  layout.positions_bytes = n * sizeof(glm::vec3);
  layout.colors_bytes = points.hasColors() ? n * sizeof(glm::vec3) : 0;
  layout.indices_bytes = points.triangles.size() * sizeof(uint32_t);
  for (const Dimension& d : points.dimensions.all()) layout.dimensions_bytes += n * gltfDimensionForm(d.type).stride;
  layout.bin_bytes = padTo4(layout.positions_bytes) * (layout.low2 ? 3 : 2) + padTo4(layout.colors_bytes) +
                     layout.dimensions_bytes + padTo4(layout.indices_bytes);
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
  // A 2D set (z not a coordinate: read from x,y input, or made with every z 0) says so, as the PLY
  // writer's comment does: glTF positions are VEC3, so without it x,y → GLB → CSV came back x,y,z.
  if (!points.hasZ()) {
    tinygltf::Value::Object dpoint;
    dpoint["2d"] = tinygltf::Value(true);
    tinygltf::Value::Object extras;
    extras["dpoint"] = tinygltf::Value(dpoint);
    model.asset.extras = tinygltf::Value(extras);
  }

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
  // The float32 residuals that make the positions exact for dpoint (gltf_position.h).
  const int low_view = addView(model, offset, layout.positions_bytes, TINYGLTF_TARGET_ARRAY_BUFFER);
  offset += padTo4(layout.positions_bytes);
  primitive.attributes[kGltfPositionLow] =
      addAccessor(model, low_view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, points.size());
  if (layout.low2) {
    const int low2_view = addView(model, offset, layout.positions_bytes, TINYGLTF_TARGET_ARRAY_BUFFER);
    offset += padTo4(layout.positions_bytes);
    primitive.attributes[kGltfPositionLow2] =
        addAccessor(model, low2_view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, points.size());
  }

  if (points.hasColors()) {
    const int color_view =
        addView(model, offset, layout.colors_bytes, TINYGLTF_TARGET_ARRAY_BUFFER);
    offset += padTo4(layout.colors_bytes);
    primitive.attributes["COLOR_0"] = addAccessor(model, color_view, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                                  TINYGLTF_TYPE_VEC3, points.size());
  }
  // Each dimension as an application-specific attribute (gltf_dimensions.h), before the indices.
  for (const Dimension& d : points.dimensions.all()) {
    const GltfDimensionForm form = gltfDimensionForm(d.type);
    const size_t bytes = points.size() * form.stride;
    const int view = addView(model, offset, bytes, TINYGLTF_TARGET_ARRAY_BUFFER);
    offset += bytes;
    if (dimTypeSize(d.type) < 4) model.bufferViews[size_t(view)].byteStride = 4;
    const int accessor = addAccessor(model, view, form.component_type, form.type, points.size());
    const KnownDimension* known = findKnownDimension(d.name);
    // Names that differ only in case (a LAS extra byte "Intensity" beside the field) get a suffix.
    const std::string base = known ? known->gltf_attribute : gltfAttributeName(d.name);
    std::string attribute = base;
    for (int k = 2; primitive.attributes.count(attribute); ++k) attribute = base + "_" + std::to_string(k);
    tinygltf::Value::Object facts;
    if (form.raw) facts["type"] = tinygltf::Value(std::string(dimTypeName(d.type)));
    if (gltfDimensionName(attribute) != d.name) facts["name"] = tinygltf::Value(d.name);
    if (!facts.empty()) {
      tinygltf::Value::Object extras;
      extras["dpoint"] = tinygltf::Value(facts);
      model.accessors[size_t(accessor)].extras = tinygltf::Value(extras);
    }
    primitive.attributes[attribute] = accessor;
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
  // A power-of-two scale only for data beyond float32's range (a set at 1e-300): elsewhere the
  // node is as before, a translation only.
  if (layout.exponent != glm::ivec3(0))
    node.scale = {std::ldexp(1.0, layout.exponent.x), std::ldexp(1.0, layout.exponent.y),
                  std::ldexp(1.0, layout.exponent.z)};
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
  const glm::dvec3 inv_scale = layout.invScale();
  std::vector<glm::vec3> block;
  block.reserve(std::min(kPositionBlock, points.size()));
  // POSITION, _POSITION_LOW, then _POSITION_LOW2: one view after the other.
  for (glm::vec3 PointParts::*part : {&PointParts::hi, &PointParts::mid, &PointParts::lo}) {
    if (part == &PointParts::lo && !layout.low2) break;
    for (size_t begin = 0; begin < points.size(); begin += kPositionBlock) {
      const size_t end = std::min(points.size(), begin + kPositionBlock);
      block.clear();
      for (size_t i = begin; i < end; ++i) block.push_back(splitPoint(points.positions[i], layout, inv_scale).*part);
      if (Status s = file.write(block.data(), block.size() * sizeof(glm::vec3)); !s) return s;
    }
  }
  // Colours and indices are already float32 VEC3 / uint32 little-endian in memory.
  if (points.hasColors()) {
    if (Status s = file.write(points.colors.data(), layout.colors_bytes); !s) return s;
  }
  // Dimensions: 1- and 2-byte values padded to 4 bytes each, wider ones as their bytes.
  std::vector<char> padded;
  for (const Dimension& d : points.dimensions.all()) {
    const size_t width = dimTypeSize(d.type);
    if (width >= 4) {
      if (Status s = file.write(d.bytes.data(), d.bytes.size()); !s) return s;
      continue;
    }
    for (size_t begin = 0; begin < points.size(); begin += kPositionBlock) {
      const size_t end = std::min(points.size(), begin + kPositionBlock);
      padded.assign((end - begin) * 4, 0);
      for (size_t i = begin; i < end; ++i) std::memcpy(padded.data() + (i - begin) * 4, d.bytes.data() + i * width, width);
      if (Status s = file.write(padded.data(), padded.size()); !s) return s;
    }
  }
  if (points.isMesh()) {
    if (Status s = file.write(points.triangles.data(), layout.indices_bytes); !s) return s;
  }
  // Every view length is a multiple of 4 (12-byte and 4-byte elements): no padding is needed.
  static_assert(sizeof(glm::vec3) % 4 == 0 && sizeof(uint32_t) % 4 == 0);
  return okStatus();
}

}  // namespace

Status writeGlb(const std::string& path, const PointSet& points, GlbWriteReport* report) {
  Result<Layout> layout = planLayout(points);
  if (!layout) return layout.error();
  if (report) report->inexact_points = layout->inexact;
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
  if (Status s = file->checkSpace(total); !s) return s;
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
