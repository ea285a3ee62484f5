// libFuzzer target `pcd`: the PCD reader `dpoint convert IN.pcd` runs (converters/pcd.h: the header,
// ASCII, binary and LZF-compressed data), given the input's bytes as a file (InputFile::fromMemory),
// on one thread and on three: the two reads agree.
#include "converters/pcd.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace dpoint;
  const InputFile input = InputFile::fromMemory("fuzz.pcd", fuzz::bytesOf(data, size));
  PcdReadOptions options;
  options.threads = 1;
  options.max_memory = fuzz::kMaxMemory;
  Result<PointSet> one = readPcd(input, options);
  fuzz::checkOutcome(one, input.path());
  options.threads = 3;
  Result<PointSet> three = readPcd(input, options);
  fuzz::checkThreadCountsAgree(one, three, input.path());
  return 0;
}
