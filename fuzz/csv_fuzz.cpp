// libFuzzer target `csv`: the CSV reader `dpoint convert IN.csv` runs (converters/csv.h), given the
// input's bytes as a file (InputFile::fromMemory), and the PTX reader on the same bytes as IN.ptx
// (converters/ptx_read.cpp, which reads each scan's rows through the CSV reader). One thread:
// inputs are far smaller than a block.
#include "converters/csv.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace dpoint;
  const InputFile input = InputFile::fromMemory("fuzz.csv", fuzz::bytesOf(data, size));
  CsvReadOptions options;
  options.threads = 1;
  options.max_memory = fuzz::kMaxMemory;
  fuzz::checkOutcome(readCsv(input, options), input.path());
  const InputFile scans = InputFile::fromMemory("fuzz.ptx", fuzz::bytesOf(data, size));
  fuzz::checkOutcome(readCsv(scans, options), scans.path());
  return 0;
}
