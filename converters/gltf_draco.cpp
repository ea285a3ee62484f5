// KHR_draco_mesh_compression decoding through Debian's libdraco (KhronosGroup/glTF
// extensions/2.0/Khronos/KHR_draco_mesh_compression). The extension's rules are checked here, and
// so is everything libdraco hands back before we read through it: the decoded attribute buffers
// are read by index arithmetic (PointAttribute::GetAddress checks nothing), and a hostile file
// may name attribute ids, counts and types that do not match what the bitstream holds.
//
// libdraco decodes quantized attributes back to their original type (POSITION to float), which is
// what the glTF accessor then declares; both are compared rather than converted, since a glTF
// writer that stored other types than Draco decodes wrote a broken file.
#include "converters/gltf_draco.h"

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <memory>

#include "converters/gltf_accessor.h"
#include "core/text.h"

namespace dpoint {
namespace {

constexpr const char* kExtension = "KHR_draco_mesh_compression";

draco::DataType dracoTypeOf(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return draco::DT_INT8;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return draco::DT_UINT8;
    case TINYGLTF_COMPONENT_TYPE_SHORT: return draco::DT_INT16;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return draco::DT_UINT16;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return draco::DT_UINT32;
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return draco::DT_FLOAT32;
    default: return draco::DT_INVALID;
  }
}

std::string dracoTypeName(draco::DataType type) {
  static const char* const kNames[] = {"invalid", "int8",   "uint8",  "int16",   "uint16",  "int32",
                                       "uint32",  "int64",  "uint64", "float32", "float64", "bool"};
  const int i = int(type);
  return i >= 0 && i < int(std::size(kNames)) ? kNames[i] : "type " + std::to_string(i);
}

std::string oneLine(const std::string& text) { return oneLineText(text, "no reason given"); }

class PrimitiveDecoder {
 public:
  PrimitiveDecoder(const std::string& path, tinygltf::Model& model, uint64_t max_decoded_bytes)
      : path_(path), model_(model), limit_(max_decoded_bytes), budget_(max_decoded_bytes) {}

  Status decode(size_t mesh_index, size_t primitive_index) {
    mesh_ = mesh_index;
    primitive_ = primitive_index;
    primitive_pointer_ = "/meshes/" + std::to_string(mesh_index) + "/primitives/" + std::to_string(primitive_index);
    pointer_ = primitive_pointer_ + "/extensions/" + kExtension;
    // Copied: the model's vectors grow below, and the primitive's attributes are rewritten.
    const tinygltf::Value ext = primitive().extensions.at(kExtension);
    if (!ext.IsObject()) return fail("", "must be an object");
    Result<size_t> view_index = integer(ext, "bufferView");
    if (!view_index) return view_index.error();
    if (!ext.Has("attributes") || !ext.Get("attributes").IsObject()) return fail("/attributes", "must be an object");
    const tinygltf::Value& attribute_ids = ext.Get("attributes");
    std::vector<std::pair<std::string, uint32_t>> listed;
    for (const std::string& name : attribute_ids.Keys()) {
      Result<size_t> id = integer(attribute_ids, name.c_str(), "/attributes/");
      if (!id) return id.error();
      if (!primitive().attributes.count(name))
        return fail("/attributes/" + printableExcerpt(name),
                    "is not an attribute of the primitive (the extension's must be a subset)");
      listed.emplace_back(name, uint32_t(*id));
    }
    const int mode = primitive().mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP)
      return Error{path_ + ": " + primitive_pointer_ + "/mode: " + std::to_string(mode) +
                   " is not allowed with " + kExtension + " (only TRIANGLES or TRIANGLE_STRIP)"};

    // The compressed bytes: the view inside its buffer, both tested by subtraction.
    if (*view_index >= model_.bufferViews.size())
      return fail("/bufferView", "bufferView " + std::to_string(*view_index) + " does not exist");
    const tinygltf::BufferView& view = model_.bufferViews[*view_index];
    if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
      return fail("/bufferView", "bufferView " + std::to_string(*view_index) + ": buffer " +
                                     std::to_string(view.buffer) + " does not exist");
    const std::vector<unsigned char>& source = model_.buffers[size_t(view.buffer)].data;
    if (view.byteOffset > source.size() || view.byteLength > source.size() - view.byteOffset)
      return fail("/bufferView", "bufferView " + std::to_string(*view_index) + ": byteOffset " +
                                     std::to_string(view.byteOffset) + " + byteLength " + std::to_string(view.byteLength) +
                                     " exceeds buffer " + std::to_string(view.buffer) + " length " +
                                     std::to_string(source.size()));
    if (view.byteLength == 0) return fail("/bufferView", "bufferView " + std::to_string(*view_index) + " is empty");

