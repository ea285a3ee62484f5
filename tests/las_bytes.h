// Fields of LAS and LAZ files held in memory, for the tests that read, build or break them byte by
// byte (LAS 1.4 R15 table 3's offsets). Little-endian hosts, as the readers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

namespace dpoint::test {

template <typename T>
T at(const std::string& bytes, size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof v);
  return v;
}

template <typename T>
void put(std::string& bytes, size_t offset, T v) {
  std::memcpy(bytes.data() + offset, &v, sizeof v);
}

// The header's point count: LAS 1.4's 64-bit one when it is set, else the legacy one.
inline uint64_t lasCount(const std::string& file) {
  uint64_t count = at<uint32_t>(file, 107);
  if (file[25] >= 4 && at<uint64_t>(file, 247) != 0) count = at<uint64_t>(file, 247);
  return count;
}

// The point records of an uncompressed LAS file, straight from its header's fields.
inline std::string lasRecords(const std::string& file) {
  return file.substr(at<uint32_t>(file, 96), lasCount(file) * at<uint16_t>(file, 105));
}

// The first extra bytes descriptor of an uncompressed LAS file (the data of its first LASF_Spec
// record 4): where it starts in the bytes; npos without one.
inline size_t descriptorAt(const std::string& file) {
  size_t vlr = at<uint16_t>(file, 94);  // the header's size: the VLRs follow
  for (uint32_t k = 0, vlrs = at<uint32_t>(file, 100); k < vlrs; ++k) {
    const uint16_t length = at<uint16_t>(file, vlr + 20);
    if (file.compare(vlr + 2, 9, "LASF_Spec") == 0 && at<uint16_t>(file, vlr + 18) == 4) return vlr + 54;
    vlr += 54 + length;
  }
  return std::string::npos;
}

// The offset of the laszip VLR's data (after its 54-byte header) in a LAZ file; 0 without one.
inline size_t laszipVlrAt(const std::string& file) {
  size_t p = at<uint16_t>(file, 94);
  for (uint32_t i = 0; i < at<uint32_t>(file, 100); ++i) {
    if (std::strncmp(file.data() + p + 2, "laszip encoded", 16) == 0) return p + 54;
    p += 54 + at<uint16_t>(file, p + 20);
  }
  return 0;
}

}  // namespace dpoint::test
