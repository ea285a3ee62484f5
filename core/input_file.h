// Opening an input file with the checks every reader needs: exists, is a regular file, readable.
// Readers take an InputFile, so the same code reads a file or bytes in memory (the fuzz targets).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/result.h"

namespace dpoint {

// The error of a file that could not be opened (errno `error_number`), naming it; too many open
// files is a resource limit (kResourceLimit), with the process's limit and how to raise it.
Error cannotOpen(const std::string& path, int error_number);

class InputFile {
 public:
  // Fails with a message naming the path when it does not exist, is a folder or cannot be read.
  // An empty file is not an error here; readers decide what empty means.
  static Result<InputFile> open(const std::string& path);
  // `bytes` read as if they were a file named `name` (which names it in errors); no file is
  // opened. The bytes must outlive the InputFile.
  static InputFile fromMemory(std::string name, std::string_view bytes);
  // Bytes [offset, offset + size) of this file read as a file of their own, under the same name
  // (a PTX scan's rows for the CSV reader). It reads through this file's descriptor, so this file
  // must outlive it; reads stop at its end.
  InputFile slice(uint64_t offset, uint64_t size) const;

  InputFile(InputFile&& other) noexcept
      : path_(std::move(other.path_)), fd_(other.fd_), size_(other.size_), memory_(other.memory_),
        base_(other.base_), owns_fd_(other.owns_fd_) {
    other.fd_ = -1;
  }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(InputFile&&) = delete;
  ~InputFile();

  const std::string& path() const { return path_; }
  uint64_t size() const { return size_; }
  // True for fromMemory: there is no folder beside it to read other files from.
  bool inMemory() const { return memory_ != nullptr; }
  // Reads up to `size` bytes at `offset` (pread, safe from several threads). Returns bytes read,
  // fewer only at the end of the file; an I/O error is an Error naming the file, and so is an
  // interrupt (interruptedError, core/interrupt.h).
  Result<size_t> readAt(uint64_t offset, void* data, size_t size) const;

 private:
  InputFile(std::string path, int fd, uint64_t size, const char* memory = nullptr)
      : path_(std::move(path)), fd_(fd), size_(size), memory_(memory) {}
  std::string path_;
  int fd_ = -1;
  uint64_t size_ = 0;
  const char* memory_ = nullptr;  // fromMemory: the bytes (fd_ is -1)
  uint64_t base_ = 0;             // a slice: where it starts in the file
  bool owns_fd_ = true;           // false for a slice, which reads through its file's descriptor
};

}  // namespace dpoint
