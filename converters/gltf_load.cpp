// Pre-checks and tinygltf loading. Every check here exists because tinygltf 2.7.0 crashes, reads
// out of bounds or silently changes a value on that input (corpus README, "Known traps").
#include "converters/gltf_load.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>
#include <new>
#include <optional>
#include <string_view>
#include <vector>

#include "converters/gltf_draco.h"
#include "converters/gltf_json.h"
#include "converters/gltf_meshopt.h"
#include "core/input_file.h"
#include "core/memory.h"
#include "core/text.h"

namespace dpoint {
namespace {

constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;     // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;      // "BIN\0"
// tinygltf keeps indices in int; sizes in size_t but we want them exact in a double too.
constexpr int64_t kMaxIndex = std::numeric_limits<int32_t>::max();
constexpr int64_t kMaxSize = int64_t(1) << 53;

uint32_t readU32(const std::vector<unsigned char>& bytes, size_t at) {
  uint32_t v;
  std::memcpy(&v, bytes.data() + at, 4);  // GLB is little-endian, as is every target we build for
  return v;
}

struct GlbLayout {
  size_t json_offset = 0, json_length = 0;
  std::optional<uint64_t> bin_length;  // the BIN chunk right after JSON, if any
};

// Walks every chunk header with 64-bit arithmetic; tinygltf reads 8 bytes past the end when the
// BIN chunk's length does not leave room for its own header.
Result<GlbLayout> checkGlb(const std::string& path, const std::vector<unsigned char>& bytes) {
  const auto fail = [&](const std::string& what) { return Error{path + ": GLB: " + what}; };
  if (bytes.size() < 20) return fail("file of " + std::to_string(bytes.size()) + " bytes is shorter than a GLB header and chunk");
  if (readU32(bytes, 0) != kGlbMagic) return fail("no 'glTF' magic at byte 0");
  const uint32_t version = readU32(bytes, 4);
  if (version == 1) return fail("version 1 (glTF 1.0) is not supported; only glTF 2.x");
  if (version != 2) return fail("header version " + std::to_string(version) + " is not 2");
  const uint64_t length = readU32(bytes, 8);
  // Bytes after `length` are not part of the GLB (the validator only warns); fewer is truncation.
  if (length > bytes.size())
    return fail("header length " + std::to_string(length) + " exceeds the file size " +
                std::to_string(bytes.size()));
  GlbLayout layout;
  uint64_t at = 12;
  for (int chunk = 0; at < length; ++chunk) {
    const std::string name = "chunk " + std::to_string(chunk) + " at byte " + std::to_string(at);
    if (length - at < 8) return fail(name + ": " + std::to_string(length - at) + " bytes left, less than a chunk header");
    const uint64_t chunk_length = readU32(bytes, size_t(at));
    const uint32_t type = readU32(bytes, size_t(at + 4));
    if (chunk_length > length - at - 8)
      return fail(name + ": length " + std::to_string(chunk_length) + " runs past the end of the file");
    if (chunk == 0) {
      if (type != kChunkJson) return fail("first chunk is not JSON");
      if (chunk_length == 0) return fail("JSON chunk is empty");
      layout.json_offset = size_t(at + 8);
      layout.json_length = size_t(chunk_length);
    } else if (type == kChunkJson) {
      return fail(name + ": a second JSON chunk");
    } else if (chunk == 1 && type == kChunkBin) {
      layout.bin_length = chunk_length;
    }
    at += 8 + chunk_length;
  }
  if (layout.json_length == 0) return fail("no JSON chunk");
  return layout;
}

std::string pointerTo(const std::string& base, size_t index) { return base + "/" + std::to_string(index); }

// Checks the integer-valued fields tinygltf would wrap (2^32 → 0) or clamp (−4 → 0).
class FieldChecker {
 public:
  explicit FieldChecker(const std::string& path) : path_(path) {}
  std::optional<Error> error;

