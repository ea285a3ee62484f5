// libFuzzer target `e57`: the E57 reader `dpoint convert IN.e57` runs (converters/e57.h: the paged
// file, its XML tree, the compressed vectors' packets and bit-packed fields). Each whole page's
// checksum is made right first, so that a mutation inside a page reaches what the page holds
// instead of stopping at its CRC (a wrong checksum is tested in tests/converters/e57_test.cpp).
// Read on one thread and on three: the two reads agree.
#include <cstring>
#include <string>

#include "converters/e57.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace dpoint;
  std::string bytes(fuzz::bytesOf(data, size));
  for (size_t page = 0; page + 1024 <= bytes.size(); page += 1024) {
    const uint32_t crc = __builtin_bswap32(crc32c(reinterpret_cast<const uint8_t*>(bytes.data() + page), 1020));
    std::memcpy(bytes.data() + page + 1020, &crc, 4);
  }
  const InputFile input = InputFile::fromMemory("fuzz.e57", bytes);
  E57ReadOptions options;
  options.threads = 1;
  options.max_memory = fuzz::kMaxMemory;
  Result<PointSet> one = readE57(input, options);
  fuzz::checkOutcome(one, input.path());
  options.threads = 3;
  Result<PointSet> three = readE57(input, options);
  fuzz::checkThreadCountsAgree(one, three, input.path());
  return 0;
}
