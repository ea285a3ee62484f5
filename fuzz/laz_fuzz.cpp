// libFuzzer target `laz`: dpoint's own LASzip decoder (converters/laz_decode.h: the laszip VLR, the
// chunk table, the chunks' arithmetic code) on a stranger's .laz, as `dpoint convert IN.laz` runs
// it (issue #35: a broken file is one error line, exit 2, never a crash). The input's bytes are a
// file (InputFile::fromMemory) decoded by decodeLaz and read by readLas. Beyond the sanitizers:
// - a decoded file is the header's count of records, no more or fewer bytes;
// - decoding is a function of the bytes: a second decode, on two threads, gives the same records or
//   the same error (decodeLaz's contract: chunks decode into their own places and the first failing
//   chunk's error wins whatever the thread count). One decode serves both rules: a one-chunk file
//   decodes on one thread anyway, and each decode of a few chunks costs most of an input's time
//   (every chunk builds its models afresh);
// - readLas agrees: it reads a compressed file only when the decoder does, into the same count.
#include <cstring>

#include "converters/las.h"
#include "converters/laz_decode.h"
#include "core/bytes.h"
#include "fuzz/fuzz_support.h"

namespace {

using namespace dpoint;

// The count decodeLaz decodes (laz_decode.h): the 64-bit one of a LAS 1.4 header where it is not
// 0, else the legacy one. Called only after a successful decode, which checked the header's size.
uint64_t headerPointCount(const uint8_t* data) {
  uint64_t count = loadUnaligned<uint32_t>(data + 107);
  if (data[25] >= 4 && loadUnaligned<uint64_t>(data + 247) != 0) count = loadUnaligned<uint64_t>(data + 247);
  return count;
}

std::string outcome(const Result<std::string>& r) {
  return r ? "decoded " + std::to_string(r->size()) + " bytes" : r.error().message;
}

void checkSame(const Result<std::string>& a, const Result<std::string>& b, const std::string& rule) {
  if (bool(a) != bool(b) || (a && *a != *b) || (!a && a.error().message != b.error().message))
    fuzz::broken(rule, outcome(a) + " | " + outcome(b));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const InputFile input = InputFile::fromMemory("fuzz.laz", fuzz::bytesOf(data, size));
  Result<std::string> records = decodeLaz(input, 1, fuzz::kMaxMemory);
  if (records) {
    const uint64_t count = headerPointCount(data), length = loadUnaligned<uint16_t>(data + 105);
    if (records->size() != count * length)
      fuzz::broken("a decoded file is count x record length bytes",
                   std::to_string(records->size()) + " for " + std::to_string(count) + " x " + std::to_string(length));
  } else {
    fuzz::checkError(records.error(), input.path());
  }
  checkSame(records, decodeLaz(input, 2, fuzz::kMaxMemory), "decoding again, on two threads, gives the same outcome");

  LasReadOptions options;
  options.threads = 1;
  options.max_memory = fuzz::kMaxMemory;
  Result<PointSet> points = readLas(input, options);
  fuzz::checkOutcome(points, input.path());
  // readLas decodes through decodeLaz when the header's format byte says LAZ (bit 7 or 6).
  const bool compressed = size > 104 && (data[104] & 0xC0) != 0;
  if (points && compressed) {
    if (!records) fuzz::broken("readLas reads only what the decoder decodes", records.error().message);
    if (points->size() != headerPointCount(data))
      fuzz::broken("readLas reads every decoded point",
                   std::to_string(points->size()) + " of " + std::to_string(headerPointCount(data)));
  }
  return 0;
}
