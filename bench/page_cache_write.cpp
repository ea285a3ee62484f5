// How fast a file's bytes reach the page cache, three ways (issue #38 item 4: is one `write`
// stream the limit of `generate`'s face rows at the end?): one thread writing 1 MiB pieces in order
// (as PlyRowStream and dd do), N threads writing 4 MiB pieces of their own with pwrite, and N
// threads copying into a MAP_SHARED mapping of the file (ftruncate, or fallocate first).
//   page_cache_write PATH BYTES pwrite|pwriteN|mmapN|mmapNf [THREADS=8]
// Prints the seconds and GB/s; removes PATH. Run it on the machine and folder the numbers are for
// (the GPU machine: bench/results/2026-11-29/h200/page-cache-write.md).
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

namespace {

double seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool writeAll(int fd, const char* data, size_t bytes, off_t at) {
  while (bytes > 0) {
    const ssize_t n = pwrite(fd, data, bytes, at);
    if (n <= 0) return false;
    data += n, bytes -= static_cast<size_t>(n), at += n;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: page_cache_write PATH BYTES pwrite|pwriteN|mmapN|mmapNf [THREADS]\n");
    return 2;
  }
  const char* path = argv[1];
  const size_t bytes = std::stoull(argv[2]);
  const std::string mode = argv[3];
  const unsigned threads = argc > 4 ? static_cast<unsigned>(std::stoul(argv[4])) : 8u;
  std::vector<char> source(bytes);
  for (size_t i = 0; i < bytes; i += 4096) source[i] = static_cast<char>(i >> 12);  // every page touched
  unlink(path);
  const int fd = open(path, O_RDWR | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) {
    std::perror(path);
    return 1;
  }
  bool ok = true;
  const double start = seconds();
  if (mode == "pwrite") {
    for (size_t at = 0; at < bytes && ok; at += size_t{1} << 20)
      ok = writeAll(fd, source.data() + at, std::min<size_t>(size_t{1} << 20, bytes - at), static_cast<off_t>(at));
  } else if (mode == "pwriteN" || mode == "mmapN" || mode == "mmapNf") {
    char* map = nullptr;
    if (mode != "pwriteN") {
      ok = (mode == "mmapNf" ? fallocate(fd, 0, 0, static_cast<off_t>(bytes)) : ftruncate(fd, static_cast<off_t>(bytes))) == 0;
      void* m = ok ? mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0) : MAP_FAILED;
      ok = m != MAP_FAILED;
      map = ok ? static_cast<char*>(m) : nullptr;
    }
    std::vector<std::thread> workers;
    std::vector<char> failed(threads, 0);
    constexpr size_t kPiece = size_t{4} << 20;
    for (unsigned t = 0; t < threads && ok; ++t)
      workers.emplace_back([&, t] {
        for (size_t at = t * kPiece; at < bytes; at += threads * kPiece) {
          const size_t n = std::min(kPiece, bytes - at);
          if (map)
            std::memcpy(map + at, source.data() + at, n);
          else if (!writeAll(fd, source.data() + at, n, static_cast<off_t>(at)))
            failed[t] = 1;
        }
      });
    for (std::thread& w : workers) w.join();
    ok = ok && std::none_of(failed.begin(), failed.end(), [](char f) { return f != 0; });
    if (map) munmap(map, bytes);
  } else {
    std::fprintf(stderr, "page_cache_write: unknown mode %s\n", mode.c_str());
    ok = false;
  }
  const double elapsed = seconds() - start;
  close(fd);
  unlink(path);
  if (!ok) {
    std::fprintf(stderr, "page_cache_write: %s failed on %s\n", mode.c_str(), path);
    return 1;
  }
  std::printf("%s %u threads: %.3f s (%.2f GB/s)\n", mode.c_str(), mode == "pwrite" ? 1u : threads, elapsed,
              static_cast<double>(bytes) / elapsed / 1e9);
  return 0;
}
