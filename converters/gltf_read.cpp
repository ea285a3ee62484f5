// The scene walk: nodes to world space, primitives to points and triangles. Loading and the
// pre-checks are in gltf_load.cpp, accessor decoding and its bounds checks in gltf_accessor.cpp.
//
// Node transforms are composed in double (glTF 2.0 §3.5.3: local = T·R·S, or `matrix`), so
// positions stored relative to a far-away node translation keep their float precision.
//
// One walk serves three passes: building a PointSet (readGltf), and streamGltf's checking pass
// (every check of the build pass, nothing kept) and emitting pass (no checks left to fail; points
// handed out in blocks). Vertex placement, colour decoding and material colours are shared
// functions, so a streamed point is bit-identical to the built one.
#include "converters/gltf_read.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
#include <limits>
#include <new>
#include <optional>
#include <string_view>

#include "converters/gltf_accessor.h"
#include "converters/gltf_dimensions.h"
#include "converters/gltf_load.h"
#include "converters/gltf_position.h"
#include "converters/gltf_texture.h"
#include "core/interrupt.h"
#include "core/memory.h"
#include "core/parallel.h"

namespace dpoint {
namespace {

// Deeper than any real scene graph; it bounds our recursion on hostile files.
constexpr int kMaxNodeDepth = 64;
// Accessors without a bufferView own their (zero) values; this caps what a bare count can allocate.
constexpr size_t kMaxUnbackedValues = size_t(1) << 28;
constexpr uint32_t kUnused = std::numeric_limits<uint32_t>::max();

// Rotation matrix of a unit quaternion (x, y, z, w), column-major like glm. Written out rather
// than via glm::dquat because glm's quaternion constructor order depends on configuration macros.
glm::dmat4 rotationMatrix(double x, double y, double z, double w) {
  glm::dmat4 r(1.0);
  r[0] = glm::dvec4(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0);
  r[1] = glm::dvec4(2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0);
  r[2] = glm::dvec4(2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0);
  return r;
}

// Room for `extra` more elements: exactly for the first (often the only, and largest) primitive,
// then growing by half at least, so many small primitives do not copy the arrays once each.
template <typename T, typename Allocator>
void reserveMore(std::vector<T, Allocator>& v, size_t extra) {
  const size_t needed = v.size() + extra;
  if (needed > v.capacity()) v.reserve(std::max(needed, v.capacity() + v.capacity() / 2));
}

bool allFinite(const std::vector<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

// A primitive's positions: POSITION and, in a file dpoint wrote, the float32 residuals that make
// them exact (gltf_position.h). Files without _POSITION_LOW are read exactly as before.
struct PositionParts {
  AccessorElements hi;
  std::optional<AccessorElements> mid, lo;

  glm::dvec3 local(size_t e) const {
    if (!mid) return glm::dvec3(hi.value(e, 0), hi.value(e, 1), hi.value(e, 2));
    glm::dvec3 v;
    for (int k = 0; k < 3; ++k) v[k] = joinGltfPositionParts(hi.value(e, k), mid->value(e, k), lo ? lo->value(e, k) : 0.0);
    return v;
  }
};

// Vertex e in world space.
glm::dvec3 placeVertex(const PositionParts& positions, const glm::dmat4& world, size_t e) {
  return placeGltfVertex(world, positions.local(e));
}

// Linear colour (spec §3.7.2.1); alpha is dropped.
glm::vec3 vertexColour(const AccessorElements& colours, size_t e) {
  return glm::vec3(float(colours.value(e, 0)), float(colours.value(e, 1)), float(colours.value(e, 2)));
}

// A dimension the file's primitives carry (gltf_dimensions.h): its attribute, name and type.
struct GltfDimension {
  std::string attribute, name;
  DimType type;
};

// The type a SCALAR accessor of this component type holds, for an attribute without dpoint's extras.
std::optional<DimType> scalarType(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return DimType::kU8;
    case TINYGLTF_COMPONENT_TYPE_BYTE: return DimType::kI8;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return DimType::kU16;
    case TINYGLTF_COMPONENT_TYPE_SHORT: return DimType::kI16;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return DimType::kU32;
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return DimType::kF32;
    default: return std::nullopt;
  }
}

// How one primitive's accessor fills a dimension: as stored, or (`raw`) from its unsigned shorts.
struct DimensionSource {
  size_t column;  // in the set's dimensions
  AccessorElements elements;
  bool raw;
  DimType stored;  // the accessor's own type, converted where the set's column differs

  void store(Dimension& d, size_t at, size_t e) const {
    if (raw) {
      uint8_t bytes[8] = {};
      for (int k = 0; k < elements.components(); ++k) {
        const uint16_t word = static_cast<uint16_t>(elements.value(e, k));
        std::memcpy(bytes + 2 * k, &word, 2);
      }
      if (stored == d.type) {
        std::memcpy(d.bytes.data() + at * dimTypeSize(d.type), bytes, dimTypeSize(d.type));
        return;
      }
      Dimension one("", stored, 1);
      std::memcpy(one.bytes.data(), bytes, dimTypeSize(stored));
      d.setValue(at, one.value(0));
      return;
    }
    d.setValue(at, elements.value(e, 0));  // a byte, short, u32 or float: exact in double
  }
};

// A primitive without COLOR_0; it gets its material colour if any other primitive has colours.
struct Uncoloured {
  size_t begin = 0, end = 0;
  glm::vec3 color{1.0f};
};

class SceneReader {
 public:
  // A note naming what attributesLeftOut finds, where it finds any.
  static void noteLeftOut(const std::string& path, const tinygltf::Model& model, const GltfReadOptions& options) {
    if (!options.notices) return;
    const std::vector<std::string> left = attributesLeftOut(model, options.texture != nullptr);
    if (left.empty()) return;
    std::string list;
    for (const std::string& a : left) list += (list.empty() ? "" : ", ") + a;
    options.notices->push_back(path + ": vertex attributes not read (dpoint reads POSITION, COLOR_0 and SCALAR _NAME "
                                      "attributes): " + list);
  }

