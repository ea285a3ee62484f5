// Bad input text quoted in a one-line error message: at most 40 characters, control and
// non-ASCII bytes written as \xNN so the message stays one printable line.
#pragma once

#include <string>
#include <string_view>

namespace dpoint {

inline std::string printableExcerpt(std::string_view text) {
  constexpr size_t kMax = 40;
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  for (size_t i = 0; i < text.size() && out.size() < kMax; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (text.size() > kMax) out += "...";
  return out;
}

}  // namespace dpoint
