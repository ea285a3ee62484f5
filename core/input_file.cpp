#include "core/input_file.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "core/interrupt.h"

namespace dpoint {

Error cannotOpen(const std::string& path, int error_number) {
  std::string message = path + ": cannot open: " + std::strerror(error_number);
  if (error_number != EMFILE && error_number != ENFILE) return Error{message};
  struct rlimit limit {};
  if (error_number == EMFILE && ::getrlimit(RLIMIT_NOFILE, &limit) == 0)
    message += " (this process may hold " + std::to_string(limit.rlim_cur) + "; a shell raises that with `ulimit -n`)";
  return Error{message, ExitCode::kResourceLimit};
}

Result<InputFile> InputFile::open(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return Error{path + ": file not found"};
    return Error{path + ": " + std::strerror(errno)};
  }
  if (S_ISDIR(st.st_mode)) return Error{path + ": is a folder, not a file"};
  // Its size is what every reader goes by: a pipe or a device has none (it had read as "empty file").
  if (!S_ISREG(st.st_mode))
    return Error{path + ": not a regular file (" +
                 (S_ISFIFO(st.st_mode) ? "a pipe" : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device" : "a socket") +
                 "): dpoint reads files whose size it can see; copy it into one first"};
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return cannotOpen(path, errno);
  return InputFile(path, fd, static_cast<uint64_t>(st.st_size));
}

InputFile InputFile::fromMemory(std::string name, std::string_view bytes) {
  // A non-null pointer even for no bytes: inMemory() tells the two kinds apart.
  static const char kEmpty = 0;
  return InputFile(std::move(name), -1, bytes.size(), bytes.empty() ? &kEmpty : bytes.data());
}

InputFile InputFile::slice(uint64_t offset, uint64_t size) const {
  offset = std::min(offset, size_);
  InputFile part(path_, fd_, std::min(size, size_ - offset), memory_ ? memory_ + offset : nullptr);
  part.base_ = base_ + offset;
  part.owns_fd_ = false;
  return part;
}

InputFile::~InputFile() {
  if (fd_ >= 0 && owns_fd_) ::close(fd_);
}

Result<size_t> InputFile::readAt(uint64_t offset, void* data, size_t size) const {
  // Every reader comes through here: an interrupted run stops reading (core/interrupt.h).
  if (interrupted()) return interruptedError();
  // No bytes asked for: `data` may be an empty vector's null pointer, which memcpy must not get.
  if (size == 0) return size_t{0};
  if (memory_) {
    if (offset >= size_) return size_t{0};
    const size_t n = static_cast<size_t>(std::min<uint64_t>(size, size_ - offset));
    std::memcpy(data, memory_ + offset, n);
    return n;
  }
  if (!owns_fd_) {  // a slice reads no further than its end
    if (offset >= size_) return size_t{0};
    size = static_cast<size_t>(std::min<uint64_t>(size, size_ - offset));
  }
  offset += base_;
  size_t total = 0;
  char* out = static_cast<char*>(data);
  while (total < size) {
    ssize_t n = ::pread(fd_, out + total, size - total, static_cast<off_t>(offset + total));
    if (n < 0) {
      if (errno == EINTR) continue;
      return Error{path_ + ": read error at byte " + std::to_string(offset + total) + ": " +
                   std::strerror(errno)};
    }
    if (n == 0) break;
    total += static_cast<size_t>(n);
  }
  return total;
}

}  // namespace dpoint
