// JSON reports built member by member, in order, with the project's number and string forms
// (core/text.h: formatNumber, jsonString), instead of by concatenating text. A JsonObject prints
// as a block (one member a line, the form of render's --json) or on one line (nested values).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace dpoint {

class JsonObject;

// One JSON value, already written out.
class JsonValue {
 public:
  static JsonValue number(double v);  // shortest round trip; null when not finite
  static JsonValue integer(uint64_t v);
  static JsonValue string(std::string_view text);
  static JsonValue boolean(bool v);
  static JsonValue null();
  static JsonValue numbers(std::span<const double> values);  // [1, 2.5] on one line
  static JsonValue object(const JsonObject& object);         // {"a": 1, "b": 2} on one line
  static JsonValue array(std::span<const JsonValue> values); // ["a", {"b": 2}] on one line
  const std::string& text() const { return text_; }

 private:
  explicit JsonValue(std::string text) : text_(std::move(text)) {}
  std::string text_;
};

// Members in the order they are added (a key added twice appears twice: the caller's mistake).
class JsonObject {
 public:
  JsonObject& add(std::string_view key, const JsonValue& value);
  JsonObject& add(std::string_view key, const JsonObject& object) { return add(key, JsonValue::object(object)); }
  bool empty() const { return members_.empty(); }
  // {"a": 1, "b": 2}
  std::string line() const;
  // "{\n  \"a\": 1,\n  \"b\": 2\n}\n": a file's whole content.
  std::string block() const;

 private:
  std::vector<std::pair<std::string, std::string>> members_;  // the key as a JSON string, the value's text
};

}  // namespace dpoint