    // What we will write, from the accessors' declared shapes, against the budget before decoding.
    std::vector<Target> targets;
    for (const auto& [name, id] : listed) {
      if (name != "POSITION" && name != "COLOR_0") continue;
      Result<Target> t = target(primitive().attributes.at(name), name);
      if (!t) return t.error();
      t->draco_id = id;
      targets.push_back(*t);
    }
    uint64_t needed = 0;
    for (const Target& t : targets) needed += uint64_t(t.count) * t.element_size;  // each < 2^31 · 16
    if (primitive().indices >= 0) {
      Result<Target> t = target(primitive().indices, "indices");
      if (!t) return t.error();
      if (t->components != 1 || (t->component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                 t->component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                 t->component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        return accessorFail(primitive().indices, "indices",
                            "must be SCALAR unsigned byte, short or int, not " + std::to_string(t->components) +
                                " components of componentType " + std::to_string(t->component_type));
      needed += uint64_t(t->count) * t->element_size;
    }
    if (needed > budget_)
      return Error{path_ + ": " + pointer_ + ": decoded data exceeds the limit of " + std::to_string(limit_) + " bytes",
                   ExitCode::kResourceLimit};

    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(source.data() + view.byteOffset), view.byteLength);
    draco::StatusOr<draco::EncodedGeometryType> type = draco::Decoder::GetEncodedGeometryType(&buffer);
    if (!type.ok()) return fail("", "libdraco cannot read the header: " + oneLine(type.status().error_msg_string()));
    if (type.value() != draco::TRIANGULAR_MESH)
      return fail("", "the Draco data is not a triangle mesh (geometry type " + std::to_string(int(type.value())) + ")");
    buffer.Init(reinterpret_cast<const char*>(source.data() + view.byteOffset), view.byteLength);
    draco::Decoder decoder;
    draco::StatusOr<std::unique_ptr<draco::Mesh>> decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok()) return fail("", "libdraco could not decode it: " + oneLine(decoded.status().error_msg_string()));
    const draco::Mesh& mesh = *decoded.value();

    // Every listed id must exist, also for attributes we do not read: a wrong id is a broken file.
    for (const auto& [name, id] : listed)
      if (!mesh.GetAttributeByUniqueId(id))
        return fail("/attributes/" + printableExcerpt(name), "Draco attribute id " + std::to_string(id) + " is not in the decoded data (" +
                                               std::to_string(mesh.num_attributes()) + " attributes)");
    std::vector<std::pair<std::string, int>> replaced;
    for (const Target& t : targets) {
      Result<int> accessor = copyAttribute(t, mesh);
      if (!accessor) return accessor.error();
      replaced.emplace_back(t.role, *accessor);
    }
    Result<int> indices = copyIndices(mesh);
    if (!indices) return indices.error();

    tinygltf::Primitive& p = primitive();
    for (const auto& [name, accessor] : replaced) p.attributes[name] = accessor;
    p.indices = *indices;
    // Draco stores faces: a TRIANGLE_STRIP primitive decodes to the same triangles as a list.
    p.mode = TINYGLTF_MODE_TRIANGLES;
    return okStatus();
  }

 private:
  // One accessor to fill, with its declared shape.
  struct Target {
    std::string role;  // POSITION, COLOR_0 or indices
    int accessor = -1;
    uint32_t draco_id = 0;
    size_t count = 0;
    int components = 0;
    int component_type = 0;
    size_t element_size = 0;
  };

  tinygltf::Primitive& primitive() { return model_.meshes[mesh_].primitives[primitive_]; }

  Error fail(const std::string& field, const std::string& what) const {
    return Error{path_ + ": " + pointer_ + field + ": " + what};
  }
  Error accessorFail(int accessor, const std::string& role, const std::string& what) const {
    return Error{path_ + ": " + pointer_ + ": " + role + " accessor " + std::to_string(accessor) + ": " + what};
  }

  Result<size_t> integer(const tinygltf::Value& object, const char* key, const std::string& prefix = "/") const {
    // key may be an attribute name from the file: quoted printably.
    if (!object.Has(key)) return fail(prefix + printableExcerpt(key), "missing");
    const tinygltf::Value& v = object.Get(key);
    const double d = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
    if (!(d >= 0) || d > 2147483647.0 || d != std::floor(d))
      return fail(prefix + printableExcerpt(key), "must be an integer from 0 to 2147483647");
    return size_t(d);
  }