  // dpoint's writer marks a 2D set's asset (gltf_write.cpp).
  static bool saysFlat(const tinygltf::Model& model) {
    const tinygltf::Value& dpoint = model.asset.extras.Get("dpoint");
    return model.asset.generator == "dpoint" && dpoint.IsObject() && dpoint.Get("2d").IsBool() &&
           dpoint.Get("2d").Get<bool>();
  }

  SceneReader(const std::string& path, const tinygltf::Model& model, const GltfReadOptions& options)
      : path_(path),
        model_(model),
        options_(options),
        memory_limit_(options.max_memory ? options.max_memory : defaultMemoryLimit()),
        decoder_(path, model, std::min<uint64_t>(kMaxUnbackedValues, memory_limit_ / sizeof(double))),
        dimensions_(findDimensions(model)) {
    if (options.texture && options.triangles) {
      *options.texture = MeshTexture{};
      textures_.emplace(path, model, memory_limit_, *options.texture);
    }
  }

  Result<PointSet> read() {
    pass_ = Pass::kBuild;
    for (const GltfDimension& d : dimensions_) out_.dimensions.append(d.name, d.type, 0);
    if (Status s = walkScenes(); !s) return s.error();
    out_.dimensions.resize(out_.positions.size());  // 0 for the points of primitives without one
    // glTF positions are VEC3, whatever their values; a set dpoint wrote as 2D says so in the
    // asset's extras (gltf_write.cpp), and its z are 0.
    const bool flat = saysFlat(model_) && std::all_of(out_.positions.begin(), out_.positions.end(),
                                                      [](const glm::dvec3& p) { return p.z == 0.0; });
    out_.z_axis = flat ? ZAxis::kAbsent : ZAxis::kPresent;
    if (textures_) {
      options_.texture->uv.resize(out_.positions.size());
      options_.texture->triangle_image.resize(out_.triangles.size() / 3, -1);
    }
    if (any_colour_) {
      out_.colors.resize(out_.positions.size());
      for (const Uncoloured& u : uncoloured_)
        std::fill(out_.colors.begin() + std::ptrdiff_t(u.begin), out_.colors.begin() + std::ptrdiff_t(u.end), u.color);
    }
    return std::move(out_);
  }

  Status stream(GltfPointSink& sink) {
    pass_ = Pass::kCheck;
    if (Status s = walkScenes(); !s) return s;
    GltfSummary summary{emitted_total_, any_colour_, saysFlat(model_), {}};
    for (const GltfDimension& d : dimensions_) summary.dimensions.emplace_back(d.name, d.type);
    if (Status s = sink.begin(summary); !s) return s;
    pass_ = Pass::kEmit;
    sink_ = &sink;
    emitted_total_ = 0;
    block_.positions.reserve(kGltfStreamBlockPoints);
    if (any_colour_) block_.colors.reserve(kGltfStreamBlockPoints);
    for (const GltfDimension& d : dimensions_) block_.dimensions.append(d.name, d.type, kGltfStreamBlockPoints);
    if (Status s = walkScenes(); !s) return s;
    return block_.positions.empty() ? okStatus() : flushBlock();
  }

 private:
  enum class Pass { kBuild, kCheck, kEmit };

  // The application-specific SCALAR attributes of every primitive (dpoint's position residuals
  // aside), each once, by name, in the order of their first accessors (the order dpoint wrote
  // them in); a name stored in two types is read as float64.
  static std::vector<GltfDimension> findDimensions(const tinygltf::Model& model) {
    std::vector<GltfDimension> found;
    std::vector<int> first_accessor;
    for (const tinygltf::Mesh& mesh : model.meshes)
      for (const tinygltf::Primitive& primitive : mesh.primitives)
        for (const auto& [attribute, index] : primitive.attributes) {
          std::optional<GltfDimension> d = describe(model, attribute, index);
          if (!d) continue;
          auto same = std::find_if(found.begin(), found.end(), [&](const GltfDimension& f) { return f.name == d->name; });
          if (same == found.end()) {
            found.push_back(*d);
            first_accessor.push_back(index);
          } else {
            if (same->type != d->type) same->type = DimType::kF64;
            int& first = first_accessor[size_t(same - found.begin())];
            first = std::min(first, index);
          }
        }
    std::vector<size_t> order(found.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return first_accessor[a] < first_accessor[b]; });
    std::vector<GltfDimension> sorted;
    for (size_t i : order) sorted.push_back(std::move(found[i]));
    return sorted;
  }

  // The vertex attributes of the model's primitives that the set does not hold, each named once in
  // the order met: what is neither the position (and dpoint's residuals), COLOR_0, a dimension, nor
  // a sampled texture's TEXCOORD (a review found NORMAL and VEC3 attributes dropped without a word).
  static std::vector<std::string> attributesLeftOut(const tinygltf::Model& model, bool texture) {
    std::vector<std::string> out;
    for (const tinygltf::Mesh& mesh : model.meshes)
      for (const tinygltf::Primitive& primitive : mesh.primitives)
        for (const auto& [attribute, index] : primitive.attributes) {
          if (attribute == "POSITION" || attribute == "COLOR_0" || attribute == kGltfPositionLow ||
              attribute == kGltfPositionLow2 || (texture && attribute.rfind("TEXCOORD_", 0) == 0) ||
              describe(model, attribute, index) || std::find(out.begin(), out.end(), attribute) != out.end())
            continue;
          out.push_back(attribute);
        }
    return out;
  }

