// Text for messages and reports: bad input quoted in a one-line error message, numbers in
// shortest round-trip form, JSON strings. Shared by the readers, the CLI and the bench report.
#pragma once

#include <algorithm>
#include <cassert>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "core/memory.h"

namespace dpoint {

// "a.ply" for one path, "a.ply and 3 more" for several: for messages and reports.
inline std::string describeInputs(const std::vector<std::string>& paths) {
  if (paths.size() == 1) return paths[0];
  return paths[0] + " and " + std::to_string(paths.size() - 1) + " more";
}

// The length of the well-formed UTF-8 sequence of two to four bytes at text[i] (Unicode's table 3-7:
// a lead byte C2-F4, its continuation bytes, and no overlong form, surrogate or code point past
// U+10FFFF, which a strict decoder such as Python's refuses: a review finding), or 0.
inline size_t utf8SequenceAt(std::string_view text, size_t i) {
  const unsigned char c = static_cast<unsigned char>(text[i]);
  const size_t n = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
  if (n == 0 || i + n > text.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if ((static_cast<unsigned char>(text[i + k]) & 0xC0) != 0x80) return 0;
  const unsigned char second = static_cast<unsigned char>(text[i + 1]);
  if ((c == 0xE0 && second < 0xA0) || (c == 0xED && second > 0x9F) || (c == 0xF0 && second < 0x90) ||
      (c == 0xF4 && second > 0x8F))
    return 0;
  return n;
}

// A byte as two lower-case hex digits.
inline void appendHexDigits(std::string& out, unsigned char c) {
  static const char kHex[] = "0123456789abcdef";
  out += kHex[c >> 4];
  out += kHex[c & 15];
}

// The offset of the first byte of `text` that is not plain text a header or an XML document can
// carry (well-formed UTF-8 with no control byte but tab, line feed and carriage return, no DEL, and
// not U+FFFE or U+FFFF, which XML refuses), or npos.
inline size_t firstNonTextByte(std::string_view text) {
  for (size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    const size_t sequence = c >= 0x80 ? utf8SequenceAt(text, i) : 1;
    if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f || sequence == 0) return i;
    if (c == 0xEF && text.compare(i + 1, 2, "\xBF\xBE") == 0) return i;  // U+FFFE
    if (c == 0xEF && text.compare(i + 1, 2, "\xBF\xBF") == 0) return i;  // U+FFFF
    i += sequence - 1;
  }
  return std::string_view::npos;
}

// Bytes as lower-case hex digits in pieces of at most `piece_bytes` bytes each (header comment
// lines: Open3D's PLY and PCD readers stop at a line over 1,024 bytes); none for no bytes.
inline std::vector<std::string> hexPieces(std::string_view bytes, size_t piece_bytes) {
  std::vector<std::string> pieces;
  for (size_t at = 0; at < bytes.size(); at += piece_bytes) {
    std::string& piece = pieces.emplace_back();
    for (size_t i = at; i < std::min(bytes.size(), at + piece_bytes); ++i) appendHexDigits(piece, static_cast<unsigned char>(bytes[i]));
  }
  return pieces;
}

// Appends the bytes that lower- or upper-case hex digits spell; false, appending nothing, where
// `hex` is not an even number of them.
inline bool appendHexBytes(std::string& out, std::string_view hex) {
  const auto nibble = [](char c) {
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
  };
  if (hex.size() % 2 != 0) return false;
  for (char c : hex)
    if (nibble(c) < 0) return false;
  for (size_t k = 0; k < hex.size(); k += 2) out += static_cast<char>(nibble(hex[k]) * 16 + nibble(hex[k + 1]));
  return true;
}

// A byte as \xNN, how a message shows a control byte or a byte that is not UTF-8 so that it stays
// one printable line.
inline void appendHexByte(std::string& out, unsigned char c) {
  out += "\\x";
  appendHexDigits(out, c);
}

// Bad input text quoted in a one-line error message: at most 40 characters, UTF-8 letters as they
// are (a header `Höhe` reads as Höhe), control bytes and bytes that are not UTF-8 written as \xNN
// so the message stays one printable line.
inline std::string printableExcerpt(std::string_view text) {
  constexpr size_t kMax = 40;
  std::string out;
  for (size_t i = 0; i < text.size() && out.size() < kMax; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (const size_t n = c >= 0x80 ? utf8SequenceAt(text, i) : 0; n > 0) {
      out.append(text.substr(i, n));
      i += n - 1;
    } else if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      appendHexByte(out, c);
    }
  }
  if (text.size() > kMax) out += "...";
  return out;
}

// "1 scan", "3 scans": a count and its noun, plural with an s.
inline std::string countOf(uint64_t n, const char* what) { return std::to_string(n) + " " + what + (n == 1 ? "" : "s"); }

// printableExcerpt in single quotes. (Built by appending: GCC 12 warns falsely on "'" + string,
// bug 105651.)
inline std::string quotedExcerpt(std::string_view text) {
  std::string out = "'";
  out += printableExcerpt(text);
  out += '\'';
  return out;
}

