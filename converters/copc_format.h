// What COPC's writer and reader share (converters/copc.h says what and whence): the LAS 1.4 header
// offsets and record numbers both use, and a VLR's user ID. Internal to copc_write.cpp and
// copc_read.cpp.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace dpoint::copc_detail {

static_assert(std::endian::native == std::endian::little, "LAS fields are little-endian, copied as they are");

inline std::string str(uint64_t v) { return std::to_string(v); }

// LAS 1.4 R15 header offsets (table 3).
constexpr size_t kGlobalEncodingAt = 6, kVersionMajorAt = 24, kVersionMinorAt = 25, kHeaderSizeAt = 94;
constexpr size_t kPointOffsetAt = 96, kVlrCountAt = 100, kFormatAt = 104, kRecordLengthAt = 105;
constexpr size_t kLegacyCountAt = 107, kLegacyByReturnAt = 111, kScaleAt = 131, kOffsetAt = 155;
constexpr size_t kMaxXAt = 179, kWaveformAt = 227, kEvlrStartAt = 235, kEvlrCountAt = 243, kCountAt = 247;
constexpr size_t kByReturnAt = 255;
constexpr size_t kHeader14 = 375, kVlrHeaderBytes = 54, kEvlrHeaderBytes = 60;
constexpr size_t kInfoBytes = 160, kEntryBytes = 32;
constexpr uint16_t kWktBit = 1u << 4;
constexpr uint16_t kInfoRecord = 1, kHierarchyRecord = 1000, kLaszipRecord = 22204;

// A VLR's or EVLR's user ID: 16 bytes, NUL-padded.
inline std::string_view userId(const char* header) { return {header + 2, strnlen(header + 2, 16)}; }

}  // namespace dpoint::copc_detail
