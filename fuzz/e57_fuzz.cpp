// libFuzzer target `e57`: the E57 reader `dpoint convert IN.e57` runs (converters/e57.h: the paged
// file, its XML tree, the compressed vectors' packets and bit-packed fields). Each whole page's
// checksum is made right first, so that a mutation inside a page reaches what the page holds
// instead of stopping at its CRC (a wrong checksum is tested in tests/converters/e57_test.cpp).
// Read on one thread and on three: the two reads agree. Then streamed (render's --stream): where the
// read succeeded, every block the stream gives is its points; else the stream fails naming the input.
#include <algorithm>
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
  options.packet_window = 1;  // 64 KiB: small files take several windows
  Result<std::unique_ptr<E57PointStream>> stream = E57PointStream::open(InputFile::fromMemory("fuzz.e57", bytes), options);
  if (!stream) {
    if (one && stream.error().code != ExitCode::kResourceLimit)
      fuzz::broken("a file read whole opens as a stream", stream.error().message);
    fuzz::checkError(stream.error(), input.path());
    return 0;
  }
  if (one && (*stream)->count() != one->size())
    fuzz::broken("a stream has the points a read has", std::to_string((*stream)->count()) + " for " + std::to_string(one->size()));
  const uint64_t count = (*stream)->count();
  PointSet block;
  constexpr uint64_t kBlock = 997;
  for (uint64_t first = 0; first < count && first < 100000; first += kBlock) {
    const uint64_t n = std::min(kBlock, count - first);
    if (Status s = (*stream)->read(first, n, block); !s) {
      if (one && s.error().code != ExitCode::kResourceLimit) fuzz::broken("a file read whole streams", s.error().message);
      fuzz::checkError(s.error(), input.path());
      return 0;
    }
    fuzz::checkPoints(block);
    if (one && (block.size() != n || std::memcmp(block.positions.data(), one->positions.data() + first, n * sizeof(glm::dvec3)) != 0))
      fuzz::broken("a stream's block is the read's points", std::to_string(first));
  }
  return 0;
}
