// The item decoders of pointwise LAZ code (compressors 1 and 2): one per item of a record, each
// starting from the raw first item of its code (a chunk's, or the whole point data's for
// compressor 1) and then decoding one item per point in place of the last one. Internal to
// laz_decode.cpp, which drives them, and laz_decode_v1.cpp and laz_decode_v2.cpp, which hold them;
// laz_decode.h says what LAZ is.
//
// A decoder lives for one code: LASzip resets every model and state where a chunk starts, which a
// fresh decoder is. Decoders never read outside their LazDecoder's bytes (laz_codec.h); the
// caller checks the decoder's ok() once per point.
#pragma once

#include <cstdint>
#include <memory>

#include "converters/laz_codec.h"
#include "converters/laz_decode.h"

namespace dpoint {

class LazItemDecoder {
 public:
  virtual ~LazItemDecoder() = default;
  virtual void decode(LazDecoder& decoder, uint8_t* item) = 0;
  // True once the item's code held something no encoder writes that the arithmetic decoder cannot
  // see (version 2's GPS time switching sequence twice within one point).
  virtual bool corrupt() const { return false; }
};

// The version-1 (LASzip 1.x) or version-2 decoder of `item` (POINT10, GPSTIME11, RGB12 or BYTE of
// that version, as parseLaszipVlr accepts; an assert), starting from the raw item at `first`
// (item.size bytes).
std::unique_ptr<LazItemDecoder> makeLazItemDecoderV1(const LazItem& item, const uint8_t* first);
std::unique_ptr<LazItemDecoder> makeLazItemDecoderV2(const LazItem& item, const uint8_t* first);

}  // namespace dpoint
