// Text for messages and reports: bad input quoted in a one-line error message, numbers in
// shortest round-trip form, JSON strings. Shared by the readers, the CLI and the bench report.
#pragma once

#include <string>
#include <string_view>

namespace dpoint {

// Bad input text quoted in a one-line error message: at most 40 characters, control and
// non-ASCII bytes written as \xNN so the message stays one printable line.
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

// Shortest round-trip text; JSON has no infinity, so non-finite values become null there.
std::string formatNumber(double v, bool json = false);
// A JSON string literal: quotes, with '"', '\\' and control characters escaped.
std::string jsonString(const std::string& s);

}  // namespace dpoint