  void integer(const JsonValue* v, const std::string& pointer, int64_t max) {
    if (!v || error) return;
    // 1.0 is an integer to the validator (JSON has one number type); 1.5, −4 and 2^32 are not.
    if (v->kind != JsonValue::Kind::kNumber || !(v->number >= 0) || v->number > double(max) ||
        v->number != double(int64_t(v->number)))
      error = Error{path_ + ": " + pointer + ": must be an integer from 0 to " + std::to_string(max)};
  }
  void index(const JsonValue& object, const char* key, const std::string& base) {
    integer(object.find(key), base + "/" + key, kMaxIndex);
  }
  void size(const JsonValue& object, const char* key, const std::string& base) {
    integer(object.find(key), base + "/" + key, kMaxSize);
  }
  // Each element of an array member (e.g. children) must be an index.
  void indexArray(const JsonValue& object, const char* key, const std::string& base) {
    const JsonValue* a = object.find(key);
    if (!a || error) return;
    if (a->kind != JsonValue::Kind::kArray) {
      error = Error{path_ + ": " + base + "/" + key + ": must be an array"};
      return;
    }
    for (size_t i = 0; i < a->items.size(); ++i) integer(&a->items[i], pointerTo(base + "/" + key, i), kMaxIndex);
  }
  // Top-level arrays of objects; glTF 1.0 used objects keyed by id here.
  const std::vector<JsonValue>* objects(const JsonValue& root, const char* key) {
    static const std::vector<JsonValue> kNone;
    const JsonValue* a = root.find(key);
    if (!a || error) return &kNone;
    if (a->kind != JsonValue::Kind::kArray) {
      error = Error{path_ + ": /" + key + ": must be an array (glTF 2.0)"};
      return &kNone;
    }
    for (size_t i = 0; i < a->items.size(); ++i)
      if (a->items[i].kind != JsonValue::Kind::kObject && !error)
        error = Error{path_ + ": " + pointerTo(std::string("/") + key, i) + ": must be an object"};
    return error ? &kNone : &a->items;
  }

