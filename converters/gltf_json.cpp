// Recursive-descent JSON (RFC 8259). Recursion depth is capped by the caller's max_depth, which is
// what makes it safe on hostile input where tinygltf's parser is not.
#include "converters/gltf_json.h"

#include <algorithm>
#include <cassert>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace dpoint {

const JsonValue* JsonValue::find(std::string_view key) const {
  if (kind != Kind::kObject) return nullptr;
  for (const auto& [name, value] : members)
    if (name == key) return &value;
  return nullptr;
}

JsonValue* JsonValue::find(std::string_view key) {
  return const_cast<JsonValue*>(static_cast<const JsonValue&>(*this).find(key));
}

void JsonValue::set(const std::string& key, JsonValue value) {
  assert(kind == Kind::kObject);
  if (JsonValue* member = find(key)) {
    *member = std::move(value);
    return;
  }
  members.push_back(JsonMember{key, std::move(value)});
}

bool JsonValue::erase(std::string_view key) {
  const auto it = std::find_if(members.begin(), members.end(), [&](const auto& m) { return m.first == key; });
  if (it == members.end()) return false;
  members.erase(it);
  return true;
}

JsonValue JsonValue::integerValue(int64_t v) {
  JsonValue out;
  out.kind = Kind::kNumber;
  out.number = double(v);
  out.is_integer = true;
  out.integer = v;
  return out;
}

JsonValue JsonValue::stringValue(const std::string& text) {
  JsonValue out;
  out.kind = Kind::kString;
  out.text = text;
  return out;
}

namespace {

class JsonParser {
 public:
  JsonParser(std::string_view text, int max_depth) : text_(text), max_depth_(max_depth) {}

  Result<JsonValue> document() {
    JsonValue value;
    if (!parseValue(value, 0)) return error();
    skipSpace();
    if (pos_ != text_.size()) {
      fail("unexpected text after the JSON document");
      return error();
    }
    return value;
  }

 private:
  Error error() const { return Error{"byte " + std::to_string(error_pos_) + ": " + error_}; }

  bool fail(const std::string& what) {
    if (error_.empty()) {
      error_ = what;
      error_pos_ = pos_;
    }
    return false;
  }

  void skipSpace() {
    while (pos_ < text_.size() &&
           (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\n' || text_[pos_] == '\r'))
      ++pos_;
  }

  bool literal(std::string_view word) {
    if (text_.substr(pos_, word.size()) != word) return fail("invalid literal");
    pos_ += word.size();
    return true;
  }

  bool parseValue(JsonValue& out, int depth) {
    skipSpace();
    if (pos_ >= text_.size()) return fail("unexpected end of JSON");
    const char c = text_[pos_];
    if (c == '{' || c == '[') {
      // Depth counts open brackets: the 65th nested one is refused before we recurse into it.
      if (depth >= max_depth_)
        return fail("JSON nested deeper than " + std::to_string(max_depth_) + " levels");
      return c == '{' ? parseObject(out, depth + 1) : parseArray(out, depth + 1);
    }
    if (c == '"') {
      out.kind = JsonValue::Kind::kString;
      return parseString(out.text);
    }
    if (c == 't' || c == 'f') {
      out.kind = JsonValue::Kind::kBool;
      out.boolean = c == 't';
      return literal(c == 't' ? "true" : "false");
    }
    if (c == 'n') return literal("null");
    return parseNumber(out);
  }

  bool parseObject(JsonValue& out, int depth) {
    out.kind = JsonValue::Kind::kObject;
    ++pos_;
    skipSpace();
    if (pos_ < text_.size() && text_[pos_] == '}') return ++pos_, true;
    while (true) {
      skipSpace();
      if (pos_ >= text_.size() || text_[pos_] != '"') return fail("expected a member name");
      std::string key;
      if (!parseString(key)) return false;
      skipSpace();
      if (pos_ >= text_.size() || text_[pos_] != ':') return fail("expected ':'");
      ++pos_;
      out.members.push_back(JsonMember{std::move(key), JsonValue{}});
      if (!parseValue(out.members.back().second, depth)) return false;
      skipSpace();
      if (pos_ < text_.size() && text_[pos_] == ',') { ++pos_; continue; }
      if (pos_ < text_.size() && text_[pos_] == '}') return ++pos_, true;
      return fail("expected ',' or '}'");
    }
  }

  bool parseArray(JsonValue& out, int depth) {
    out.kind = JsonValue::Kind::kArray;
    ++pos_;
    skipSpace();
    if (pos_ < text_.size() && text_[pos_] == ']') return ++pos_, true;
    while (true) {
      out.items.emplace_back();
      if (!parseValue(out.items.back(), depth)) return false;
      skipSpace();
      if (pos_ < text_.size() && text_[pos_] == ',') { ++pos_; continue; }
      if (pos_ < text_.size() && text_[pos_] == ']') return ++pos_, true;
      return fail("expected ',' or ']'");
    }
  }

  static void appendUtf8(std::string& s, uint32_t cp) {
    if (cp < 0x80) {
      s += char(cp);
    } else if (cp < 0x800) {
      s += char(0xC0 | (cp >> 6));
      s += char(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      s += char(0xE0 | (cp >> 12));
      s += char(0x80 | ((cp >> 6) & 0x3F));
      s += char(0x80 | (cp & 0x3F));
    } else {
      s += char(0xF0 | (cp >> 18));
      s += char(0x80 | ((cp >> 12) & 0x3F));
      s += char(0x80 | ((cp >> 6) & 0x3F));
      s += char(0x80 | (cp & 0x3F));
    }
  }

  bool hex4(uint32_t& cp) {
    if (text_.size() - pos_ < 4) return fail("truncated \\u escape");
    cp = 0;
    for (int i = 0; i < 4; ++i) {
      const char h = text_[pos_++];
      const uint32_t d = h >= '0' && h <= '9'   ? uint32_t(h - '0')
                         : h >= 'a' && h <= 'f' ? uint32_t(h - 'a' + 10)
                         : h >= 'A' && h <= 'F' ? uint32_t(h - 'A' + 10)
                                                : 16u;
      if (d == 16) return fail("bad hex digit in \\u escape");
      cp = cp * 16 + d;
    }
    return true;
  }

  bool parseString(std::string& out) {
    ++pos_;  // opening quote
    while (pos_ < text_.size()) {
      const char c = text_[pos_++];
      if (c == '"') return true;
      if (static_cast<unsigned char>(c) < 0x20) return fail("control character in a string");
      if (c != '\\') {
        out += c;
        continue;
      }
      if (pos_ >= text_.size()) break;
      const char e = text_[pos_++];
      switch (e) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          uint32_t cp = 0;
          if (!hex4(cp)) return false;
          // A high surrogate followed by a low one is one code point; a lone one becomes U+FFFD.
          if (cp >= 0xD800 && cp < 0xDC00 && text_.substr(pos_, 2) == "\\u") {
            pos_ += 2;
            uint32_t low = 0;
            if (!hex4(low)) return false;
            cp = (low >= 0xDC00 && low < 0xE000) ? 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00)
                                                 : 0xFFFD;
          } else if (cp >= 0xD800 && cp < 0xE000) {
            cp = 0xFFFD;
          }
          appendUtf8(out, cp);
          break;
        }
        default: return fail("invalid escape in a string");
      }
    }
    return fail("unterminated string");
  }

