#include "core/json_writer.h"

#include "core/text.h"

namespace dpoint {

JsonValue JsonValue::number(double v) { return JsonValue(formatNumber(v, true)); }
JsonValue JsonValue::integer(uint64_t v) { return JsonValue(std::to_string(v)); }
JsonValue JsonValue::string(std::string_view text) { return JsonValue(jsonString(std::string(text))); }
JsonValue JsonValue::boolean(bool v) { return JsonValue(v ? "true" : "false"); }
JsonValue JsonValue::null() { return JsonValue("null"); }

JsonValue JsonValue::numbers(std::span<const double> values) {
  std::string text = "[";
  for (size_t i = 0; i < values.size(); ++i) {
    if (i) text += ", ";
    text += formatNumber(values[i], true);
  }
  return JsonValue(text + "]");
}

JsonValue JsonValue::object(const JsonObject& object) { return JsonValue(object.line()); }

JsonValue JsonValue::array(std::span<const JsonValue> values) {
  std::string text = "[";
  for (size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + values[i].text();
  return JsonValue(text + "]");
}

JsonObject& JsonObject::add(std::string_view key, const JsonValue& value) {
  members_.emplace_back(jsonString(std::string(key)), value.text());
  return *this;
}

std::string JsonObject::line() const {
  std::string text = "{";
  for (size_t i = 0; i < members_.size(); ++i) {
    if (i) text += ", ";
    text += members_[i].first + ": " + members_[i].second;
  }
  return text + "}";
}

std::string JsonObject::block() const {
  std::string text = "{\n";
  for (size_t i = 0; i < members_.size(); ++i) {
    if (i) text += ",\n";
    text += "  " + members_[i].first + ": " + members_[i].second;
  }
  return text + "\n}\n";
}

}  // namespace dpoint
