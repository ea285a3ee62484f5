// Opening an input file with the checks every reader needs: exists, is a regular file, readable.
#pragma once

#include <cstdint>
#include <string>

#include "core/result.h"

namespace dpoint {

class InputFile {
 public:
  // Fails with a message naming the path when it does not exist, is a folder or cannot be read.
  // An empty file is not an error here; readers decide what empty means.
  static Result<InputFile> open(const std::string& path);

  InputFile(InputFile&& other) noexcept : path_(std::move(other.path_)), fd_(other.fd_), size_(other.size_) {
    other.fd_ = -1;
  }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(InputFile&&) = delete;
  ~InputFile();

  const std::string& path() const { return path_; }
  uint64_t size() const { return size_; }
  // Reads up to `size` bytes at `offset` (pread, safe from several threads). Returns bytes read,
  // fewer only at the end of the file; an I/O error is an Error naming the file.
  Result<size_t> readAt(uint64_t offset, void* data, size_t size) const;

 private:
  InputFile(std::string path, int fd, uint64_t size) : path_(std::move(path)), fd_(fd), size_(size) {}
  std::string path_;
  int fd_ = -1;
  uint64_t size_ = 0;
};

}  // namespace dpoint