  bool parseNumber(JsonValue& out) {
    const size_t start = pos_;
    if (pos_ < text_.size() && text_[pos_] == '-') ++pos_;
    const size_t digits = pos_;
    while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') ++pos_;
    if (pos_ == digits) return fail("invalid value");
    if (text_[digits] == '0' && pos_ - digits > 1) return fail("number with a leading zero");
    bool integral = true;
    if (pos_ < text_.size() && text_[pos_] == '.') {
      integral = false;
      const size_t frac = ++pos_;
      while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') ++pos_;
      if (pos_ == frac) return fail("number without digits after '.'");
    }
    if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
      integral = false;
      ++pos_;
      if (pos_ < text_.size() && (text_[pos_] == '+' || text_[pos_] == '-')) ++pos_;
      const size_t exp = pos_;
      while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') ++pos_;
      if (pos_ == exp) return fail("number without exponent digits");
    }
    out.kind = JsonValue::Kind::kNumber;
    const std::string token(text_.substr(start, pos_ - start));
    out.number = std::strtod(token.c_str(), nullptr);  // the C locale: the CLI never changes it
    if (integral) {
      const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), out.integer);
      out.is_integer = ec == std::errc() && end == token.data() + token.size();
    }
    return true;
  }

  std::string_view text_;
  int max_depth_;
  size_t pos_ = 0;
  std::string error_;
  size_t error_pos_ = 0;
};

}  // namespace

Result<JsonValue> parseJson(std::string_view text, int max_depth) {
  return JsonParser(text, max_depth).document();
}

namespace {

void appendJson(const JsonValue& v, std::string& out) {
  switch (v.kind) {
    case JsonValue::Kind::kNull: out += "null"; return;
    case JsonValue::Kind::kBool: out += v.boolean ? "true" : "false"; return;
    case JsonValue::Kind::kNumber: {
      if (v.is_integer) {
        out += std::to_string(v.integer);
      } else {
        char digits[32];
        std::snprintf(digits, sizeof digits, "%.17g", v.number);
        out += digits;
      }
      return;
    }
    case JsonValue::Kind::kString: {
      out += '"';
      for (const char c : v.text) {
        if (c == '"' || c == '\\') {
          out += '\\';
          out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
          char escape[8];
          std::snprintf(escape, sizeof escape, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
          out += escape;
        } else {
          out += c;
        }
      }
      out += '"';
      return;
    }
    case JsonValue::Kind::kArray:
      out += '[';
      for (size_t i = 0; i < v.items.size(); ++i) {
        if (i) out += ',';
        appendJson(v.items[i], out);
      }
      out += ']';
      return;
    case JsonValue::Kind::kObject:
      out += '{';
      for (size_t i = 0; i < v.members.size(); ++i) {
        if (i) out += ',';
        appendJson(JsonValue::stringValue(v.members[i].first), out);
        out += ':';
        appendJson(v.members[i].second, out);
      }
      out += '}';
      return;
  }
}

}  // namespace

std::string writeJson(const JsonValue& value) {
  std::string out;
  appendJson(value, out);
  return out;
}

}  // namespace dpoint