  Result<Target> target(int accessor, const std::string& role) const {
    if (accessor < 0 || size_t(accessor) >= model_.accessors.size())
      return fail("", role + " accessor " + std::to_string(accessor) + " does not exist");
    const tinygltf::Accessor& a = model_.accessors[size_t(accessor)];
    Target t;
    t.role = role;
    t.accessor = accessor;
    t.count = a.count;
    t.component_type = a.componentType;
    // Matrices never hold geometry; refusing them keeps the decoded layout tight (no column padding).
    t.components = a.type == TINYGLTF_TYPE_SCALAR ? 1
                   : a.type == TINYGLTF_TYPE_VEC2 ? 2
                   : a.type == TINYGLTF_TYPE_VEC3 ? 3
                   : a.type == TINYGLTF_TYPE_VEC4 ? 4
                                                  : 0;
    if (t.components == 0) return accessorFail(accessor, role, "type must be SCALAR or VEC2..VEC4");
    const size_t size = gltfComponentSize(a.componentType);
    if (size == 0) return accessorFail(accessor, role, "componentType " + std::to_string(a.componentType) + " is not valid");
    if (t.count > size_t(std::numeric_limits<int32_t>::max()))
      return accessorFail(accessor, role, "count " + std::to_string(t.count) + " is too large");
    t.element_size = size * size_t(t.components);
    return t;
  }

  // Appends a buffer, a view over all of it and accessor `like` reading it tightly.
  int addAccessor(tinygltf::Accessor accessor, std::vector<unsigned char> bytes) {
    tinygltf::Buffer buffer;
    buffer.name = "decoded " + pointer_;
    const size_t length = bytes.size();
    buffer.data = std::move(bytes);
    budget_ -= length;  // within budget: checked against the declared sizes before decoding
    model_.buffers.push_back(std::move(buffer));
    tinygltf::BufferView view;
    view.buffer = int(model_.buffers.size() - 1);
    view.byteOffset = 0;
    view.byteLength = length;
    view.byteStride = 0;
    model_.bufferViews.push_back(view);
    accessor.bufferView = int(model_.bufferViews.size() - 1);
    accessor.byteOffset = 0;
    accessor.sparse = tinygltf::Accessor().sparse;  // not sparse (the type is unnamed in 2.7.0)
    model_.accessors.push_back(accessor);
    return int(model_.accessors.size() - 1);
  }

  Result<int> copyAttribute(const Target& t, const draco::Mesh& mesh) {
    const draco::PointAttribute& att = *mesh.GetAttributeByUniqueId(t.draco_id);  // checked by the caller
    const size_t points = mesh.num_points();
    if (t.count != points)
      return accessorFail(t.accessor, t.role, "count " + std::to_string(t.count) + " differs from the " +
                                                  std::to_string(points) + " points the Draco data decodes to");
    if (int(att.num_components()) != t.components)
      return accessorFail(t.accessor, t.role, std::to_string(t.components) + " components, but Draco attribute " +
                                                  std::to_string(t.draco_id) + " has " +
                                                  std::to_string(int(att.num_components())));
    if (att.data_type() != dracoTypeOf(t.component_type))
      return accessorFail(t.accessor, t.role, "componentType " + std::to_string(t.component_type) +
                                                  ", but Draco attribute " + std::to_string(t.draco_id) + " holds " +
                                                  dracoTypeName(att.data_type()));
    // libdraco's own arrays, checked before reading through them: values are element_size bytes
    // at byte_offset + stride·v for v < size(), all inside the data buffer.
    const draco::DataBuffer* data = att.buffer();
    const size_t values = att.size();
    if (!data || att.byte_offset() < 0 || att.byte_stride() < int64_t(t.element_size))
      return fail("/attributes/" + t.role, "libdraco returned an attribute without a usable buffer");
    const size_t offset = size_t(att.byte_offset()), stride = size_t(att.byte_stride());
    if (values > 0 && (offset > data->data_size() || t.element_size > data->data_size() - offset ||
                       values - 1 > (data->data_size() - offset - t.element_size) / stride))
      return fail("/attributes/" + t.role, "libdraco returned an attribute larger than its buffer");
    if (!att.is_mapping_identity() ? att.indices_map_size() < points : values < points)
      return fail("/attributes/" + t.role, "libdraco maps fewer values than the mesh has points");

    std::vector<unsigned char> bytes(points * t.element_size);
    for (size_t i = 0; i < points; ++i) {
      const draco::AttributeValueIndex v = att.mapped_index(draco::PointIndex(uint32_t(i)));
      if (v.value() >= values)
        return fail("/attributes/" + t.role, "point " + std::to_string(i) + " maps to value " +
                                                 std::to_string(v.value()) + " of " + std::to_string(values));
      std::memcpy(bytes.data() + i * t.element_size, data->data() + offset + stride * v.value(), t.element_size);
    }
    return addAccessor(model_.accessors[size_t(t.accessor)], std::move(bytes));
  }