// A library's own message (tinygltf's, libdraco's) as part of a one-line error: trailing blanks
// dropped, line ends become "; ", other control bytes \xNN, and a word longer than 200 bytes (a
// data URI tinygltf quotes whole: 2.7 MB of base64 in one error line) cut to its first 80 and its
// length. `empty` when nothing is left.
inline std::string oneLineText(std::string_view text, std::string_view empty) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.remove_suffix(1);
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      out += "; ";
    } else if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
      continue;
    } else if (c < 0x20 || c == 0x7f) {
      appendHexByte(out, c);
    } else {
      out += static_cast<char>(c);
    }
  }
  constexpr size_t kLongWord = 200, kKept = 80;
  std::string shortened;
  for (size_t at = 0; at < out.size();) {
    const size_t end = std::min(out.find(' ', at), out.size());
    if (end - at <= kLongWord) {
      shortened.append(out, at, end - at);
    } else {
      size_t cut = at + kKept;
      while (cut > at && (static_cast<unsigned char>(out[cut]) & 0xC0) == 0x80) --cut;  // whole UTF-8 characters
      shortened.append(out, at, cut - at).append("… (" + std::to_string(end - at) + " bytes)");
    }
    if (end < out.size()) shortened += ' ';
    at = end + 1;
  }
  return shortened.empty() ? std::string(empty) : shortened;
}

// Decimal digits only, no sign, no spaces, at most 2^64 - 1 (18446744073709551615): false otherwise.
inline bool parseDecimalU64(std::string_view text, uint64_t& value) {
  if (text.empty()) return false;
  value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
    if (__builtin_mul_overflow(value, uint64_t{10}, &value) ||
        __builtin_add_overflow(value, static_cast<uint64_t>(c - '0'), &value))
      return false;
  }
  return true;
}

// Decimal digits only, at least one: a number parseDecimalU64 refuses only for its size.
inline bool allDecimalDigits(std::string_view text) {
  return !text.empty() && text.find_first_not_of("0123456789") == std::string_view::npos;
}

// `text` split at every `separator`, empty fields kept ("a,,b": a, "", b; "": one empty field).
std::vector<std::string> splitAt(std::string_view text, char separator);

// A path's extension in lower case, with its dot (".las" for "SCAN.LAS"), "" when it has none: what
// the readers and writers choose a format by.
std::string lowerExtension(const std::string& path);
// `text` with its ASCII letters in lower case (other bytes as they are).
std::string lowerAscii(std::string text);

// Where a number's text starts after a leading '+', which writers emit (printf's %+g) and
// fast_float, as std::from_chars, refuses: "+1.5" from "1.5"; "+-1" and "++1" keep theirs and so do
// not parse. The text readers (CSV, PCD, PLY) all take a '+' so.
inline const char* afterPlusSign(const char* begin, const char* end) {
  return end - begin >= 2 && *begin == '+' && begin[1] != '-' && begin[1] != '+' ? begin + 1 : begin;
}

// Shortest round-trip text; JSON has no infinity, so non-finite values become null there.
std::string formatNumber(double v, bool json = false);
// A JSON string literal: quotes, with '"', '\\' and control characters escaped.
std::string jsonString(const std::string& s);

// Text made a piece at a time, numbers formatted straight into it, in a buffer that grows without
// zeroing (DefaultInitAllocator): the ASCII writers' rows. Appending each number to a std::vector<char>
// or std::string (a memcpy call a number, a zero-fill a growth) was a quarter of an ASCII PLY write.
class TextBuffer {
 public:
  void clear() { used_ = 0; }
  // Room for `size` characters in all, made at once (a text whose size is about known).
  void reserve(size_t size) {
    if (size > bytes_.size()) bytes_.resize(size);
  }
  size_t size() const { return used_; }
  const char* data() const { return bytes_.data(); }
  void append(char c) { *room(1) = c, ++used_; }
  void append(std::string_view piece) {
    std::memcpy(room(piece.size()), piece.data(), piece.size());
    used_ += piece.size();
  }
  // An integer, or a float in shortest round-trip form (std::to_chars).
  template <typename T>
  void appendNumber(T value) {
    constexpr size_t kMost = 40;  // a double's shortest form is at most 24 characters
    char* at = room(kMost);
    used_ += static_cast<size_t>(std::to_chars(at, at + kMost, value).ptr - at);
  }
  // Up to `most` characters made by write(begin, limit), which returns the end of what it wrote:
  // a row whose longest form is known, formatted with one check of the room.
  template <typename Write>
  void appendWith(size_t most, const Write& write) {
    char* at = room(most);
    char* end = write(at, at + most);
    assert(end >= at && end <= at + most);
    used_ += static_cast<size_t>(end - at);
  }

 private:
  // Room for at least `size` more characters at the end.
  char* room(size_t size) {
    if (used_ + size > bytes_.size()) bytes_.resize(std::max(2 * bytes_.size(), used_ + size + 4096));
    return bytes_.data() + used_;
  }
  std::vector<char, DefaultInitAllocator<char>> bytes_;
  size_t used_ = 0;
};

}  // namespace dpoint
