// The one glTF accessor decoder (internal to converters/). Every element it hands out was
// bounds-checked first, with arithmetic that cannot overflow: offsets and counts come straight
// from a possibly hostile file and tinygltf 2.7.0 checks none of them.
#pragma once

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/result.h"

namespace dpoint {

template <typename T>
T loadGltfValue(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));  // buffer data has no alignment guarantee
  return value;
}

// The component at p as the spec defines it (AccessorElements::value); component_type is one that
// AccessorDecoder::open admitted.
inline double decodeGltfComponent(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double c = static_cast<int8_t>(p[0]);
      return normalized ? std::max(c / 127.0, -1.0) : c;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const double c = loadGltfValue<int16_t>(p);
      return normalized ? std::max(c / 32767.0, -1.0) : c;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const double c = loadGltfValue<uint16_t>(p);
      return normalized ? c / 65535.0 : c;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return loadGltfValue<uint32_t>(p);
    default: return loadGltfValue<float>(p);  // open() admitted only the types above and FLOAT
  }
}

// The elements of one accessor. value(e, k) is component k of element e as the spec defines it:
// integers as they are, or mapped to [0,1] / [-1,1] when `normalized` (glTF 2.0 §3.11,
// signed: max(c / (2^(b−1) − 1), −1)), sparse substitutions applied.
class AccessorElements {
 public:
  size_t count() const { return count_; }
  int components() const { return components_; }
  int componentType() const { return component_type_; }
  bool normalized() const { return normalized_; }
  // Requires e < count(), k < components(). Inline, with each component's offset in an element
  // worked out by open(): it is called once per value of every vertex, colour and index.
  double value(size_t e, int k) const {
    if (!decoded_.empty()) return decoded_[e * size_t(components_) + size_t(k)];
    return decodeGltfComponent(first_ + e * stride_ + offsets_[size_t(k)], component_type_, normalized_);
  }

 private:
  friend class AccessorDecoder;
  size_t count_ = 0;
  int components_ = 0;
  int component_type_ = 0;
  bool normalized_ = false;
  // Dense elements in a buffer view: element e starts at first_ + e·stride_; matrix columns of
  // 1- and 2-byte components are padded to 4 bytes (spec §3.6.2.4), so column c of an element
  // starts at c·column_stride_.
  const unsigned char* first_ = nullptr;
  size_t stride_ = 0, column_stride_ = 0;
  int rows_ = 1;
  std::array<size_t, 16> offsets_{};  // component k at (k / rows_)·column_stride_ + (k % rows_)·size
  // Used instead when the accessor is sparse or has no bufferView: count·components values.
  std::vector<double> decoded_;
};

class AccessorDecoder {
 public:
  // `path` prefixes error messages. Accessors without a bufferView own their values; more than
  // max_unbacked_values of those is an ExitCode::kResourceLimit error (the count is unbacked data).
  AccessorDecoder(const std::string& path, const tinygltf::Model& model, size_t max_unbacked_values)
      : path_(path), model_(model), max_unbacked_values_(max_unbacked_values) {}

  // Checks accessor `index` (exists, valid type/componentType, every byte inside its view and
  // buffer, sparse indices strictly increasing and < count). Errors: "PATH: /accessors/I: what".
  Result<AccessorElements> open(int index) const;

  // "PATH: /accessors/I: what", for callers checking an accessor's role (e.g. POSITION's type).
  Error fail(int index, const std::string& what) const;

 private:
  struct Span {
    const unsigned char* first = nullptr;
    size_t stride = 0;
  };
  // Checks byte_offset + stride·(count−1) + extent ≤ view length; stride is the view's byteStride
  // (when use_view_stride and set) else element_size, and must be ≥ element_size.
  Result<Span> locate(const std::string& pointer, int view_index, size_t byte_offset, size_t count,
                      size_t element_size, size_t extent, bool use_view_stride) const;
  Status applySparse(int index, const tinygltf::Accessor& accessor, AccessorElements& out) const;

  const std::string& path_;
  const tinygltf::Model& model_;
  size_t max_unbacked_values_;
};

// Byte size of one component, 0 for an invalid componentType.
size_t gltfComponentSize(int component_type);

}  // namespace dpoint
