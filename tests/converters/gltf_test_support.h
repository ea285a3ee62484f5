// Helpers the glTF test files share: hand-written .gltf files with embedded buffers, read back,
// and the check that a refused file gives one line naming it.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "converters/gltf_read.h"
#include "test_support.h"

namespace dpoint::test {

// RFC 4648 base64, for `data:` URIs.
inline std::string base64(const std::vector<unsigned char>& bytes) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t chunk = uint32_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) chunk |= uint32_t(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) chunk |= bytes[i + 2];
    for (size_t k = 0; k < 4; ++k) out += i + k <= bytes.size() ? kDigits[(chunk >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

// Writes `json` as scene.gltf in `dir` and reads it.
inline Result<PointSet> readText(const TempDir& dir, const std::string& json) {
  writeFile(dir.file("scene.gltf"), json);
  return readGltf(dir.file("scene.gltf"));
}

// The file is refused with one line that starts with its path and contains every part.
inline void expectReadError(const std::string& json, const std::vector<std::string>& parts) {
  TempDir dir;
  Result<PointSet> set = readText(dir, json);
  ASSERT_FALSE(set);
  const std::string& message = set.error().message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind(dir.file("scene.gltf") + ": ", 0), 0u) << message;
  for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
}

}  // namespace dpoint::test
