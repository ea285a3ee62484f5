// Dimensions (core/dimensions.h) as glTF vertex attributes: application-specific attributes, named
// `_` + the dimension's name in upper case (`_INTENSITY`, `_GPS_TIME`), one SCALAR per point.
//
// Spec §3.7.2.1 keeps every vertex attribute element 4-byte aligned, and glTF has no 32-bit signed
// or 64-bit integers and no doubles. So:
// - uint8, int8, uint16, int16: their own component type, one element per 4 bytes (byteStride 4);
// - float32: FLOAT;
// - uint32, int32, uint64, int64, float64: their little-endian bytes as VEC2 or VEC4 of
//   UNSIGNED_SHORT, the type named in the accessor's extras ({"dpoint": {"type": "float64"}}):
//   dpoint reads them back bit for bit; another reader sees the words.
// A name that the attribute does not give back (lower case of what follows `_`) is in the same
// extras ("name"); so is one whose attribute another dimension took first (a LAS extra byte
// "Intensity" beside the field: `_INTENSITY_2`). A reader takes any SCALAR of a non-normalized integer or float type.
#pragma once

#include <tiny_gltf.h>

#include <cctype>
#include <string>

#include "core/dimensions.h"

namespace dpoint {

struct GltfDimensionForm {
  int component_type = TINYGLTF_COMPONENT_TYPE_FLOAT;
  int type = TINYGLTF_TYPE_SCALAR;
  bool raw = false;       // the value's bytes as unsigned shorts
  size_t stride = 4;      // bytes per point in the buffer view
};

inline GltfDimensionForm gltfDimensionForm(DimType type) {
  switch (type) {
    case DimType::kU8: return {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_SCALAR, false, 4};
    case DimType::kI8: return {TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_TYPE_SCALAR, false, 4};
    case DimType::kU16: return {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR, false, 4};
    case DimType::kI16: return {TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_TYPE_SCALAR, false, 4};
    case DimType::kF32: return {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, false, 4};
    case DimType::kU32:
    case DimType::kI32: return {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC2, true, 4};
    case DimType::kU64:
    case DimType::kI64:
    case DimType::kF64: return {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC4, true, 8};
  }
  return {};
}

// `_INTENSITY` for intensity; characters other than letters, digits and `_` become `_`.
inline std::string gltfAttributeName(const std::string& name) {
  std::string attribute = "_";
  for (char c : name)
    attribute += std::isalnum(static_cast<unsigned char>(c)) ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : '_';
  return attribute;
}

// The dimension an attribute names when its extras do not: `_GPS_TIME` → gps_time.
inline std::string gltfDimensionName(const std::string& attribute) {
  std::string name;
  for (size_t i = 1; i < attribute.size(); ++i)
    name += static_cast<char>(std::tolower(static_cast<unsigned char>(attribute[i])));
  return name;
}

}  // namespace dpoint