  // The dimension an attribute holds, if it is one (gltf_dimensions.h); the accessor is checked
  // when a primitive is read.
  static std::optional<GltfDimension> describe(const tinygltf::Model& model, const std::string& attribute, int index) {
    if (attribute.size() < 2 || attribute[0] != '_' || attribute == kGltfPositionLow || attribute == kGltfPositionLow2)
      return std::nullopt;
    if (index < 0 || size_t(index) >= model.accessors.size()) return std::nullopt;
    const tinygltf::Accessor& a = model.accessors[size_t(index)];
    const tinygltf::Value& facts = a.extras.Get("dpoint");
    std::string name;
    for (const KnownDimension& k : knownDimensions())
      if (attribute == k.gltf_attribute) name = k.name;
    if (name.empty()) name = gltfDimensionName(attribute);
    if (facts.IsObject() && facts.Get("name").IsString()) name = facts.Get("name").Get<std::string>();
    if (facts.IsObject() && facts.Get("type").IsString()) {
      const std::optional<DimType> type = parseDimType(facts.Get("type").Get<std::string>());
      if (type && dimTypeSize(*type) >= 4 && a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
          a.type == (dimTypeSize(*type) == 4 ? TINYGLTF_TYPE_VEC2 : TINYGLTF_TYPE_VEC4) && !a.normalized)
        return GltfDimension{attribute, name, *type};
    }
    const std::optional<DimType> type = scalarType(a.componentType);
    if (!type || a.type != TINYGLTF_TYPE_SCALAR || a.normalized) return std::nullopt;
    return GltfDimension{attribute, name, *type};
  }

  // The sources of a primitive's dimensions, checked: one per attribute that is one, of
  // POSITION's count.
  Result<std::vector<DimensionSource>> openDimensions(const tinygltf::Primitive& primitive, size_t count) const {
    std::vector<DimensionSource> sources;
    for (const auto& [attribute, index] : primitive.attributes) {
      const std::optional<GltfDimension> d = describe(model_, attribute, index);
      if (!d) continue;
      Result<AccessorElements> elements = decoder_.open(index);
      if (!elements) return elements.error();
      if (elements->count() != count)
        return decoder_.fail(index, attribute + " count " + std::to_string(elements->count()) +
                                        " differs from POSITION count " + std::to_string(count));
      size_t column = 0;
      while (dimensions_[column].name != d->name) ++column;
      sources.push_back({column, std::move(*elements), elements->components() > 1, d->type});
    }
    return sources;
  }

  Status walkScenes() {
    if (Status s = checkParents(); !s) return s;
    std::vector<std::vector<int>> scenes;
    if (Status s = sceneRoots(scenes); !s) return s;
    for (const std::vector<int>& roots : scenes) {
      on_path_.assign(model_.nodes.size(), false);
      visited_.assign(model_.nodes.size(), false);
      for (int root : roots)
        if (Status s = walk(root, glm::dmat4(1.0), 0); !s) return s;
    }
    return okStatus();
  }

  Error fail(const std::string& what, ExitCode code = ExitCode::kBadInput) const {
    return Error{path_ + ": " + what, code};
  }
  static std::string nodePointer(size_t i) { return "/nodes/" + std::to_string(i); }

  // Spec §3.5.1: nodes form disjoint trees. Checked over all nodes up front, so a node reached
  // twice can neither duplicate points nor make the walk exponential.
  Status checkParents() const {
    std::vector<int> parent(model_.nodes.size(), -1);
    for (size_t i = 0; i < model_.nodes.size(); ++i)
      for (int child : model_.nodes[i].children) {
        if (child < 0 || size_t(child) >= model_.nodes.size())
          return fail(nodePointer(i) + "/children: node " + std::to_string(child) + " does not exist");
        if (parent[size_t(child)] != -1)
          return fail(nodePointer(size_t(child)) + ": has two parents (nodes " + std::to_string(parent[size_t(child)]) +
                      " and " + std::to_string(i) + ")");
        parent[size_t(child)] = int(i);
      }
    return okStatus();
  }

  Status sceneRoots(std::vector<std::vector<int>>& scenes) const {
    if (model_.scenes.empty()) {
      // No scene: every node without a parent (a converter's reading of "the whole file"), as
      // scene 0; another --scene does not exist (a review finding: it read scene 0 in silence).
      if (options_.scene > 0)
        return fail("--scene: scene " + std::to_string(options_.scene) +
                    " does not exist (the file has no scene; its root nodes are read as scene 0)");
      std::vector<bool> is_child(model_.nodes.size(), false);
      for (const tinygltf::Node& node : model_.nodes)
        for (int child : node.children) is_child[size_t(child)] = true;  // indices checked above
      scenes.emplace_back();
      for (size_t i = 0; i < model_.nodes.size(); ++i)
        if (!is_child[i]) scenes.back().push_back(int(i));
      return okStatus();
    }
    if (options_.all_scenes) {
      for (const tinygltf::Scene& scene : model_.scenes) scenes.push_back(scene.nodes);
      return okStatus();
    }
    // tinygltf leaves defaultScene at -1 when the file names none.
    const int scene = options_.scene >= 0 ? options_.scene : model_.defaultScene == -1 ? 0 : model_.defaultScene;
    if (scene < 0 || size_t(scene) >= model_.scenes.size())
      return fail(std::string(options_.scene >= 0 ? "--scene" : "/scene") + ": scene " + std::to_string(scene) +
                  " does not exist (the file has " + std::to_string(model_.scenes.size()) + ")");
    scenes.push_back(model_.scenes[size_t(scene)].nodes);
    return okStatus();
  }

  Result<glm::dmat4> localMatrix(size_t index) const {
    const tinygltf::Node& node = model_.nodes[index];
    const std::string name = nodePointer(index);
    if (!node.matrix.empty()) {
      if (node.matrix.size() != 16)
        return fail(name + "/matrix: has " + std::to_string(node.matrix.size()) + " values, not 16");
      if (!allFinite(node.matrix)) return fail(name + "/matrix: has a non-finite value");
      glm::dmat4 m(1.0);
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[size_t(c * 4 + r)];  // column-major
      return m;
    }
    glm::dmat4 t(1.0), r(1.0), s(1.0);
    if (!node.translation.empty()) {
      if (node.translation.size() != 3 || !allFinite(node.translation))
        return fail(name + "/translation: must be 3 finite numbers");
      t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    }
    if (!node.rotation.empty()) {
      const std::vector<double>& q = node.rotation;
      if (q.size() != 4 || !allFinite(q)) return fail(name + "/rotation: must be 4 finite numbers");
      // Exporters write quaternions rounded to float; normalizing keeps R a pure rotation.
      const double length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (!(length > 0.0) || !std::isfinite(length)) return fail(name + "/rotation: zero or non-finite length");
      r = rotationMatrix(q[0] / length, q[1] / length, q[2] / length, q[3] / length);
    }
    if (!node.scale.empty()) {
      if (node.scale.size() != 3 || !allFinite(node.scale)) return fail(name + "/scale: must be 3 finite numbers");
      s[0][0] = node.scale[0];
      s[1][1] = node.scale[1];
      s[2][2] = node.scale[2];
    }
    return t * r * s;
  }

