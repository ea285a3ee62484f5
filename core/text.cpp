#include "core/text.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace dpoint {

std::string formatNumber(double v, bool json) {
  if (json && !std::isfinite(v)) return "null";
  char text[32];
  auto r = std::to_chars(text, text + sizeof text, v);
  return std::string(text, r.ptr);
}

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char esc[8];
      std::snprintf(esc, sizeof esc, "\\u%04x", c);
      out += esc;
      continue;
    }
    out += c;
  }
  return out + "\"";
}

}  // namespace dpoint
