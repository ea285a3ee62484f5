// A small JSON reader for the glTF pre-checks, run before tinygltf sees the text.
// tinygltf 2.7.0 overflows the stack on deep nesting and silently turns bad integers into 0
// (2^32, -4), so we parse the document once ourselves with a depth cap and check the fields whose
// values tinygltf would mangle. writeJson turns a (rewritten) document back into text for
// tinygltf, for the few files whose JSON must change before it can load them (gltf_meshopt.h,
// gltf_draco.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/result.h"

namespace dpoint {

struct JsonMember;

struct JsonValue {
  enum class Kind { kNull, kBool, kNumber, kString, kArray, kObject };
  Kind kind = Kind::kNull;
  bool boolean = false;
  double number = 0.0;
  bool is_integer = false;  // number written without fraction or exponent and fits int64
  int64_t integer = 0;      // valid when is_integer
  std::string text;         // kString: decoded UTF-8
  std::vector<JsonValue> items;     // kArray
  std::vector<JsonMember> members;  // kObject, in file order

  // Member of an object by key; nullptr when absent or when this is not an object.
  const JsonValue* find(std::string_view key) const;
  JsonValue* find(std::string_view key);
  // Replaces the member `key` of an object, or appends it. Requires kind == kObject.
  void set(const std::string& key, JsonValue value);
  // Removes the member `key` of an object if present; returns whether it was.
  bool erase(std::string_view key);

  static JsonValue integerValue(int64_t v);
  static JsonValue stringValue(const std::string& text);
};

// An object member. A struct rather than std::pair: clang with libstdc++ cannot instantiate
// std::pair<std::string, JsonValue> inside JsonValue's own definition (the fuzz build uses clang).
struct JsonMember {
  std::string first;  // the key
  JsonValue second;   // the value
};

// Parses one JSON document. Nesting deeper than max_depth arrays/objects is an error, so the
// recursion is bounded. Errors say "byte N: what" (the caller prefixes the file name).
Result<JsonValue> parseJson(std::string_view text, int max_depth);

// Just enough JSON output to hand a rewritten document to tinygltf: integers as written, other
// numbers with 17 significant digits (round-trips a double), strings escaped per RFC 8259.
std::string writeJson(const JsonValue& value);

}  // namespace dpoint
