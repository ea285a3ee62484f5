#include "core/text.h"

#include <filesystem>

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace dpoint {

std::vector<std::string> splitAt(std::string_view text, char separator) {
  std::vector<std::string> fields;
  for (size_t start = 0;;) {
    const size_t at = text.find(separator, start);
    fields.emplace_back(text.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start));
    if (at == std::string_view::npos) return fields;
    start = at + 1;
  }
}

std::string lowerAscii(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

std::string lowerExtension(const std::string& path) { return lowerAscii(std::filesystem::path(path).extension().string()); }

std::string formatNumber(double v, bool json) {
  if (json && !std::isfinite(v)) return "null";
  char text[32];
  auto r = std::to_chars(text, text + sizeof text, v);
  return std::string(text, r.ptr);
}

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char esc[8];
      std::snprintf(esc, sizeof esc, "\\u%04x", c);
      out += esc;
      continue;
    }
    if (static_cast<unsigned char>(c) >= 0x80) {
      // JSON is UTF-8: a byte that is not (a file name's, a header's text) as the replacement
      // character, not raw, which made the whole document unreadable (a review finding).
      const size_t n = utf8SequenceAt(s, i);
      if (n == 0) {
        out += "\\ufffd";
      } else {
        out.append(s, i, n);
        i += n - 1;
      }
      continue;
    }
    out += c;
  }
  return out + "\"";
}

}  // namespace dpoint
