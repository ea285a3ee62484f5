// libFuzzer target `las`: the LAS reader `dpoint convert IN.las` runs (converters/las.h: LAS 1.0-1.4,
// point formats 0-10, VLRs and EVLRs skipped), given the input's bytes as a file
// (InputFile::fromMemory), once with colours as the file has them and once by classification
// (`render --color classification`), which must agree on the positions.
#include <cstring>

#include "converters/las.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace dpoint;
  const InputFile input = InputFile::fromMemory("fuzz.las", fuzz::bytesOf(data, size));
  LasReadOptions options;
  options.threads = 1;
  options.max_memory = fuzz::kMaxMemory;
  Result<PointSet> rgb = readLas(input, options);
  fuzz::checkOutcome(rgb, input.path());
  options.color = LasColorSource::kClassification;
  Result<PointSet> classes = readLas(input, options);
  fuzz::checkOutcome(classes, input.path());
  // The colour source changes the colours only: both reads succeed or fail together, and agree
  // on every position bit for bit.
  if (bool(rgb) != bool(classes))
    fuzz::broken("the colour source does not decide whether a file reads",
                 rgb ? classes.error().message : rgb.error().message);
  if (rgb && (rgb->size() != classes->size() ||
              (rgb->size() && std::memcmp(rgb->positions.data(), classes->positions.data(),
                                          rgb->size() * sizeof(rgb->positions[0])) != 0)))
    fuzz::broken("the colour source changes no position", std::to_string(rgb->size()));
  if (classes && classes->colors.size() != classes->size())
    fuzz::broken("classification colours every point", std::to_string(classes->colors.size()));
  return 0;
}
