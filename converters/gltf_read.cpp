// glTF/GLB input. tinygltf parses the JSON and fetches buffers; everything after that is ours:
// tinygltf 2.7.0 does not check accessors against their buffer views, so every byte we read is
// bounds-checked here first, with arithmetic that cannot overflow (hostile counts and offsets
// are size_t values straight from the JSON).
//
// Node transforms are composed in double (glTF 2.0 spec §3.5.3: local = T·R·S, or `matrix`),
// so positions stored relative to a far-away node translation keep their float precision.
#include "converters/gltf_read.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
#include <limits>
#include <vector>

#include "core/input_file.h"

namespace dpoint {
namespace {

static_assert(std::endian::native == std::endian::little, "glTF buffers are little-endian");

// Deeper than any real scene graph; it bounds our recursion on hostile files.
constexpr int kMaxNodeDepth = 64;

std::string typeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return std::to_string(type);
  }
}

size_t componentSize(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;  // callers accept only the types above
  }
}

// offset + stride·(count−1) + elem_size ≤ limit, without overflow. Needs stride ≥ elem_size ≥ 1.
bool fitsIn(size_t offset, size_t stride, size_t count, size_t elem_size, size_t limit) {
  if (count == 0) return offset <= limit;
  if (offset > limit || elem_size > limit - offset) return false;
  return count - 1 <= (limit - offset - elem_size) / stride;
}

template <typename T>
T load(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));  // buffer data has no alignment guarantee
  return value;
}

// Rotation matrix of a unit quaternion (x, y, z, w), column-major like glm. Written out rather
// than via glm::dquat because glm's quaternion constructor order depends on configuration macros.
glm::dmat4 rotationMatrix(double x, double y, double z, double w) {
  glm::dmat4 r(1.0);
  r[0] = glm::dvec4(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0);
  r[1] = glm::dvec4(2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0);
  r[2] = glm::dvec4(2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0);
  return r;
}