  // Where node `index` places its mesh: its world matrix, or with EXT_mesh_gpu_instancing one
  // matrix per instance, world · T·R·S of the instance's TRANSLATION, ROTATION and SCALE
  // (KhronosGroup/glTF extensions/2.0/Vendor/EXT_mesh_gpu_instancing), composed in double like
  // node transforms. The node's children are not instanced.
  Result<std::vector<glm::dmat4>> instanceMatrices(size_t index, const glm::dmat4& world) const {
    const auto ext_it = model_.nodes[index].extensions.find("EXT_mesh_gpu_instancing");
    if (ext_it == model_.nodes[index].extensions.end()) return std::vector<glm::dmat4>{world};
    const std::string pointer = nodePointer(index) + "/extensions/EXT_mesh_gpu_instancing";
    const tinygltf::Value& ext = ext_it->second;
    if (!ext.IsObject() || !ext.Has("attributes") || !ext.Get("attributes").IsObject())
      return fail(pointer + "/attributes: must be an object");
    const tinygltf::Value& attributes = ext.Get("attributes");
    struct Part {
      const char* name;
      int components;
      std::optional<AccessorElements> elements;
    };
    Part parts[3] = {{"TRANSLATION", 3, {}}, {"ROTATION", 4, {}}, {"SCALE", 3, {}}};
    std::optional<size_t> count;
    const char* count_from = nullptr;
    for (Part& part : parts) {
      if (!attributes.Has(part.name)) continue;
      const std::string at = pointer + "/attributes/" + part.name;
      const tinygltf::Value& v = attributes.Get(part.name);
      const double d = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
      if (!(d >= 0) || d > 2147483647.0 || d != std::floor(d)) return fail(at + ": must be an accessor index");
      const int accessor = int(d);
      Result<AccessorElements> elements = decoder_.open(accessor);
      if (!elements) return elements.error();
      const int ct = elements->componentType();
      // Float, or the integer forms KHR_mesh_quantization allows (ROTATION: normalized signed only).
      const bool float_type = ct == TINYGLTF_COMPONENT_TYPE_FLOAT;
      const bool type_ok = part.components == 4
                               ? float_type || ((ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_SHORT) &&
                                                elements->normalized())
                               : ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
      if (elements->components() != part.components || !type_ok)
        return fail(at + ": accessor " + std::to_string(accessor) + " must be VEC" + std::to_string(part.components) +
                    (part.components == 4 ? " of float or normalized byte/short" : " of float, (u)byte or (u)short") +
                    ", not " + std::to_string(elements->components()) + " components of componentType " +
                    std::to_string(ct));
      if (count && *count != elements->count())
        return fail(at + ": accessor " + std::to_string(accessor) + " has count " + std::to_string(elements->count()) +
                    ", " + count_from + " has " + std::to_string(*count) + " (all must be equal)");
      count = elements->count();
      count_from = part.name;
      part.elements = std::move(*elements);
    }
    if (!count) return fail(pointer + "/attributes: has none of TRANSLATION, ROTATION, SCALE");
    if (options_.max_points != 0 && *count > options_.max_points)
      return fail(pointer + ": " + std::to_string(*count) + " instances exceed " + options_.max_points_name + " " +
                      std::to_string(options_.max_points),
                  ExitCode::kResourceLimit);
    // 128 bytes of matrix per instance, from as little as 3 bytes of TRANSLATION.
    if (Status s = checkMemory(path_ + ": " + pointer + ": " + std::to_string(*count) + " instances",
                               *count * sizeof(glm::dmat4), memory_limit_);
        !s)
      return s.error();
    std::vector<glm::dmat4> placements;
    placements.reserve(*count);
    for (size_t e = 0; e < *count; ++e) {
      glm::dmat4 t(1.0), r(1.0), s(1.0);
      double q[4] = {0, 0, 0, 1};
      for (const Part& part : parts) {
        if (!part.elements) continue;
        double v[4] = {0, 0, 0, 0};
        for (int k = 0; k < part.components; ++k) v[k] = part.elements->value(e, k);
        if (!std::isfinite(v[0] + v[1] + v[2] + v[3]))
          return fail(pointer + "/attributes/" + part.name + ": instance " + std::to_string(e) + " is not finite");
        if (part.components == 4) {
          std::copy(v, v + 4, q);
        } else if (std::string_view(part.name) == "TRANSLATION") {
          t[3] = glm::dvec4(v[0], v[1], v[2], 1.0);
        } else {
          s[0][0] = v[0];
          s[1][1] = v[1];
          s[2][2] = v[2];
        }
      }
      // As for node rotations: quantized quaternions are not unit length; normalizing keeps R a rotation.
      const double length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (!(length > 0.0)) return fail(pointer + "/attributes/ROTATION: instance " + std::to_string(e) + " has zero length");
      r = rotationMatrix(q[0] / length, q[1] / length, q[2] / length, q[3] / length);
      placements.push_back(world * (t * r * s));
    }
    return placements;
  }