 private:
  const std::string& path_;
};

std::optional<Error> checkUri(const std::string& path, const std::string& pointer, const std::string& uri) {
  if (uri.rfind("data:", 0) == 0) return std::nullopt;
  const auto fail = [&](const std::string& why) {
    return Error{path + ": " + pointer + ": '" + printableExcerpt(uri) + "' " + why};
  };
  if (uri.empty() || uri == "." || uri == "..") return fail("is not a file name");
  if (uri.find(':') != std::string::npos) return fail("is not a relative file name (only data: URIs and files beside the model)");
  if (uri.front() == '/' || uri.find('\\') != std::string::npos) return fail("is not a relative path inside the model's folder");
  for (const auto& part : std::filesystem::path(uri))
    if (part == "..") return fail("leaves the model's folder");
  return std::nullopt;
}

std::optional<Error> checkDocument(const std::string& path, const JsonValue& root,
                                   const std::optional<uint64_t>& glb_bin) {
  if (root.kind != JsonValue::Kind::kObject) return Error{path + ": the JSON document is not an object"};
  const JsonValue* asset = root.find("asset");
  const JsonValue* version = asset ? asset->find("version") : nullptr;
  if (!version || version->kind != JsonValue::Kind::kString)
    return Error{path + ": /asset/version: missing; not a glTF 2.0 file (glTF 1.0 is not supported)"};
  if (version->text.rfind("2.", 0) != 0)
    return Error{path + ": /asset/version: '" + printableExcerpt(version->text) + "' is not supported; only glTF 2.x"};
  if (const JsonValue* min = asset->find("minVersion"); min && min->kind == JsonValue::Kind::kString &&
                                                          min->text != "2.0")
    return Error{path + ": /asset/minVersion: '" + printableExcerpt(min->text) + "' is newer than glTF 2.0"};

  if (const JsonValue* required = root.find("extensionsRequired")) {
    if (required->kind != JsonValue::Kind::kArray) return Error{path + ": /extensionsRequired: must be an array"};
    for (size_t i = 0; i < required->items.size(); ++i) {
      const JsonValue& name = required->items[i];
      if (name.kind != JsonValue::Kind::kString) return Error{path + ": " + pointerTo("/extensionsRequired", i) + ": must be a string"};
      if (!gltfRequiredExtensionSupported(name.text))
        return Error{path + ": " + pointerTo("/extensionsRequired", i) + ": requires extension " + printableExcerpt(name.text) +
                     ", which dpoint does not decode"};
    }
  }

  FieldChecker check(path);
  check.index(root, "scene", "");
  const auto& scenes = *check.objects(root, "scenes");
  for (size_t i = 0; i < scenes.size(); ++i) check.indexArray(scenes[i], "nodes", pointerTo("/scenes", i));
  const auto& nodes = *check.objects(root, "nodes");
  for (size_t i = 0; i < nodes.size(); ++i) {
    const std::string at = pointerTo("/nodes", i);
    for (const char* key : {"mesh", "skin", "camera"}) check.index(nodes[i], key, at);
    check.indexArray(nodes[i], "children", at);
    const JsonValue* extensions = nodes[i].find("extensions");
    const JsonValue* instancing = extensions ? extensions->find("EXT_mesh_gpu_instancing") : nullptr;
    if (const JsonValue* attributes = instancing ? instancing->find("attributes") : nullptr)
      for (const auto& [name, value] : attributes->members)
        check.integer(&value, at + "/extensions/EXT_mesh_gpu_instancing/attributes/" + printableExcerpt(name), kMaxIndex);
  }
  const auto& meshes = *check.objects(root, "meshes");
  for (size_t m = 0; m < meshes.size(); ++m) {
    const JsonValue* primitives = meshes[m].find("primitives");
    if (!primitives || primitives->kind != JsonValue::Kind::kArray) continue;  // tinygltf reports it
    for (size_t p = 0; p < primitives->items.size(); ++p) {
      const JsonValue& primitive = primitives->items[p];
      const std::string at = pointerTo(pointerTo("/meshes", m) + "/primitives", p);
      for (const char* key : {"indices", "material", "mode"}) check.index(primitive, key, at);
      if (const JsonValue* attributes = primitive.find("attributes"))
        for (const auto& [name, value] : attributes->members)
          check.integer(&value, at + "/attributes/" + printableExcerpt(name), kMaxIndex);
      // tinygltf keeps extension numbers in int, wrapping larger ones.
      const JsonValue* extensions = primitive.find("extensions");
      if (const JsonValue* draco = extensions ? extensions->find("KHR_draco_mesh_compression") : nullptr) {
        const std::string ext_at = at + "/extensions/KHR_draco_mesh_compression";
        check.index(*draco, "bufferView", ext_at);
        if (const JsonValue* ids = draco->find("attributes"))
          for (const auto& [name, value] : ids->members)
            check.integer(&value, ext_at + "/attributes/" + printableExcerpt(name), kMaxIndex);
      }
    }
  }
  const auto& accessors = *check.objects(root, "accessors");
  for (size_t i = 0; i < accessors.size(); ++i) {
    const std::string at = pointerTo("/accessors", i);
    check.index(accessors[i], "bufferView", at);
    check.index(accessors[i], "componentType", at);
    check.size(accessors[i], "byteOffset", at);
    check.size(accessors[i], "count", at);
    if (const JsonValue* sparse = accessors[i].find("sparse")) {
      check.size(*sparse, "count", at + "/sparse");
      for (const char* part : {"indices", "values"}) {
        const JsonValue* p = sparse->find(part);
        if (!p) continue;
        const std::string sub = at + "/sparse/" + part;
        check.index(*p, "bufferView", sub);
        check.index(*p, "componentType", sub);
        check.index(*p, "byteOffset", sub);  // tinygltf keeps sparse offsets in int
      }
    }
  }
  const auto& views = *check.objects(root, "bufferViews");
  for (size_t i = 0; i < views.size(); ++i) {
    const std::string at = pointerTo("/bufferViews", i);
    check.index(views[i], "buffer", at);
    check.index(views[i], "target", at);
    for (const char* key : {"byteOffset", "byteLength", "byteStride"}) check.size(views[i], key, at);
    // tinygltf keeps extension numbers in int, wrapping larger ones.
    const JsonValue* extensions = views[i].find("extensions");
    if (const JsonValue* meshopt = extensions ? extensions->find("EXT_meshopt_compression") : nullptr)
      for (const char* key : {"buffer", "byteOffset", "byteLength", "byteStride", "count"})
        check.index(*meshopt, key, at + "/extensions/EXT_meshopt_compression");
  }
  const auto& buffers = *check.objects(root, "buffers");
  for (size_t i = 0; i < buffers.size(); ++i) {
    const std::string at = pointerTo("/buffers", i);
    check.size(buffers[i], "byteLength", at);
    if (check.error) break;
    const JsonValue* uri = buffers[i].find("uri");
    if (uri && uri->kind == JsonValue::Kind::kString) {
      if (auto e = checkUri(path, at + "/uri", uri->text)) return e;
    } else if (i == 0 && glb_bin) {
      const JsonValue* length = buffers[i].find("byteLength");
      if (length && uint64_t(length->number) > *glb_bin)
        return Error{path + ": " + at + "/byteLength: " + std::to_string(uint64_t(length->number)) +
                     " exceeds the GLB BIN chunk (" + std::to_string(*glb_bin) + " bytes)"};
    }  // other buffers without uri hold no data; an accessor using one fails its bounds check
  }
  return check.error;
}

// File-system callbacks: only regular files under the model's folder, by relative names without
// "..", size-capped. tinygltf also tries the current directory and absolute paths; both refused.
struct FolderJail {
  std::string base;                  // the folder string handed to tinygltf as its base dir
  std::filesystem::path canonical;   // the folder with links resolved
  uint64_t max_bytes = 0;
  uint64_t memory_left = 0;          // --max-memory left for external files, all of them together
  bool in_memory = false;            // the model came from memory: it has no folder, nothing is read
  bool keep_images = false;          // keep the encoded bytes of images given by uri (keepImage)
};

bool allowed(const std::string& file, const FolderJail& jail) {
  if (jail.in_memory) return false;
  if (file.size() <= jail.base.size() + 1 || file.compare(0, jail.base.size(), jail.base) != 0 ||
      file[jail.base.size()] != '/')
    return false;  // not JoinPath(base, name): the cwd fallback or an absolute name
  const std::filesystem::path relative(file.substr(jail.base.size() + 1));
  if (relative.is_absolute()) return false;
  for (const auto& part : relative)
    if (part == "..") return false;
  std::error_code ec;
  const std::filesystem::path full = std::filesystem::canonical(file, ec);  // follows links
  if (ec || !std::filesystem::is_regular_file(full, ec) || ec) return false;
  const auto mismatch = std::mismatch(jail.canonical.begin(), jail.canonical.end(), full.begin(), full.end());
  return mismatch.first == jail.canonical.end();
}

bool jailedFileExists(const std::string& file, void* user) {
  return allowed(file, *static_cast<const FolderJail*>(user));
}

std::string noExpansion(const std::string& file, void*) { return file; }

bool jailedReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& file, void* user) {
  auto& jail = *static_cast<FolderJail*>(user);
  const auto refuse = [&](const std::string& why) {
    if (err) err->append("'").append(printableExcerpt(file)).append("' ").append(why);
    return false;
  };
  if (!allowed(file, jail)) return refuse("is not a regular file inside the model's folder");
  Result<InputFile> input = InputFile::open(file);
  if (!input) return refuse(input.error().message);
  if (input->size() > jail.max_bytes) return refuse("is larger than the size limit");
  if (input->size() > jail.memory_left)
    return refuse("is larger (" + std::to_string(input->size()) + " bytes) than the memory left under --max-memory");
  jail.memory_left -= input->size();
  out->resize(size_t(input->size()));
  Result<size_t> got = input->readAt(0, out->data(), out->size());
  if (!got || *got != out->size()) return refuse("could not be read whole");
  return true;
}

bool refuseWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "the reader writes no files";
  return false;
}

