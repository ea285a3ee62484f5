// libFuzzer target `pcd`: the PCD reader `dpoint convert IN.pcd` runs (converters/pcd.h: the header,
// ASCII, binary and LZF-compressed data), given the input's bytes as a file (InputFile::fromMemory),
// on one thread and on three: the two reads agree.
#include <cstring>

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
  if (one)
    for (const Dimension& d : one->dimensions.all())
      if (d.size() != one->size()) fuzz::broken("one value per point in each dimension", d.name);
  options.threads = 3;
  Result<PointSet> three = readPcd(input, options);
  if (one.ok() != three.ok()) fuzz::broken("the thread count does not change the outcome", input.path());
  const auto same = [](const auto& a, const auto& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
  };
  if (one && !(same(one->positions, three->positions) && same(one->colors, three->colors)))
    fuzz::broken("the thread count does not change the points", std::to_string(one->size()));
  if (!one && one.error().message != three.error().message)
    fuzz::broken("the thread count does not change the error", one.error().message + " | " + three.error().message);
  return 0;
}