  Status walk(int index, const glm::dmat4& parent, int depth) {
    if (index < 0 || size_t(index) >= model_.nodes.size()) return fail("node " + std::to_string(index) + " does not exist");
    const size_t i = size_t(index);
    if (on_path_[i]) return fail(nodePointer(i) + ": cycle in the node hierarchy");
    if (visited_[i]) return fail(nodePointer(i) + ": reached twice in one scene");
    if (depth >= kMaxNodeDepth)
      return fail(nodePointer(i) + ": hierarchy deeper than " + std::to_string(kMaxNodeDepth) + " levels");
    on_path_[i] = visited_[i] = true;

    Result<glm::dmat4> local = localMatrix(i);
    if (!local) return local.error();
    const glm::dmat4 world = parent * *local;
    const tinygltf::Node& node = model_.nodes[i];
    if (node.mesh != -1) {  // -1: tinygltf's "no mesh"
      if (node.mesh < 0 || size_t(node.mesh) >= model_.meshes.size())
        return fail(nodePointer(i) + "/mesh: mesh " + std::to_string(node.mesh) + " does not exist");
      Result<std::vector<glm::dmat4>> placements = instanceMatrices(i, world);
      if (!placements) return placements.error();
      const tinygltf::Mesh& mesh = model_.meshes[size_t(node.mesh)];
      for (const glm::dmat4& placement : *placements)
        for (size_t p = 0; p < mesh.primitives.size(); ++p) {
          const std::string pointer = "/meshes/" + std::to_string(node.mesh) + "/primitives/" + std::to_string(p);
          if (Status s = readPrimitive(mesh.primitives[p], pointer, placement); !s) return s;
        }
    }
    for (int child : node.children)
      if (Status s = walk(child, world, depth + 1); !s) return s;
    on_path_[i] = false;
    return okStatus();
  }

  // POSITION checked (VEC3; float or, with KHR_mesh_quantization, (u)byte or (u)short), and
  // dpoint's residual attributes when present: float VEC3 of POSITION's count, POSITION float.
  Result<PositionParts> openPositions(const tinygltf::Primitive& primitive, int position_index,
                                      const std::string& pointer) const {
    Result<AccessorElements> hi = decoder_.open(position_index);
    if (!hi) return hi.error();
    const int ct = hi->componentType();
    // KHR_mesh_quantization admits (u)byte and (u)short, normalized or not; core glTF only float.
    if (hi->components() != 3 || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      return decoder_.fail(position_index, "POSITION must be VEC3 of float, (u)byte or (u)short, not " +
                                               std::to_string(hi->components()) + " components of type " +
                                               std::to_string(ct));
    PositionParts parts{std::move(*hi), std::nullopt, std::nullopt};
    const auto low_it = primitive.attributes.find(kGltfPositionLow);
    const auto low2_it = primitive.attributes.find(kGltfPositionLow2);
    if (low_it == primitive.attributes.end()) {
      if (low2_it != primitive.attributes.end())
        return fail(pointer + "/attributes/" + kGltfPositionLow2 + ": present without " + kGltfPositionLow);
      return parts;
    }
    if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT || parts.hi.normalized())
      return decoder_.fail(position_index, std::string("POSITION must be float when ") + kGltfPositionLow +
                                               " is present, not componentType " + std::to_string(ct));
    const auto openResidual = [&](const char* name, int index) -> Result<AccessorElements> {
      Result<AccessorElements> residual = decoder_.open(index);
      if (!residual) return residual.error();
      if (residual->components() != 3 || residual->componentType() != TINYGLTF_COMPONENT_TYPE_FLOAT ||
          residual->normalized())
        return decoder_.fail(index, std::string(name) + " must be VEC3 of float, like POSITION");
      if (residual->count() != parts.hi.count())
        return decoder_.fail(index, std::string(name) + " count " + std::to_string(residual->count()) +
                                        " differs from POSITION count " + std::to_string(parts.hi.count()));
      return residual;
    };
    Result<AccessorElements> mid = openResidual(kGltfPositionLow, low_it->second);
    if (!mid) return mid.error();
    parts.mid = std::move(*mid);
    if (low2_it != primitive.attributes.end()) {
      Result<AccessorElements> lo = openResidual(kGltfPositionLow2, low2_it->second);
      if (!lo) return lo.error();
      parts.lo = std::move(*lo);
    }
    return parts;
  }

  // chunk(begin, end) over [0, n) in chunks of 16K on all cores (one chunk, inline, for a small
  // primitive); chunk must be safe to call from several threads at once.
  template <typename Chunk>
  void eachChunk(size_t n, const Chunk& chunk) const {
    constexpr size_t kChunk = size_t{1} << 14;
    parallelFor((n + kChunk - 1) / kChunk, options_.threads,
                [&](size_t c, unsigned) { chunk(c * kChunk, std::min(n, (c + 1) * kChunk)); });
  }

