// EXT_meshopt_compression decoding through Debian's libmeshoptimizer. The extension's rules
// (KhronosGroup/glTF extensions/2.0/Vendor/EXT_meshopt_compression) are checked here because the
// library only asserts them: ATTRIBUTES strides are multiples of 4 up to 256, TRIANGLES and
// INDICES strides are 2 or 4, TRIANGLES counts are multiples of 3, filters apply to ATTRIBUTES
// only (OCTAHEDRAL stride 4 or 8, QUATERNION 8, EXPONENTIAL a multiple of 4). The decoders
// themselves are documented safe for untrusted input once those hold.
#include "converters/gltf_meshopt.h"

#include <meshoptimizer.h>

#include <cmath>
#include <vector>

#include "core/text.h"

namespace dpoint {
namespace {

constexpr const char* kExtension = "EXT_meshopt_compression";

class ViewDecoder {
 public:
  ViewDecoder(const std::string& path, tinygltf::Model& model, uint64_t max_decoded_bytes)
      : path_(path), model_(model), limit_(max_decoded_bytes), budget_(max_decoded_bytes) {}

  Status decode(size_t view_index, const tinygltf::Value& ext) {
    pointer_ = "/bufferViews/" + std::to_string(view_index) + "/extensions/" + kExtension;
    if (!ext.IsObject()) return fail("", "must be an object");
    // The load pre-checks (gltf_load.cpp) made these integers in [0, 2^31) when present.
    Result<size_t> buffer = integer(ext, "buffer", true, 0);
    Result<size_t> byte_offset = integer(ext, "byteOffset", false, 0);
    Result<size_t> byte_length = integer(ext, "byteLength", true, 0);
    Result<size_t> stride = integer(ext, "byteStride", true, 0);
    Result<size_t> count = integer(ext, "count", true, 0);
    for (const Result<size_t>* r : {&buffer, &byte_offset, &byte_length, &stride, &count})
      if (!*r) return r->error();
    const std::string mode = text(ext, "mode", "");
    const std::string filter = text(ext, "filter", "NONE");

    if (mode == "ATTRIBUTES") {
      if (*stride == 0 || *stride % 4 != 0 || *stride > 256)
        return fail("/byteStride", std::to_string(*stride) + " is not a multiple of 4 from 4 to 256 (mode ATTRIBUTES)");
    } else if (mode == "TRIANGLES" || mode == "INDICES") {
      if (*stride != 2 && *stride != 4) return fail("/byteStride", std::to_string(*stride) + " is not 2 or 4 (mode " + mode + ")");
      if (mode == "TRIANGLES" && *count % 3 != 0)
        return fail("/count", std::to_string(*count) + " is not a multiple of 3 (mode TRIANGLES)");
      if (filter != "NONE") return fail("/filter", quotedExcerpt(filter) + " is only allowed with mode ATTRIBUTES");
    } else {
      return fail("/mode", quotedExcerpt(mode) + " is not ATTRIBUTES, TRIANGLES or INDICES");
    }
    if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
      return fail("/filter", quotedExcerpt(filter) + " is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
    // EXPONENTIAL needs a multiple of 4, which ATTRIBUTES already guarantees.
    if ((filter == "OCTAHEDRAL" && *stride != 4 && *stride != 8) || (filter == "QUATERNION" && *stride != 8))
      return fail("/byteStride", std::to_string(*stride) + " is not allowed with filter " + filter);

    if (*buffer >= model_.buffers.size()) return fail("/buffer", "buffer " + std::to_string(*buffer) + " does not exist");
    const std::vector<unsigned char>& source = model_.buffers[*buffer].data;
    if (*byte_offset > source.size() || *byte_length > source.size() - *byte_offset)
      return fail("", "byteOffset " + std::to_string(*byte_offset) + " + byteLength " + std::to_string(*byte_length) +
                          " exceeds buffer " + std::to_string(*buffer) + " length " + std::to_string(source.size()));
    // Both factors are below 2^31 (pre-checks), so the product fits in 64 bits.
    const uint64_t decoded_size = uint64_t(*count) * uint64_t(*stride);
    tinygltf::BufferView& view = model_.bufferViews[view_index];
    if (decoded_size != view.byteLength)
      return fail("", "count " + std::to_string(*count) + " * byteStride " + std::to_string(*stride) + " = " +
                          std::to_string(decoded_size) + " differs from the view's byteLength " +
                          std::to_string(view.byteLength));
    if (decoded_size > budget_)
      return Error{path_ + ": " + pointer_ + ": decoded data exceeds the limit of " + std::to_string(limit_) + " bytes",
                   ExitCode::kResourceLimit};
    budget_ -= decoded_size;

    std::vector<unsigned char> decoded(static_cast<size_t>(decoded_size));
    const unsigned char* compressed = source.data() + *byte_offset;
    int rc = 0;
    if (mode == "ATTRIBUTES") {
      rc = meshopt_decodeVertexBuffer(decoded.data(), *count, *stride, compressed, *byte_length);
    } else if (mode == "TRIANGLES") {
      rc = meshopt_decodeIndexBuffer(decoded.data(), *count, *stride, compressed, *byte_length);
    } else {
      rc = meshopt_decodeIndexSequence(decoded.data(), *count, *stride, compressed, *byte_length);
    }
    if (rc != 0) return fail("", "meshoptimizer could not decode the " + mode + " data (error " + std::to_string(rc) + ")");
    if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(decoded.data(), *count, *stride);
    if (filter == "QUATERNION") meshopt_decodeFilterQuat(decoded.data(), *count, *stride);
    if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(decoded.data(), *count, *stride);

    // The view now names the decoded bytes; its byteStride (if any) still describes them.
    tinygltf::Buffer out;
    out.name = "decoded " + pointer_;
    out.data = std::move(decoded);
    model_.buffers.push_back(std::move(out));
    view.buffer = int(model_.buffers.size() - 1);
    view.byteOffset = 0;
    return okStatus();
  }

 private:
  Error fail(const std::string& field, const std::string& what) const {
    return Error{path_ + ": " + pointer_ + field + ": " + what};
  }
  Result<size_t> integer(const tinygltf::Value& ext, const char* key, bool required, size_t fallback) const {
    if (!ext.Has(key)) {
      if (required) return fail(std::string("/") + key, "missing");
      return fallback;
    }
    const tinygltf::Value& v = ext.Get(key);
    const double d = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
    if (!(d >= 0) || d > 2147483647.0 || d != std::floor(d))
      return fail(std::string("/") + key, "must be an integer from 0 to 2147483647");
    return size_t(d);
  }
  static std::string text(const tinygltf::Value& ext, const char* key, const std::string& fallback) {
    if (!ext.Has(key)) return fallback;
    const tinygltf::Value& v = ext.Get(key);
    return v.IsString() ? v.Get<std::string>() : "(not a string)";
  }

  const std::string& path_;
  tinygltf::Model& model_;
  uint64_t limit_, budget_;  // budget_: what is left of limit_
  std::string pointer_;
};

}  // namespace

bool emptyMeshoptFallbackBuffers(JsonValue& root, bool binary) {
  JsonValue* buffers = root.find("buffers");
  if (!buffers || buffers->kind != JsonValue::Kind::kArray) return false;
  bool changed = false;
  for (JsonValue& buffer : buffers->items) {
    const JsonValue* extensions = buffer.find("extensions");
    const JsonValue* ext = extensions ? extensions->find(kExtension) : nullptr;
    const JsonValue* fallback = ext ? ext->find("fallback") : nullptr;
    if (buffer.find("uri") || !fallback || fallback->kind != JsonValue::Kind::kBool || !fallback->boolean) continue;
    changed = true;
    // One byte, not zero: tinygltf 2.7.0 indexes data.at(0) when copying a GLB buffer.
    buffer.set("byteLength", JsonValue::integerValue(1));
    if (!binary) buffer.set("uri", JsonValue::stringValue("data:application/octet-stream;base64,AA=="));
  }
  return changed;
}

Status decodeMeshoptViews(const std::string& path, tinygltf::Model& model, uint64_t max_decoded_bytes) {
  ViewDecoder decoder(path, model, max_decoded_bytes);
  // Decoded buffers are appended; the views themselves are fixed in number.
  for (size_t i = 0; i < model.bufferViews.size(); ++i) {
    const auto it = model.bufferViews[i].extensions.find(kExtension);
    if (it == model.bufferViews[i].extensions.end()) continue;
    if (Status s = decoder.decode(i, it->second); !s) return s;
  }
  return okStatus();
}

}  // namespace dpoint
