// laz_speed: the LAZ codec alone, for bench/scripts/laz_speed.sh (issue #35). Decodes a .laz file's
// records from memory (the file read once beforehand, as laz-perf's benchmark has it in memory) R
// times on T threads and prints the median; with --encode, compresses a .las file's records.
//
//   laz_speed FILE.laz [--threads T] [--repeats R]      -> "decode points=N threads=T median_ms=M"
//   laz_speed FILE.las --encode [--threads T] [--repeats R]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "converters/laz_decode.h"
#include "converters/laz_encode.h"
#include "core/input_file.h"

int main(int argc, char** argv) {
  using namespace dpoint;
  std::string path;
  unsigned threads = 1, repeats = 7;
  bool encode = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc) threads = static_cast<unsigned>(std::atoi(argv[++i]));
    else if (a == "--repeats" && i + 1 < argc) repeats = static_cast<unsigned>(std::max(1, std::atoi(argv[++i])));
    else if (a == "--encode") encode = true;
    else path = a;
  }
  if (path.empty()) {
    std::fprintf(stderr, "usage: laz_speed FILE.laz|FILE.las [--encode] [--threads T] [--repeats R]\n");
    return 1;
  }
  Result<InputFile> file = InputFile::open(path);
  if (!file) {
    std::fprintf(stderr, "laz_speed: %s\n", file.error().message.c_str());
    return 2;
  }
  std::string bytes(file->size(), '\0');
  if (Result<size_t> got = file->readAt(0, bytes.data(), bytes.size()); !got || *got != bytes.size()) {
    std::fprintf(stderr, "laz_speed: %s: cannot read\n", path.c_str());
    return 2;
  }
  const InputFile memory = InputFile::fromMemory(path, bytes);
  std::vector<double> ms;
  size_t out_bytes = 0;
  for (unsigned r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    if (encode) {
      Result<std::string> laz = compressLasBytes(bytes, threads);
      if (!laz) {
        std::fprintf(stderr, "laz_speed: %s: %s\n", path.c_str(), laz.error().message.c_str());
        return 2;
      }
      out_bytes = laz->size();
    } else {
      // What readLas decodes into (decodeLazRecords: memory the workers touch first).
      Result<LazRecords> records = decodeLazRecords(memory, threads);
      if (!records) {
        std::fprintf(stderr, "laz_speed: %s\n", records.error().message.c_str());
        return 2;
      }
      out_bytes = records->bytes.size();
    }
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  std::printf("%s bytes_out=%zu threads=%u median_ms=%.3f\n", encode ? "encode" : "decode", out_bytes, threads,
              ms[ms.size() / 2]);
  return 0;
}