  // body(i) for every i < n (eachChunk).
  template <typename Body>
  void everyIndex(size_t n, const Body& body) const {
    eachChunk(n, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) body(i);
    });
  }

  // The smallest i < n for which failing(i) holds, else n. failing runs as eachChunk's, is called
  // for every i below the one returned, and puts its side effects in slots of their own.
  template <typename Failing>
  size_t firstFailing(size_t n, const Failing& failing) const {
    std::atomic<size_t> first{n};
    eachChunk(n, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        if (i > first.load(std::memory_order_relaxed)) return;
        if (!failing(i)) continue;
        lowerAtomic(first, i);
        return;
      }
    });
    return first.load();
  }

  // The primitive's index accessor, checked (unsigned SCALAR, each element < vertex_count), with
  // the vertices it names marked in `remap` (sized vertex_count, kUnused elsewhere); nullopt when
  // the primitive is not indexed. The elements are read again for triangles rather than kept as
  // a copy: for large meshes that copy was the size of the output's triangle list.
  Result<std::optional<AccessorElements>> readIndices(const tinygltf::Primitive& primitive, size_t vertex_count,
                                                      std::vector<uint32_t>& remap) const {
    if (primitive.indices == -1) return std::optional<AccessorElements>();  // tinygltf's "no indices"
    Result<AccessorElements> elements = decoder_.open(primitive.indices);
    if (!elements) return elements.error();
    const int ct = elements->componentType();
    if (elements->components() != 1 || elements->normalized() ||
        (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
         ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
      return decoder_.fail(primitive.indices, "indices must be unsigned byte, short or int SCALAR, not componentType " +
                                                  std::to_string(ct));
    remap.assign(vertex_count, kUnused);
    // On all cores; the first index out of range (by element) is the one named.
    const AccessorElements& indices = *elements;
    const size_t bad = firstFailing(indices.count(), [&](size_t e) {
      const double v = indices.value(e, 0);  // an unsigned integer < 2^32, exact in double
      if (v >= double(vertex_count)) return true;
      std::atomic_ref<uint32_t>(remap[size_t(v)]).store(0, std::memory_order_relaxed);  // used
      return false;
    });
    if (bad < indices.count())
      return decoder_.fail(primitive.indices, "element " + std::to_string(bad) + " is " +
                                                  std::to_string(uint64_t(indices.value(bad, 0))) + ", out of range for " +
                                                  std::to_string(vertex_count) + " vertices");
    return std::optional<AccessorElements>(std::move(*elements));
  }

  Status readPrimitive(const tinygltf::Primitive& primitive, const std::string& pointer, const glm::dmat4& world) {
    if (interrupted()) return interruptedError();  // a scene may place a mesh many times over
    if (primitive.mode < 0 || primitive.mode > 6)
      return fail(pointer + "/mode: " + std::to_string(primitive.mode) + " is not a glTF primitive mode (0-6)");
    const auto position_it = primitive.attributes.find("POSITION");
    if (position_it == primitive.attributes.end()) return okStatus();  // nothing to place
    const int position_index = position_it->second;
    Result<PositionParts> positions = openPositions(primitive, position_index, pointer);
    if (!positions) return positions.error();
    const size_t count = positions->hi.count();

    // Which vertices the primitive references, renumbered in vertex order.
    std::vector<uint32_t> remap;
    Result<std::optional<AccessorElements>> indices = readIndices(primitive, count, remap);
    if (!indices) return indices.error();
    size_t emitted = count;
    if (*indices) {
      emitted = 0;
      for (uint32_t& r : remap)
        if (r != kUnused) r = uint32_t(emitted++);
    }
    const size_t begin = emitted_total_;  // in the build pass, out_.positions.size()
    if (options_.max_points != 0 && emitted > options_.max_points - std::min<uint64_t>(begin, options_.max_points))
      return fail("more than " + options_.max_points_name + " " + std::to_string(options_.max_points) + " points",
                  ExitCode::kResourceLimit);
    if (emitted > size_t(kUnused) - begin) return fail("more than 2^32-1 vertices", ExitCode::kResourceLimit);
    emitted_total_ += emitted;
    if (pass_ == Pass::kEmit) return emitPrimitive(primitive, pointer, *positions, remap, world);

    if (pass_ == Pass::kBuild) {
      // A mesh placed by many nodes or instances multiplies the set without more file.
      if (Status s = checkSetMemory(emitted_total_, out_.triangles.size()); !s) return s;
      reserveMore(out_.positions, emitted);
      out_.positions.resize(begin + emitted);  // unset: every used vertex is placed below, or this fails
    }
    // On all cores, each used vertex to its slot (the remap numbers them in element order); the
    // first that is not finite (by element) is the one named.
    const bool build = pass_ == Pass::kBuild;
    const size_t bad = firstFailing(count, [&](size_t e) {
      if (!remap.empty() && remap[e] == kUnused) return false;
      const glm::dvec3 w = placeVertex(*positions, world, e);
      if (!options_.allow_nonfinite && (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z))) return true;
      if (build) out_.positions[begin + (remap.empty() ? e : remap[e])] = w;
      return false;
    });
    if (bad < count) {
      const glm::dvec3 local = positions->local(bad);
      const bool local_finite = std::isfinite(local.x + local.y + local.z);
      return decoder_.fail(position_index, "POSITION element " + std::to_string(bad) + " is not finite" +
                                               (local_finite ? " in world space" : ""));
    }
    if (Status s = readColours(primitive, pointer, remap, count, begin, begin + emitted); !s) return s;
    Result<std::vector<DimensionSource>> sources = openDimensions(primitive, count);
    if (!sources) return sources.error();
    if (pass_ == Pass::kBuild && !dimensions_.empty()) {
      out_.dimensions.resize(begin + emitted);
      for (const DimensionSource& source : *sources) {
        Dimension& d = out_.dimensions.all()[source.column];
        for (size_t e = 0; e < count; ++e)
          if (remap.empty() || remap[e] != kUnused) source.store(d, begin + (remap.empty() ? e : remap[e]), e);
      }
    }

    // Triangles in the output numbering; points and lines add none.
    if (pass_ != Pass::kBuild || !options_.triangles) return okStatus();
    int32_t image = -1;  // the primitive's texture, when asked for
    if (textures_) {
      Result<int32_t> read = readTexCoords(primitive, pointer, remap, count, begin, begin + emitted);
      if (!read) return read.error();
      image = *read;
    }
    const AccessorElements* index_elements = *indices ? &**indices : nullptr;
    const size_t n = index_elements ? index_elements->count() : count;
    const auto vertex = [&](size_t i) -> uint32_t {
      // Indices were checked against the vertex count by readIndices.
      const uint32_t v = index_elements ? uint32_t(index_elements->value(i, 0)) : uint32_t(i);
      return uint32_t(begin) + (remap.empty() ? v : remap[v]);
    };
    const auto triangle = [&](size_t a, size_t b, size_t c) {
      out_.triangles.insert(out_.triangles.end(), {vertex(a), vertex(b), vertex(c)});
    };
    // Spec §3.7.2.1; a trailing incomplete triangle is not drawn (the validator warns, no error).
    // Reserved up front: growth by doubling briefly holds 1.5 times a large mesh's triangle list.
    size_t added = 0;
    if (primitive.mode == TINYGLTF_MODE_TRIANGLES)
      added = n / 3 * 3;
    else if ((primitive.mode == TINYGLTF_MODE_TRIANGLE_STRIP || primitive.mode == TINYGLTF_MODE_TRIANGLE_FAN) && n >= 3)
      added = 3 * (n - 2);
    if (Status s = checkSetMemory(emitted_total_, out_.triangles.size() + added); !s) return s;
    reserveMore(out_.triangles, added);
    if (primitive.mode == TINYGLTF_MODE_TRIANGLES) {  // on all cores, each triangle to its slot
      const size_t first = out_.triangles.size();
      out_.triangles.resize(first + added);
      uint32_t* out = out_.triangles.data() + first;
      everyIndex(added / 3, [&](size_t t) {
        for (size_t k = 0; k < 3; ++k) out[3 * t + k] = vertex(3 * t + k);
      });
    } else if (primitive.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (size_t i = 0; i + 3 <= n; ++i) triangle(i, i + 1 + i % 2, i + 2 - i % 2);
    } else if (primitive.mode == TINYGLTF_MODE_TRIANGLE_FAN) {
      for (size_t i = 0; i + 3 <= n; ++i) triangle(i + 1, i + 2, 0);
    }
    if (textures_) options_.texture->triangle_image.resize(out_.triangles.size() / 3, image);
    return okStatus();
  }

  // The texture coordinates of the primitive's points [emitted_begin, emitted_end) when its
  // material has a base-colour texture that decodes: its image in the MeshTexture, else -1.
  Result<int32_t> readTexCoords(const tinygltf::Primitive& primitive, const std::string& pointer,
                                const std::vector<uint32_t>& remap, size_t count, size_t emitted_begin,
                                size_t emitted_end) {
    MeshTexture& texture = *options_.texture;
    texture.triangle_image.resize(out_.triangles.size() / 3, -1);  // the triangles before this primitive's
    texture.uv.resize(emitted_end);
    Result<GltfTextureUse> use = textures_->use(primitive, pointer);
    if (!use) return use.error();
    if (use->image < 0) return -1;
    const std::string name = "TEXCOORD_" + std::to_string(use->tex_coord);
    const auto it = primitive.attributes.find(name);
    if (it == primitive.attributes.end()) {
      texture.notes.push_back(path_ + ": " + pointer + " has a base-colour texture but no " + name +
                              "; its triangles are sampled without it");
      return -1;
    }
    Result<AccessorElements> uv = decoder_.open(it->second);
    if (!uv) return uv.error();
    const int ct = uv->componentType();
    const bool type_ok = (ct == TINYGLTF_COMPONENT_TYPE_FLOAT && !uv->normalized()) ||
                         ((ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) &&
                          uv->normalized());
    if (uv->components() != 2 || !type_ok)
      return decoder_.fail(it->second, name + " must be VEC2 of float or normalized unsigned byte/short");
    if (uv->count() != count)
      return decoder_.fail(it->second, name + " count " + std::to_string(uv->count()) + " differs from POSITION count " +
                                           std::to_string(count));
    for (size_t e = 0; e < count; ++e) {
      if (!remap.empty() && remap[e] == kUnused) continue;
      const glm::dvec3 moved = use->transform * glm::dvec3(uv->value(e, 0), uv->value(e, 1), 1.0);
      if (!std::isfinite(moved.x) || !std::isfinite(moved.y))
        return decoder_.fail(it->second, name + " element " + std::to_string(e) + " is not finite");
      texture.uv[emitted_begin + (remap.empty() ? e : remap[e])] = glm::vec2(moved);
    }
    return use->image;
  }

  // The colour of a primitive without COLOR_0: its material's base colour, white without one.
  Result<glm::vec3> materialColour(const tinygltf::Primitive& primitive, const std::string& pointer) const {
    if (primitive.material == -1) return glm::vec3(1.0f);  // -1: tinygltf's "no material"
    if (primitive.material < 0 || size_t(primitive.material) >= model_.materials.size())
      return fail(pointer + "/material: material " + std::to_string(primitive.material) + " does not exist");
    const std::vector<double>& factor =
        model_.materials[size_t(primitive.material)].pbrMetallicRoughness.baseColorFactor;
    if (factor.size() != 4 || !allFinite(factor))
      return fail("/materials/" + std::to_string(primitive.material) +
                  "/pbrMetallicRoughness/baseColorFactor: must be 4 finite numbers");
    return glm::vec3(float(factor[0]), float(factor[1]), float(factor[2]));
  }

  // Checks the primitive's colours (and in the build pass stores them) for its points
  // [emitted_begin, emitted_end).
  Status readColours(const tinygltf::Primitive& primitive, const std::string& pointer,
                     const std::vector<uint32_t>& remap, size_t count, size_t emitted_begin, size_t emitted_end) {
    const auto colour_it = primitive.attributes.find("COLOR_0");
    if (colour_it == primitive.attributes.end()) {
      Result<glm::vec3> fill = materialColour(primitive, pointer);
      if (!fill) return fill.error();
      // A material's base colour other than the default white is the primitive's colour, kept
      // even when no primitive has COLOR_0 (a CAD model coloured by materials only).
      if (*fill != glm::vec3(1.0f)) any_colour_ = true;
      if (pass_ == Pass::kBuild) uncoloured_.push_back({emitted_begin, emitted_end, *fill});
      return okStatus();
    }
    const int index = colour_it->second;
    Result<AccessorElements> colours = decoder_.open(index);
    if (!colours) return colours.error();
    const int ct = colours->componentType();
    const bool type_ok = (ct == TINYGLTF_COMPONENT_TYPE_FLOAT && !colours->normalized()) ||
                         ((ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) &&
                          colours->normalized());
    if ((colours->components() != 3 && colours->components() != 4) || !type_ok)
      return decoder_.fail(index, "COLOR_0 must be VEC3/VEC4 of float or normalized unsigned byte/short");
    if (colours->count() != count)
      return decoder_.fail(index, "COLOR_0 count " + std::to_string(colours->count()) + " differs from POSITION count " +
                                      std::to_string(count));
    any_colour_ = true;
    const bool build = pass_ == Pass::kBuild;
    if (build) {
      out_.colors.resize(emitted_begin);  // earlier uncoloured primitives are filled at the end
      reserveMore(out_.colors, emitted_end - emitted_begin);
      out_.colors.resize(emitted_end);  // unset: every used vertex's colour is set below, or this fails
    }
    // On all cores, like the positions; the first colour that is not finite (by element) is named.
    const AccessorElements& elements = *colours;
    const size_t bad = firstFailing(count, [&](size_t e) {
      if (!remap.empty() && remap[e] == kUnused) return false;
      const glm::vec3 c = vertexColour(elements, e);
      if (!std::isfinite(c.r) || !std::isfinite(c.g) || !std::isfinite(c.b)) return true;
      if (build) out_.colors[emitted_begin + (remap.empty() ? e : remap[e])] = c;
      return false;
    });
    if (bad < count) return decoder_.fail(index, "COLOR_0 element " + std::to_string(bad) + " is not finite");
    return okStatus();
  }

  // The emitting pass: the primitive's points (and colours, when the checking pass found any) in
  // the build pass's order. The checking pass made every check on the same data, so none fails.
  Status emitPrimitive(const tinygltf::Primitive& primitive, const std::string& pointer,
                       const PositionParts& positions, const std::vector<uint32_t>& remap, const glm::dmat4& world) {
    std::optional<AccessorElements> colours;
    glm::vec3 fill(1.0f);
    if (any_colour_) {
      const auto colour_it = primitive.attributes.find("COLOR_0");
      if (colour_it != primitive.attributes.end()) {
        Result<AccessorElements> opened = decoder_.open(colour_it->second);
        if (!opened) return opened.error();
        colours = std::move(*opened);
      } else {
        Result<glm::vec3> material = materialColour(primitive, pointer);
        if (!material) return material.error();
        fill = *material;
      }
    }
    Result<std::vector<DimensionSource>> sources = openDimensions(primitive, positions.hi.count());
    if (!sources) return sources.error();
    std::vector<bool> has(dimensions_.size(), false);
    for (const DimensionSource& source : *sources) has[source.column] = true;
    for (size_t e = 0; e < positions.hi.count(); ++e) {
      if (!remap.empty() && remap[e] == kUnused) continue;
      const size_t at = block_.positions.size();
      for (size_t c = 0; c < dimensions_.size(); ++c)
        if (!has[c]) block_.dimensions.all()[c].setValue(at, 0.0);
      for (const DimensionSource& source : *sources) source.store(block_.dimensions.all()[source.column], at, e);
      block_.positions.push_back(placeVertex(positions, world, e));
      if (any_colour_) block_.colors.push_back(colours ? vertexColour(*colours, e) : fill);
      if (block_.positions.size() == kGltfStreamBlockPoints)
        if (Status s = flushBlock(); !s) return s;
    }
    return okStatus();
  }

  // The build pass's point set at `points` points (colours counted: any later primitive may bring
  // them) and `indices` triangle indices, against --max-memory.
  Status checkSetMemory(size_t points, size_t indices) const {
    const uint64_t bytes = uint64_t(points) * (sizeof(glm::dvec3) + sizeof(glm::vec3)) + uint64_t(indices) * sizeof(uint32_t);
    if (bytes <= memory_limit_) return okStatus();
    return checkMemory(path_ + ": the scene's " + std::to_string(points) + " points and " + std::to_string(indices / 3) +
                           " triangles",
                       bytes, memory_limit_);
  }

  Status flushBlock() {
    block_.dimensions.resize(block_.positions.size());
    Status s = sink_->points(block_);
    block_.positions.clear();
    block_.colors.clear();
    block_.dimensions.resize(kGltfStreamBlockPoints);
    return s;
  }

  const std::string& path_;
  const tinygltf::Model& model_;
  const GltfReadOptions& options_;
  uint64_t memory_limit_;  // --max-memory, resolved
  AccessorDecoder decoder_;
  Pass pass_ = Pass::kBuild;
  size_t emitted_total_ = 0;  // points placed so far in this pass
  PointSet out_;              // the build pass's result
  std::vector<bool> on_path_, visited_;
  std::vector<Uncoloured> uncoloured_;
  bool any_colour_ = false;  // kept from the checking pass into the emitting pass
  std::vector<GltfDimension> dimensions_;  // findDimensions: the set's columns, in this order
  GltfPointSink* sink_ = nullptr;
  PointSet block_;  // emitting pass: points not yet handed to sink_
  std::optional<GltfTextures> textures_;  // when options_.texture asks for them
};

}  // namespace