// Image bytes are never decoded here (tinygltf's own decoder reads past the end of an image stored
// in a bufferView). When the caller wants textures, the encoded bytes of an image given by uri
// (a data URI or a file in the model's folder) are kept in Image::image, as far as --max-memory
// allows (else the image is left empty and its texture unused); an image in a bufferView is read
// from its buffer afterwards (GltfTextures, gltf_texture.h): tinygltf sees a stand-in of zeros.
bool keepImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
               int size, void* user) {
  auto& jail = *static_cast<FolderJail*>(user);
  if (!jail.keep_images || image->bufferView >= 0 || bytes == nullptr || size <= 0) return true;
  if (uint64_t(size) > jail.memory_left) return true;
  jail.memory_left -= uint64_t(size);
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

std::string oneLine(const std::string& text) { return oneLineText(text, "tinygltf gave no reason"); }

struct BinHandOver {
  size_t bin_offset = 0;        // of the BIN chunk's data in the file
  size_t byte_length = 0;       // buffer 0's byteLength
  size_t stand_in_length = 0;   // zeros tinygltf gets instead (covers image views, which it reads)
};

// For a GLB whose buffer 0 is its BIN chunk: shrinks buffers[0].byteLength in the DOM to a
// stand-in that still covers every image bufferView on buffer 0 (tinygltf takes a pointer into
// the buffer for each; the image loader is a no-op), and says where the real bytes are.
// checkDocument has already checked byteLength against the chunk and every view against its buffer.
std::optional<BinHandOver> standInForBin(JsonValue& document, const GlbLayout& glb) {
  if (!glb.bin_length || *glb.bin_length == 0) return std::nullopt;
  JsonValue* buffers = document.find("buffers");
  if (!buffers || buffers->kind != JsonValue::Kind::kArray || buffers->items.empty()) return std::nullopt;
  JsonValue& buffer = buffers->items[0];
  const JsonValue* byte_length = buffer.find("byteLength");
  if (buffer.find("uri") || !byte_length || byte_length->kind != JsonValue::Kind::kNumber) return std::nullopt;
  BinHandOver out;
  out.bin_offset = glb.json_offset + glb.json_length + 8;
  out.byte_length = size_t(byte_length->number);
  if (!(byte_length->number >= 0) || byte_length->number > double(*glb.bin_length)) return std::nullopt;  // tinygltf refuses it
  size_t covered = 4;
  const JsonValue* images = document.find("images");
  const JsonValue* views = document.find("bufferViews");
  if (images && images->kind == JsonValue::Kind::kArray && views && views->kind == JsonValue::Kind::kArray) {
    for (const JsonValue& image : images->items) {
      const JsonValue* index = image.find("bufferView");
      if (!index || index->kind != JsonValue::Kind::kNumber || index->number >= double(views->items.size())) continue;
      const JsonValue& view = views->items[size_t(index->number)];
      const JsonValue* offset = view.find("byteOffset");
      const JsonValue* length = view.find("byteLength");
      if (!length || length->kind != JsonValue::Kind::kNumber) continue;
      const double end = (offset && offset->kind == JsonValue::Kind::kNumber ? offset->number : 0.0) + length->number;
      covered = std::max(covered, size_t(end));
    }
  }
  covered = std::min(covered, out.byte_length == 0 ? size_t{4} : std::max<size_t>(out.byte_length, 4));
  out.stand_in_length = (covered + 3) / 4 * 4;
  buffer.set("byteLength", JsonValue::integerValue(int64_t(out.stand_in_length)));
  return out;
}

Result<tinygltf::Model> load(const InputFile& input, uint64_t max_file_bytes, uint64_t max_memory, bool keep_images) {
  const std::string& path = input.path();
  if (input.size() == 0) return Error{path + ": file is empty"};
  if (input.size() > max_file_bytes)
    return Error{path + ": " + std::to_string(input.size()) + " bytes exceeds the glTF input limit of " +
                     std::to_string(max_file_bytes) + " bytes",
                 ExitCode::kResourceLimit};
  // The model holds the file; what is decoded from it (external files, meshopt views, Draco
  // primitives) shares what is left under --max-memory, each checked before it is allocated.
  if (Status s = checkMemory(path + ": loading " + std::to_string(input.size()) + " bytes", input.size(), max_memory); !s)
    return s.error();
  const uint64_t memory_left = max_memory - input.size();
  std::vector<unsigned char> bytes(size_t(input.size()));
  std::vector<unsigned char> tinygltf_input;  // the GLB tinygltf parses when the BIN chunk is handed over
  Result<size_t> got = input.readAt(0, bytes.data(), bytes.size());
  if (!got) return got.error();
  if (*got != bytes.size()) return Error{path + ": the file shrank while being read"};

  const bool binary = bytes.size() >= 4 && readU32(bytes, 0) == kGlbMagic;
  std::string_view json(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  std::optional<uint64_t> bin_length;
  GlbLayout glb;
  if (binary) {
    Result<GlbLayout> layout = checkGlb(path, bytes);
    if (!layout) return layout.error();
    glb = *layout;
    json = json.substr(layout->json_offset, layout->json_length);
    bin_length = layout->bin_length;
  } else if (json.size() >= 3 && json.substr(0, 3) == "\xEF\xBB\xBF") {
    return Error{path + ": starts with a UTF-8 byte order mark, which glTF forbids"};
  }
  std::vector<DracoIndices> draco_indices;
  // A GLB's BIN chunk is not handed to tinygltf, which would copy it (the file and the copy, twice
  // the input, would be held at once): tinygltf gets the JSON with buffer 0 shrunk to a stand-in
  // of zeros, and the chunk's bytes are moved into buffer 0 in place afterwards.
  std::optional<BinHandOver> hand_over;
  {
    Result<JsonValue> document = parseJson(json, kGltfMaxJsonDepth);
    if (!document) return Error{path + ": JSON " + document.error().message};
    if (auto e = checkDocument(path, *document, bin_length)) return *e;
    // JSON tinygltf 2.7.0 cannot load as written (gltf_meshopt.h, gltf_draco.h) is rewritten.
    const bool fallback_emptied = emptyMeshoptFallbackBuffers(*document, binary);
    draco_indices = detachDracoIndices(*document);
    if (binary) hand_over = standInForBin(*document, glb);
    if (fallback_emptied || !draco_indices.empty() || hand_over) {
      std::string rewritten = writeJson(*document);
      if (binary) {
        // Same chunks after the JSON one (or the stand-in BIN); the JSON chunk padded with spaces
        // to 4 bytes (GLB §4.4.3.1).
        rewritten.append((4 - rewritten.size() % 4) % 4, ' ');
        const size_t rest = glb.json_offset + glb.json_length;
        const size_t end = hand_over ? rest : readU32(bytes, 8);  // checkGlb: ≤ bytes.size()
        const size_t stand_in = hand_over ? 8 + hand_over->stand_in_length : 0;
        std::vector<unsigned char> glb_bytes(12 + 8 + rewritten.size() + (end - rest) + stand_in);
        const uint32_t header[5] = {kGlbMagic, 2, uint32_t(glb_bytes.size()), uint32_t(rewritten.size()), kChunkJson};
        std::memcpy(glb_bytes.data(), header, sizeof header);
        std::memcpy(glb_bytes.data() + 20, rewritten.data(), rewritten.size());
        std::copy(bytes.begin() + std::ptrdiff_t(rest), bytes.begin() + std::ptrdiff_t(end),
                  glb_bytes.begin() + std::ptrdiff_t(20 + rewritten.size()));
        if (hand_over) {
          const uint32_t bin_header[2] = {uint32_t(hand_over->stand_in_length), kChunkBin};
          std::memcpy(glb_bytes.data() + 20 + rewritten.size(), bin_header, sizeof bin_header);  // zeros follow
          tinygltf_input = std::move(glb_bytes);  // the file's bytes stay in `bytes` for the hand-over
        } else {
          bytes = std::move(glb_bytes);
        }
      } else {
        bytes.assign(rewritten.begin(), rewritten.end());
        json = std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
      }
    }
  }  // the DOM is freed before tinygltf builds its own

  std::error_code ec;
  FolderJail jail;
  jail.in_memory = input.inMemory();
  if (!jail.in_memory) {
    jail.base = std::filesystem::absolute(path, ec).parent_path().string();
    if (!ec) jail.canonical = std::filesystem::weakly_canonical(jail.base, ec);
    if (ec) return Error{path + ": cannot resolve its folder: " + ec.message()};
  }
  jail.max_bytes = max_file_bytes;
  jail.memory_left = memory_left;
  jail.keep_images = keep_images;
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({&jailedFileExists, &noExpansion, &jailedReadWholeFile, &refuseWrite, &jail});
  loader.SetImageLoader(&keepImage, &jail);
  tinygltf::Model model;
  std::string err, warn;
  const std::vector<unsigned char>& input_bytes = hand_over ? tinygltf_input : bytes;
  const auto length = static_cast<unsigned int>(input_bytes.size());  // ≤ 2^32−1: the GLB header / cap
  const bool loaded = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, input_bytes.data(), length, jail.base)
                             : loader.LoadASCIIFromString(&model, &err, &warn, json.data(), length, jail.base);
  if (!loaded) return Error{path + ": " + oneLine(err)};
  if (hand_over) {
    // Buffer 0 becomes the BIN chunk's first byte_length bytes, moved down inside the file's own
    // allocation: no second copy of the data exists at any time.
    assert(!model.buffers.empty());
    std::memmove(bytes.data(), bytes.data() + hand_over->bin_offset, hand_over->byte_length);
    bytes.resize(hand_over->byte_length);
    model.buffers[0].data = std::move(bytes);
  }
  // Decoded here so every reader of the model sees plain views; the input cap and what is left of
  // the memory limit bound the output.
  const uint64_t decoded_limit = std::min(max_file_bytes, jail.memory_left);
  if (Status s = decodeMeshoptViews(path, model, decoded_limit); !s) return s.error();
  if (Status s = decodeDracoPrimitives(path, model, draco_indices, decoded_limit); !s) return s.error();
  return model;
}

}  // namespace