  // The faces as the primitive's indices accessor (or a new uint32 one when it has none).
  Result<int> copyIndices(const draco::Mesh& mesh) {
    const size_t faces = mesh.num_faces(), points = mesh.num_points();
    const int accessor = primitive().indices;
    int component_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    if (accessor >= 0) {
      const tinygltf::Accessor& a = model_.accessors[size_t(accessor)];  // checked by target()
      component_type = a.componentType;
      if (a.count != 3 * faces)
        return accessorFail(accessor, "indices", "count " + std::to_string(a.count) + " differs from 3 x the " +
                                                     std::to_string(faces) + " faces the Draco data decodes to");
    } else if (3 * faces * 4 > budget_) {
      return Error{path_ + ": " + pointer_ + ": decoded data exceeds the limit of " + std::to_string(limit_) + " bytes",
                   ExitCode::kResourceLimit};
    }
    const size_t size = gltfComponentSize(component_type);
    const uint64_t largest = size == 1 ? 0xFFu : size == 2 ? 0xFFFFu : 0xFFFFFFFFu;
    std::vector<unsigned char> bytes(3 * faces * size);
    for (size_t f = 0; f < faces; ++f) {
      const draco::Mesh::Face& face = mesh.face(draco::FaceIndex(uint32_t(f)));
      for (size_t k = 0; k < 3; ++k) {
        const uint32_t v = face[k].value();
        if (v >= points)
          return fail("", "face " + std::to_string(f) + " names point " + std::to_string(v) + " of " +
                              std::to_string(points));
        if (v > largest)
          return accessorFail(accessor, "indices", "componentType " + std::to_string(component_type) +
                                                       " cannot hold point index " + std::to_string(v));
        unsigned char* out = bytes.data() + (3 * f + k) * size;
        if (size == 1) {
          out[0] = static_cast<unsigned char>(v);
        } else if (size == 2) {
          const uint16_t narrow = static_cast<uint16_t>(v);
          std::memcpy(out, &narrow, 2);
        } else {
          std::memcpy(out, &v, 4);
        }
      }
    }
    if (accessor >= 0) return addAccessor(model_.accessors[size_t(accessor)], std::move(bytes));
    tinygltf::Accessor like;
    like.type = TINYGLTF_TYPE_SCALAR;
    like.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    like.count = 3 * faces;
    return addAccessor(like, std::move(bytes));
  }

  const std::string& path_;
  tinygltf::Model& model_;
  uint64_t limit_, budget_;  // budget_: what is left of limit_
  size_t mesh_ = 0, primitive_ = 0;
  std::string primitive_pointer_, pointer_;
};

}  // namespace

std::vector<DracoIndices> detachDracoIndices(JsonValue& root) {
  std::vector<DracoIndices> detached;
  JsonValue* meshes = root.find("meshes");
  if (!meshes || meshes->kind != JsonValue::Kind::kArray) return detached;
  for (size_t m = 0; m < meshes->items.size(); ++m) {
    JsonValue* primitives = meshes->items[m].find("primitives");
    if (!primitives || primitives->kind != JsonValue::Kind::kArray) continue;
    for (size_t p = 0; p < primitives->items.size(); ++p) {
      JsonValue& primitive = primitives->items[p];
      const JsonValue* extensions = primitive.find("extensions");
      const JsonValue* indices = primitive.find("indices");
      if (!extensions || !extensions->find(kExtension) || !indices) continue;
      detached.push_back({m, p, int(indices->number)});  // pre-checked: an integer below 2^31
      primitive.erase("indices");
    }
  }
  return detached;
}

Status decodeDracoPrimitives(const std::string& path, tinygltf::Model& model,
                             const std::vector<DracoIndices>& detached, uint64_t max_decoded_bytes) {
  for (const DracoIndices& d : detached) {
    // tinygltf keeps every mesh and primitive of the (pre-checked) arrays in order.
    if (d.mesh >= model.meshes.size() || d.primitive >= model.meshes[d.mesh].primitives.size())
      return Error{path + ": /meshes/" + std::to_string(d.mesh) + "/primitives/" + std::to_string(d.primitive) +
                   ": not loaded by tinygltf"};
    model.meshes[d.mesh].primitives[d.primitive].indices = d.accessor;
  }
  PrimitiveDecoder decoder(path, model, max_decoded_bytes);
  for (size_t m = 0; m < model.meshes.size(); ++m)
    for (size_t p = 0; p < model.meshes[m].primitives.size(); ++p) {
      if (!model.meshes[m].primitives[p].extensions.count(kExtension)) continue;
      if (Status s = decoder.decode(m, p); !s) return s;
    }
  return okStatus();
}

}  // namespace dpoint