Result<PointSet> readGltf(const std::string& path, const GltfReadOptions& options) {
  Result<InputFile> input = InputFile::open(path);
  if (!input) return input.error();
  return readGltf(*input, options);
}

Result<PointSet> readGltf(const InputFile& input, const GltfReadOptions& options) {
  const std::string& path = input.path();
  try {
    Result<tinygltf::Model> model =
        loadGltfModel(input, options.max_file_bytes, options.max_memory, options.texture != nullptr);
    if (!model) return model.error();
    Result<PointSet> read = SceneReader(path, *model, options).read();
    if (read) SceneReader::noteLeftOut(path, *model, options);
    return read;
  } catch (const std::bad_alloc&) {
    return Error{path + ": out of memory while converting", ExitCode::kResourceLimit};
  }
}

Status streamGltf(const std::string& path, const GltfReadOptions& options, GltfPointSink& sink) {
  Result<InputFile> input = InputFile::open(path);
  if (!input) return input.error();
  return streamGltf(*input, options, sink);
}

Status streamGltf(const InputFile& input, const GltfReadOptions& options, GltfPointSink& sink) {
  const std::string& path = input.path();
  try {
    Result<tinygltf::Model> model = loadGltfModel(input, options.max_file_bytes, options.max_memory);
    if (!model) return model.error();
    Status streamed = SceneReader(path, *model, options).stream(sink);
    if (streamed) SceneReader::noteLeftOut(path, *model, options);
    return streamed;
  } catch (const std::bad_alloc&) {
    return Error{path + ": out of memory while converting", ExitCode::kResourceLimit};
  }
}

Result<std::vector<double>> readGltfAccessor(const std::string& path, int index) {
  Result<InputFile> input = InputFile::open(path);
  if (!input) return input.error();
  try {
    Result<tinygltf::Model> model = loadGltfModel(*input, kGltfDefaultMaxFileBytes, 0);
    if (!model) return model.error();
    AccessorDecoder decoder(path, *model, kMaxUnbackedValues);
    Result<AccessorElements> elements = decoder.open(index);
    if (!elements) return elements.error();
    std::vector<double> values;
    values.reserve(elements->count() * size_t(elements->components()));
    for (size_t e = 0; e < elements->count(); ++e)
      for (int k = 0; k < elements->components(); ++k) values.push_back(elements->value(e, k));
    return values;
  } catch (const std::bad_alloc&) {
    return Error{path + ": out of memory while decoding", ExitCode::kResourceLimit};
  }
}

}  // namespace dpoint