bool allFinite(const std::vector<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

// Where an accessor's elements lie, after every bound was checked.
struct Span {
  const unsigned char* first = nullptr;
  size_t stride = 0;
  size_t count = 0;
};

// A primitive without COLOR_0; it gets its material colour if any other primitive has colours.
struct Uncoloured {
  size_t begin = 0, end = 0;
  glm::vec3 color{1.0f};
};

class SceneReader {
 public:
  SceneReader(const std::string& path, const tinygltf::Model& model) : path_(path), model_(model) {}

  Result<PointSet> read() {
    std::vector<int> roots;
    if (Status s = sceneRoots(roots); !s) return s.error();
    on_path_.assign(model_.nodes.size(), false);
    visited_.assign(model_.nodes.size(), false);
    for (int root : roots) {
      if (Status s = walk(root, glm::dmat4(1.0), 0); !s) return s.error();
    }
    if (any_colour_) {
      out_.colors.resize(out_.positions.size());
      for (const Uncoloured& u : uncoloured_)
        std::fill(out_.colors.begin() + std::ptrdiff_t(u.begin),
                  out_.colors.begin() + std::ptrdiff_t(u.end), u.color);
    }
    return std::move(out_);
  }

 private:
  Error fail(const std::string& what) const { return Error{path_ + ": " + what}; }

  // The default scene, else scene 0, else every node that is nobody's child.
  Status sceneRoots(std::vector<int>& roots) const {
    if (!model_.scenes.empty()) {
      // tinygltf leaves defaultScene at -1 when the file names none.
      const int scene = model_.defaultScene == -1 ? 0 : model_.defaultScene;
      if (scene < 0 || size_t(scene) >= model_.scenes.size())
        return fail("scene " + std::to_string(scene) + " does not exist");
      roots = model_.scenes[size_t(scene)].nodes;
      return okStatus();
    }
    std::vector<bool> is_child(model_.nodes.size(), false);
    for (const tinygltf::Node& node : model_.nodes)
      for (int child : node.children)
        if (child >= 0 && size_t(child) < is_child.size()) is_child[size_t(child)] = true;
    for (size_t i = 0; i < model_.nodes.size(); ++i)
      if (!is_child[i]) roots.push_back(static_cast<int>(i));
    return okStatus();
  }

  Result<glm::dmat4> localMatrix(size_t index) const {
    const tinygltf::Node& node = model_.nodes[index];
    const std::string name = "node " + std::to_string(index) + ": ";
    if (!node.matrix.empty()) {
      if (node.matrix.size() != 16)
        return fail(name + "matrix has " + std::to_string(node.matrix.size()) + " values, not 16");
      if (!allFinite(node.matrix)) return fail(name + "matrix has a non-finite value");
      glm::dmat4 m(1.0);
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[size_t(c * 4 + r)];  // column-major
      return m;
    }
    glm::dmat4 t(1.0), r(1.0), s(1.0);
    if (!node.translation.empty()) {
      if (node.translation.size() != 3 || !allFinite(node.translation))
        return fail(name + "translation must be 3 finite numbers");
      t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    }
    if (!node.rotation.empty()) {
      const std::vector<double>& q = node.rotation;
      if (q.size() != 4 || !allFinite(q)) return fail(name + "rotation must be 4 finite numbers");
      // Exporters write quaternions rounded to float; normalizing keeps R a pure rotation.
      const double length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (!(length > 0.0) || !std::isfinite(length))
        return fail(name + "rotation quaternion has zero or non-finite length");
      r = rotationMatrix(q[0] / length, q[1] / length, q[2] / length, q[3] / length);
    }
    if (!node.scale.empty()) {
      if (node.scale.size() != 3 || !allFinite(node.scale))
        return fail(name + "scale must be 3 finite numbers");
      s[0][0] = node.scale[0];
      s[1][1] = node.scale[1];
      s[2][2] = node.scale[2];
    }
    return t * r * s;
  }

  Status walk(int index, const glm::dmat4& parent, int depth) {
    if (index < 0 || size_t(index) >= model_.nodes.size())
      return fail("node " + std::to_string(index) + " does not exist");
    const size_t i = size_t(index);
    if (on_path_[i]) return fail("node " + std::to_string(index) + ": cycle in the node hierarchy");
    // Spec §3.5.1: nodes form disjoint trees. A node reached twice could otherwise make the walk
    // exponential (each level pointing twice at the next).
    if (visited_[i]) return fail("node " + std::to_string(index) + " has more than one parent");
    if (depth >= kMaxNodeDepth)
      return fail("node " + std::to_string(index) + ": hierarchy deeper than " +
                  std::to_string(kMaxNodeDepth) + " levels");
    on_path_[i] = visited_[i] = true;

    Result<glm::dmat4> local = localMatrix(i);
    if (!local) return local.error();
    const glm::dmat4 world = parent * *local;
    const tinygltf::Node& node = model_.nodes[i];
    if (node.mesh != -1) {  // -1: tinygltf's "no mesh"
      if (node.mesh < 0 || size_t(node.mesh) >= model_.meshes.size())
        return fail("node " + std::to_string(index) + ": mesh " + std::to_string(node.mesh) +
                    " does not exist");
      const tinygltf::Mesh& mesh = model_.meshes[size_t(node.mesh)];
      for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        if (Status s = readPrimitive(mesh.primitives[p], world); !s) return s;
      }
    }
    for (int child : node.children) {
      if (Status s = walk(child, world, depth + 1); !s) return s;
    }
    on_path_[i] = false;
    return okStatus();
  }

  // Checks the accessor's structure and every byte it covers; the caller has checked its types.
  Result<Span> locate(int index, size_t elem_size) const {
    const std::string name = "accessor " + std::to_string(index) + ": ";
    const tinygltf::Accessor& accessor = model_.accessors[size_t(index)];
    if (accessor.sparse.isSparse) return fail(name + "sparse accessors are not supported yet");
    if (accessor.bufferView < 0)
      return fail(name + "accessors without a bufferView are not supported yet");
    if (size_t(accessor.bufferView) >= model_.bufferViews.size())
      return fail(name + "bufferView " + std::to_string(accessor.bufferView) + " does not exist");
    const tinygltf::BufferView& view = model_.bufferViews[size_t(accessor.bufferView)];
    const std::string view_name = "bufferView " + std::to_string(accessor.bufferView);
    if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
      return fail(name + view_name + ": buffer " + std::to_string(view.buffer) + " does not exist");
    const std::vector<unsigned char>& data = model_.buffers[size_t(view.buffer)].data;
    if (!fitsIn(view.byteOffset, 1, 1, view.byteLength, data.size()))
      return fail(name + view_name + ": byteOffset " + std::to_string(view.byteOffset) +
                  " + byteLength " + std::to_string(view.byteLength) +
                  " is past the end of buffer " + std::to_string(view.buffer) + " (" +
                  std::to_string(data.size()) + " bytes)");
    const size_t stride = view.byteStride == 0 ? elem_size : view.byteStride;
    if (stride < elem_size)
      return fail(name + view_name + ": byteStride " + std::to_string(stride) +
                  " is smaller than the element size " + std::to_string(elem_size));
    if (!fitsIn(accessor.byteOffset, stride, accessor.count, elem_size, view.byteLength))
      return fail(name + std::to_string(accessor.count) + " elements of " +
                  std::to_string(elem_size) + " bytes from byteOffset " +
                  std::to_string(accessor.byteOffset) + " with stride " + std::to_string(stride) +
                  " run past the end of " + view_name + " (" + std::to_string(view.byteLength) +
                  " bytes)");
    return Span{data.data() + view.byteOffset + accessor.byteOffset, stride, accessor.count};
  }

  Result<Span> attribute(const tinygltf::Primitive& primitive, const char* semantic,
                         int& index) const {
    index = primitive.attributes.at(semantic);
    if (index < 0 || size_t(index) >= model_.accessors.size())
      return fail(std::string(semantic) + " accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& accessor = model_.accessors[size_t(index)];
    const std::string name = "accessor " + std::to_string(index) + ": " + semantic;
    const bool position = std::strcmp(semantic, "POSITION") == 0;
    const bool vec_ok =
        accessor.type == TINYGLTF_TYPE_VEC3 || (!position && accessor.type == TINYGLTF_TYPE_VEC4);
    if (!vec_ok) return fail(name + " type " + typeName(accessor.type) + " not supported yet");
    const int ct = accessor.componentType;
    const bool float_ok = ct == TINYGLTF_COMPONENT_TYPE_FLOAT && !accessor.normalized;
    const bool unorm_ok = !position && accessor.normalized &&
                          (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                           ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    if (!float_ok && !unorm_ok)
      return fail(name + " componentType " + std::to_string(ct) +
                  (accessor.normalized ? " normalized" : "") + " not supported yet");
    const size_t components = accessor.type == TINYGLTF_TYPE_VEC4 ? 4 : 3;
    return locate(index, components * componentSize(ct));
  }

  Status readPrimitive(const tinygltf::Primitive& primitive, const glm::dmat4& world) {
    if (primitive.attributes.count("POSITION") == 0) return okStatus();  // nothing to place
    int position_index = -1;
    Result<Span> positions = attribute(primitive, "POSITION", position_index);
    if (!positions) return positions.error();
    const size_t begin = out_.positions.size();
    const size_t count = positions->count;
    if (count > std::numeric_limits<uint32_t>::max() - begin)
      return Error{path_ + ": more than 2^32-1 vertices", ExitCode::kResourceLimit};

    out_.positions.reserve(begin + count);
    for (size_t e = 0; e < count; ++e) {
      const unsigned char* p = positions->first + e * positions->stride;
      const glm::dvec4 local(load<float>(p), load<float>(p + 4), load<float>(p + 8), 1.0);
      const glm::dvec3 w = glm::dvec3(world * local);
      if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z))
        return fail("accessor " + std::to_string(position_index) + ": element " +
                    std::to_string(e) + ": position is not finite in world space");
      out_.positions.push_back(w);
    }

    if (Status s = readColours(primitive, begin, count); !s) return s;
    if (primitive.mode == TINYGLTF_MODE_TRIANGLES) return readTriangles(primitive, begin, count);
    return okStatus();  // other modes: the vertices as points (issue #4 adds lines and strips)
  }

  Status readColours(const tinygltf::Primitive& primitive, size_t begin, size_t count) {
    if (primitive.attributes.count("COLOR_0") == 0) {
      glm::vec3 fill(1.0f);
      if (primitive.material != -1) {  // -1: tinygltf's "no material"
        const std::string name = "material " + std::to_string(primitive.material);
        if (primitive.material < 0 || size_t(primitive.material) >= model_.materials.size())
          return fail(name + " does not exist");
        const std::vector<double>& factor =
            model_.materials[size_t(primitive.material)].pbrMetallicRoughness.baseColorFactor;
        if (factor.size() != 4 || !allFinite(factor))
          return fail(name + ": baseColorFactor must be 4 finite numbers");
        fill = glm::vec3(float(factor[0]), float(factor[1]), float(factor[2]));
      }
      uncoloured_.push_back({begin, begin + count, fill});
      return okStatus();
    }
    int index = -1;
    Result<Span> colours = attribute(primitive, "COLOR_0", index);
    if (!colours) return colours.error();
    if (colours->count != count)
      return fail("accessor " + std::to_string(index) + ": COLOR_0 count " +
                  std::to_string(colours->count) + " differs from POSITION count " +
                  std::to_string(count));
    const int ct = model_.accessors[size_t(index)].componentType;
    any_colour_ = true;
    out_.colors.resize(begin);  // earlier uncoloured primitives are filled at the end
    out_.colors.reserve(begin + count);
    for (size_t e = 0; e < count; ++e) {
      const unsigned char* p = colours->first + e * colours->stride;
      glm::vec3 c;
      for (int k = 0; k < 3; ++k) {
        // Normalized integers: spec §3.11, value / (2^bits − 1).
        if (ct == TINYGLTF_COMPONENT_TYPE_FLOAT)
          c[k] = load<float>(p + 4 * k);
        else if (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE)
          c[k] = float(p[k]) / 255.0f;
        else
          c[k] = float(load<uint16_t>(p + 2 * k)) / 65535.0f;
      }
      if (!std::isfinite(c.r) || !std::isfinite(c.g) || !std::isfinite(c.b))
        return fail("accessor " + std::to_string(index) + ": element " + std::to_string(e) +
                    ": COLOR_0 is not finite");
      out_.colors.push_back(c);
    }
    return okStatus();
  }

  Status readTriangles(const tinygltf::Primitive& primitive, size_t begin, size_t count) {
    const uint32_t base = static_cast<uint32_t>(begin);  // begin + count ≤ 2^32−1 was checked
    if (primitive.indices == -1) {                       // tinygltf's "no indices"
      // Non-indexed triangles: consecutive vertex triples (spec §3.7.2.1).
      if (count % 3 != 0)
        return fail("TRIANGLES primitive has " + std::to_string(count) +
                    " vertices and no indices, not a multiple of 3");
      for (size_t e = 0; e < count; ++e) out_.triangles.push_back(base + static_cast<uint32_t>(e));
      return okStatus();
    }
    const int index = primitive.indices;
    if (index < 0 || size_t(index) >= model_.accessors.size())
      return fail("indices accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& accessor = model_.accessors[size_t(index)];
    const std::string name = "accessor " + std::to_string(index) + ": indices";
    const int ct = accessor.componentType;
    if (accessor.type != TINYGLTF_TYPE_SCALAR || accessor.normalized || componentSize(ct) == 0 ||
        ct == TINYGLTF_COMPONENT_TYPE_FLOAT)
      return fail(name + " must be unsigned byte/short/int SCALAR, not componentType " +
                  std::to_string(ct) + " " + typeName(accessor.type));
    Result<Span> span = locate(index, componentSize(ct));
    if (!span) return span.error();
    if (span->count % 3 != 0)
      return fail(name + " count " + std::to_string(span->count) + " is not a multiple of 3");
    out_.triangles.reserve(out_.triangles.size() + span->count);
    for (size_t e = 0; e < span->count; ++e) {
      const unsigned char* p = span->first + e * span->stride;
      uint32_t v = ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? p[0]
                   : ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? load<uint16_t>(p)
                                                                  : load<uint32_t>(p);
      if (v >= count)
        return fail(name + " element " + std::to_string(e) + " is " + std::to_string(v) +
                    ", out of range for " + std::to_string(count) + " vertices");
      out_.triangles.push_back(base + v);
    }
    return okStatus();
  }

  const std::string& path_;
  const tinygltf::Model& model_;
  PointSet out_;
  std::vector<bool> on_path_, visited_;
  std::vector<Uncoloured> uncoloured_;
  bool any_colour_ = false;
};

std::string oneLine(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  std::replace(text.begin(), text.end(), '\n', ';');
  return text.empty() ? "tinygltf gave no reason" : text;
}

// External files (buffers, images) must lie in the model's folder (DESIGN §9). tinygltf also
// looks in the current directory; these callbacks refuse anything outside the folder.
struct FolderJail {
  std::filesystem::path folder;
};

bool insideJail(const std::string& path, void* user) {
  const auto* jail = static_cast<const FolderJail*>(user);
  std::error_code ec;
  const std::filesystem::path full = std::filesystem::weakly_canonical(path, ec);
  if (ec) return false;
  const auto mismatch =
      std::mismatch(jail->folder.begin(), jail->folder.end(), full.begin(), full.end());
  return mismatch.first == jail->folder.end();
}

bool jailedFileExists(const std::string& path, void* user) {
  return insideJail(path, user) && tinygltf::FileExists(path, nullptr);
}

std::string noExpansion(const std::string& path, void*) { return path; }

bool jailedReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                         void* user) {
  if (!insideJail(path, user)) {
    if (err) *err += "'" + path + "' is outside the model's folder";
    return false;
  }
  return tinygltf::ReadWholeFile(out, err, path, nullptr);
}