bool gltfRequiredExtensionSupported(const std::string& name) {
  // Geometry we decode, or extensions that only change shading; anything else that is required
  // may change positions and is refused by name.
  static const char* const kAccepted[] = {
      "KHR_mesh_quantization", "EXT_meshopt_compression", "KHR_draco_mesh_compression", "EXT_mesh_gpu_instancing",
      "KHR_texture_transform", "KHR_texture_basisu",      "EXT_texture_webp",           "KHR_lights_punctual",
      "KHR_materials_"};
  for (const char* accepted : kAccepted) {
    const std::string_view a(accepted);
    if (a.back() == '_' ? name.rfind(a, 0) == 0 : name == a) return true;
  }
  return false;
}

Result<tinygltf::Model> loadGltfModel(const InputFile& input, uint64_t max_file_bytes, uint64_t max_memory,
                                      bool keep_images) {
  // tinygltf throws (std::bad_alloc on huge byteLength, nlohmann exceptions); none may escape.
  const std::string& path = input.path();
  try {
    return load(input, max_file_bytes, max_memory == 0 ? defaultMemoryLimit() : max_memory, keep_images);
  } catch (const std::bad_alloc&) {
    return Error{path + ": out of memory while loading", ExitCode::kResourceLimit};
  } catch (const std::exception& e) {
    return Error{path + ": " + oneLine(e.what())};
  }
}

}  // namespace dpoint
