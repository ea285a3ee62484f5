// Accessor decoding (glTF 2.0 §3.6). Bounds: for a view of L bytes, element size s, stride t and
// count n we need byteOffset + t·(n−1) + s ≤ L, and the view inside its buffer; both are tested
// by subtraction so no intermediate sum can wrap.
#include "converters/gltf_accessor.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <new>

namespace dpoint {
namespace {

static_assert(std::endian::native == std::endian::little, "glTF buffers are little-endian");

// Components per element and rows per column (rows == components except for matrices).
bool shapeOf(int type, int& components, int& rows) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: components = rows = 1; return true;
    case TINYGLTF_TYPE_VEC2: components = rows = 2; return true;
    case TINYGLTF_TYPE_VEC3: components = rows = 3; return true;
    case TINYGLTF_TYPE_VEC4: components = rows = 4; return true;
    case TINYGLTF_TYPE_MAT2: components = 4, rows = 2; return true;
    case TINYGLTF_TYPE_MAT3: components = 9, rows = 3; return true;
    case TINYGLTF_TYPE_MAT4: components = 16, rows = 4; return true;
    default: return false;
  }
}

}  // namespace

size_t gltfComponentSize(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

Error AccessorDecoder::fail(int index, const std::string& what) const {
  return Error{path_ + ": /accessors/" + std::to_string(index) + ": " + what};
}

Result<AccessorDecoder::Span> AccessorDecoder::locate(const std::string& pointer, int view_index,
                                                      size_t byte_offset, size_t count,
                                                      size_t element_size, size_t extent,
                                                      bool use_view_stride) const {
  const auto fail_at = [&](const std::string& what) { return Error{path_ + ": " + pointer + ": " + what}; };
  const std::string view_name = "bufferView " + std::to_string(view_index);
  if (view_index < 0 || size_t(view_index) >= model_.bufferViews.size()) return fail_at(view_name + " does not exist");
  const tinygltf::BufferView& view = model_.bufferViews[size_t(view_index)];
  if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
    return fail_at(view_name + ": buffer " + std::to_string(view.buffer) + " does not exist");
  const std::vector<unsigned char>& data = model_.buffers[size_t(view.buffer)].data;
  if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
    return fail_at(view_name + ": byteOffset " + std::to_string(view.byteOffset) + " + byteLength " +
                   std::to_string(view.byteLength) + " exceeds buffer " + std::to_string(view.buffer) +
                   " length " + std::to_string(data.size()));
  const size_t stride = use_view_stride && view.byteStride != 0 ? view.byteStride : element_size;
  if (stride < element_size)
    return fail_at(view_name + ": byteStride " + std::to_string(stride) + " is smaller than the element size " +
                   std::to_string(element_size));
  const size_t length = view.byteLength;
  bool fits = byte_offset <= length;
  if (fits && count > 0)
    fits = extent <= length - byte_offset && count - 1 <= (length - byte_offset - extent) / stride;
  if (!fits) {
    // The sum for the message, saturated: it only overflows on values no real file has.
    std::string sum = "more than 2^64";
    const size_t n = count == 0 ? 0 : count - 1;
    if (n == 0 || stride <= (std::numeric_limits<size_t>::max() - byte_offset - extent) / n)
      sum = std::to_string(byte_offset + stride * n + extent);
    return fail_at("count " + std::to_string(count) + ": byteOffset + stride*(count-1) + " + std::to_string(extent) +
                   " = " + sum + " exceeds " + view_name + " length " + std::to_string(length));
  }
  return Span{data.data() + view.byteOffset + byte_offset, stride};
}

Result<AccessorElements> AccessorDecoder::open(int index) const {
  if (index < 0 || size_t(index) >= model_.accessors.size())
    return Error{path_ + ": accessor " + std::to_string(index) + " does not exist"};
  const tinygltf::Accessor& accessor = model_.accessors[size_t(index)];
  AccessorElements out;
  if (!shapeOf(accessor.type, out.components_, out.rows_)) return fail(index, "invalid type");
  const size_t size = gltfComponentSize(accessor.componentType);
  if (size == 0) return fail(index, "componentType " + std::to_string(accessor.componentType) + " is not valid");
  const bool normalizable = accessor.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT &&
                            accessor.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  if (accessor.normalized && !normalizable)
    return fail(index, "normalized is not allowed for componentType " + std::to_string(accessor.componentType));
  out.count_ = accessor.count;
  out.component_type_ = accessor.componentType;
  out.normalized_ = accessor.normalized;
  const size_t rows = size_t(out.rows_), columns = size_t(out.components_ / out.rows_);
  out.column_stride_ = columns > 1 ? (rows * size + 3) / 4 * 4 : rows * size;
  const size_t element_size = columns * out.column_stride_;
  // The last matrix column needs no padding after it (the validator's get_elements_matrix oracle).
  const size_t extent = (columns - 1) * out.column_stride_ + rows * size;
  for (int k = 0; k < out.components_; ++k)
    out.offsets_[size_t(k)] = size_t(k / out.rows_) * out.column_stride_ + size_t(k % out.rows_) * size;

  if (accessor.bufferView >= 0) {
    Result<Span> span = locate("/accessors/" + std::to_string(index), accessor.bufferView, accessor.byteOffset,
                               accessor.count, element_size, extent, true);
    if (!span) return span.error();
    out.first_ = span->first;
    out.stride_ = span->stride;
  } else if (accessor.byteOffset != 0) {
    return fail(index, "byteOffset " + std::to_string(accessor.byteOffset) + " without a bufferView");
  }
  if (accessor.bufferView < 0 || accessor.sparse.isSparse) {
    // Materialise: all zeros (no bufferView, spec §3.6.2.3) or a copy to patch the sparse values into.
    if (accessor.count > max_unbacked_values_ / size_t(out.components_))
      return Error{path_ + ": /accessors/" + std::to_string(index) + ": count " + std::to_string(accessor.count) +
                       " without backing data exceeds the limit of " + std::to_string(max_unbacked_values_) + " values",
                   ExitCode::kResourceLimit};
    out.decoded_.assign(accessor.count * size_t(out.components_), 0.0);
    if (out.first_)
      for (size_t e = 0; e < out.count_; ++e)
        for (int k = 0; k < out.components_; ++k)
          out.decoded_[e * size_t(out.components_) + size_t(k)] = decodeGltfComponent(
              out.first_ + e * out.stride_ + out.offsets_[size_t(k)], out.component_type_, out.normalized_);
    if (accessor.sparse.isSparse) {
      if (Status s = applySparse(index, accessor, out); !s) return s.error();
    }
    // An accessor of count 0 decodes to nothing; value() is never called on it.
  }
  return out;
}

Status AccessorDecoder::applySparse(int index, const tinygltf::Accessor& accessor, AccessorElements& out) const {
  const auto& sparse = accessor.sparse;
  const std::string pointer = "/accessors/" + std::to_string(index) + "/sparse";
  if (sparse.count < 1) return Error{path_ + ": " + pointer + "/count: " + std::to_string(sparse.count) + " is not ≥ 1"};
  const size_t n = size_t(sparse.count);
  if (n > out.count_)
    return Error{path_ + ": " + pointer + "/count: " + std::to_string(n) + " exceeds the accessor count " +
                 std::to_string(out.count_)};
  const int index_type = sparse.indices.componentType;
  if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    return Error{path_ + ": " + pointer + "/indices/componentType: " + std::to_string(index_type) +
                 " is not an unsigned byte, short or int"};
  const size_t index_size = gltfComponentSize(index_type);
  Result<Span> indices = locate(pointer + "/indices", sparse.indices.bufferView, size_t(sparse.indices.byteOffset), n,
                                index_size, index_size, false);
  if (!indices) return indices.error();
  const size_t value_size = gltfComponentSize(out.component_type_);
  const size_t columns = size_t(out.components_ / out.rows_);
  const size_t value_extent = (columns - 1) * out.column_stride_ + size_t(out.rows_) * value_size;
  Result<Span> values = locate(pointer + "/values", sparse.values.bufferView, size_t(sparse.values.byteOffset), n,
                               columns * out.column_stride_, value_extent, false);
  if (!values) return values.error();
  size_t previous = 0;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char* p = indices->first + i * index_size;
    const size_t target = index_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? p[0]
                          : index_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? loadGltfValue<uint16_t>(p)
                                                                                 : loadGltfValue<uint32_t>(p);
    if (target >= out.count_)
      return Error{path_ + ": " + pointer + "/indices: element " + std::to_string(i) + " is " +
                   std::to_string(target) + ", not below the accessor count " + std::to_string(out.count_)};
    if (i > 0 && target <= previous)
      return Error{path_ + ": " + pointer + "/indices: element " + std::to_string(i) + " (" +
                   std::to_string(target) + ") does not increase strictly"};
    previous = target;
    const unsigned char* v = values->first + i * values->stride;
    for (int k = 0; k < out.components_; ++k)
      out.decoded_[target * size_t(out.components_) + size_t(k)] =
          decodeGltfComponent(v + out.offsets_[size_t(k)], out.component_type_, out.normalized_);
  }
  return okStatus();
}

}  // namespace dpoint