bool refuseWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "the reader writes no files";
  return false;
}

// We take points, never textures: keep the bytes undecoded instead of running stb_image on them.
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int,
               const unsigned char*, int, void*) {
  return true;
}

}  // namespace

Result<PointSet> readGltf(const std::string& path) {
  Result<InputFile> input = InputFile::open(path);
  if (!input) return input.error();
  if (input->size() == 0) return Error{path + ": file is empty"};

  // GLB stores its length in 32 bits and tinygltf takes an unsigned int length.
  if (input->size() > std::numeric_limits<uint32_t>::max())
    return Error{path + ": larger than the 4 GiB glTF limit", ExitCode::kResourceLimit};
  std::vector<unsigned char> bytes(input->size());
  Result<size_t> got = input->readAt(0, bytes.data(), bytes.size());
  if (!got) return got.error();
  if (*got != bytes.size()) return Error{path + ": the file shrank while being read"};

  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  bool binary = extension == ".glb";
  if (extension != ".glb" && extension != ".gltf")
    binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;

  // External URIs resolve against the folder the path names (as tinygltf does); the jail is that
  // folder with links resolved.
  std::error_code ec;
  const std::filesystem::path folder = std::filesystem::absolute(path, ec).parent_path();
  FolderJail jail;
  if (!ec) jail.folder = std::filesystem::weakly_canonical(folder, ec);
  if (ec) return Error{path + ": cannot resolve its folder: " + ec.message()};
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(
      {&jailedFileExists, &noExpansion, &jailedReadWholeFile, &refuseWrite, &jail});
  loader.SetImageLoader(&skipImage, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const auto length = static_cast<unsigned int>(bytes.size());
  const bool loaded =
      binary
          ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), length, folder.string())
          : loader.LoadASCIIFromString(&model, &err, &warn,
                                       reinterpret_cast<const char*>(bytes.data()), length,
                                       folder.string());
  if (!loaded) return Error{path + ": " + oneLine(err)};
  // tinygltf copied the buffers out; free the file image before decoding.
  std::vector<unsigned char>().swap(bytes);
  return SceneReader(path, model).read();
}

}  // namespace dpoint
