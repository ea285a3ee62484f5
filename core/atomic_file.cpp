#include "core/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/interrupt.h"
#include "core/memory.h"

namespace dpoint {
namespace {

constexpr size_t kBufferSize = 1 << 20;

// A full disk or quota is a resource limit (exit 4), as --max-memory's refusal is; any other
// failure to write is the output's fault (exit 2).
Error ioError(const std::string& what, const std::string& path, int err) {
  return Error{what + " '" + path + "': " + std::strerror(err),
               err == ENOSPC || err == EDQUOT ? ExitCode::kResourceLimit : ExitCode::kBadInput};
}

std::string folderOf(const std::string& path) {
  std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

// The longest file name a folder takes (NAME_MAX, 255 on Linux's file systems).
size_t longestName(const std::string& folder) {
  const long most = ::pathconf(folder.c_str(), _PC_NAME_MAX);
  return most > 0 ? static_cast<size_t>(most) : 255;
}

// A name longer than the folder takes: a usage error, before any work.
Status checkName(const std::string& path, const std::string& folder) {
  const size_t name = std::filesystem::path(path).filename().string().size(), most = longestName(folder);
  if (name <= most) return okStatus();
  return Error{path + ": the file name is " + std::to_string(name) + " bytes long, more than the " + std::to_string(most) +
                   " its folder takes", ExitCode::kUsage};
}

// A temporary's name beside `path`: its name with `suffix`, or where that would be longer than the
// folder takes (a name of 243-255 bytes), ".dpoint" with the suffix alone.
std::string tempBeside(const std::string& path, const std::string& suffix) {
  const std::filesystem::path p(path);
  const std::string name = p.filename().string();
  if (name.size() + suffix.size() <= longestName(folderOf(path))) return path + suffix;
  return (p.parent_path() / (".dpoint" + suffix)).string();
}

}  // namespace

AtomicFile::AtomicFile(std::string path, std::string temp_path, int fd, bool direct)
    : path_(std::move(path)), temp_path_(std::move(temp_path)), fd_(fd), direct_(direct) {
  buffer_.reserve(kBufferSize);
}

AtomicFile::AtomicFile(AtomicFile&& other) noexcept
    : path_(std::move(other.path_)),
      temp_path_(std::move(other.temp_path_)),
      fd_(other.fd_),
      direct_(other.direct_),
      committed_(other.committed_),
      written_(other.written_),
      buffer_(std::move(other.buffer_)) {
  other.fd_ = -1;
  other.temp_path_.clear();
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && !temp_path_.empty()) {
    ::unlink(temp_path_.c_str());
    unregisterTemporaryFile(temp_path_);
  }
}

namespace {

// The target's folder exists and is a folder (create's first checks on a regular or new target).
Status checkFolder(const std::string& path, const std::string& folder) {
  struct stat folder_st {};
  if (::stat(folder.c_str(), &folder_st) != 0)
    return Error{"cannot write '" + path + "': folder '" + folder + "' does not exist"};
  if (!S_ISDIR(folder_st.st_mode))
    return Error{"cannot write '" + path + "': '" + folder + "' is not a folder"};
  return okStatus();
}

// A path the process's own descriptors stand behind (/dev/stdout, /dev/fd/N, /proc/self/fd/N):
// written where it leads, never replaced by a rename (which, for a redirect to a regular file,
// had put a file in place of the /dev/stdout link and left the redirect empty).
bool isDescriptorPath(const std::string& path) { return path.rfind("/dev/", 0) == 0 || path.rfind("/proc/", 0) == 0; }

// Where a symbolic link leads, link after link (at most 40), stopping at a descriptor path: the
// output is written there and the link stays (a rename had put a file in place of the link).
std::string followLinks(const std::string& path) {
  namespace fs = std::filesystem;
  fs::path p(path);
  for (int hops = 0; hops < 40 && !isDescriptorPath(p.string()); ++hops) {
    std::error_code ec;
    if (!fs::is_symlink(p, ec) || ec) break;
    const fs::path to = fs::read_symlink(p, ec);
    if (ec) break;
    p = to.is_absolute() ? to : p.parent_path() / to;
  }
  return p.string();
}

// A path that exists already: a folder is refused; a device or a pipe (not a regular file), or a
// descriptor path, is opened for writing as it is (special_fd; -1 when the path is absent or a
// regular file, which is replaced by rename). With `probed` (checkTarget) nothing is opened: it
// says whether the path is such a target, and only the right to write it is checked (opening a
// named pipe and closing it would end its reader, and the real open would then wait for ever).
Status openIfSpecial(const std::string& path, int& special_fd, bool* probed = nullptr) {
  special_fd = -1;
  if (probed) *probed = false;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || (S_ISREG(st.st_mode) && !isDescriptorPath(path))) return okStatus();
  if (S_ISDIR(st.st_mode)) return Error{"cannot write '" + path + "': it is a folder"};
  if (probed) {
    if (::access(path.c_str(), W_OK) != 0) return ioError("cannot open", path, errno);
    *probed = true;
    return okStatus();
  }
  special_fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC | (S_ISREG(st.st_mode) ? O_TRUNC : 0));
  if (special_fd < 0) return ioError("cannot open", path, errno);
  return okStatus();
}

// The temporary a regular target is written to, in its folder (which must exist, be a folder and
// take the target's name): unnamed (O_TMPFILE), or, on a file system without that, named beside
// the target (`named`, else left empty).
Result<int> openTemporary(const std::string& path, std::string& named) {
  const std::string folder = folderOf(path);
  if (Status s = checkFolder(path, folder); !s) return s.error();
  if (Status s = checkName(path, folder); !s) return s.error();
  int fd = ::open(folder.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0666);
  if (fd >= 0) return fd;
  if (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL)
    return ioError("cannot write into folder", folder, errno);
  named = tempBeside(path, ".dpoint-XXXXXX");
  fd = ::mkstemp(named.data());
  if (fd < 0) return ioError("cannot create a temporary file beside", path, errno);
  return fd;
}

}  // namespace

Status AtomicFile::checkTarget(const std::string& given) {
  if (given.empty()) return Error{"output path is empty", ExitCode::kUsage};
  const std::string path = followLinks(given);
  int special = -1;
  bool probed = false;
  if (Status s = openIfSpecial(path, special, &probed); !s) return s;
  if (probed) return okStatus();
  std::string named;
  Result<int> fd = openTemporary(path, named);
  if (!fd) return fd.error();
  ::close(*fd);
  if (!named.empty()) ::unlink(named.c_str());
  return okStatus();
}

Result<AtomicFile> AtomicFile::create(const std::string& given) {
  if (given.empty()) return Error{"output path is empty", ExitCode::kUsage};
  const std::string path = followLinks(given);
  if (interrupted()) return interruptedError();
  int special = -1;
  if (Status s = openIfSpecial(path, special); !s) return s.error();
  if (special >= 0) return AtomicFile(path, "", special, true);
  std::string named;
  Result<int> fd = openTemporary(path, named);
  if (!fd) return fd.error();
  if (!named.empty()) {
    registerTemporaryFile(named);  // removed by the interrupt watcher if it must end the process
    ::fchmod(*fd, 0644);
  }
  return AtomicFile(path, named, *fd, false);
}

// Every byte out, at the file's position (write) or from `offset` on (pwrite, offset ≥ 0), again
// after a signal and after a short write.
Status AtomicFile::writeFully(const char* data, size_t size, int64_t offset) {
  while (size > 0) {
    const ssize_t n = offset < 0 ? ::write(fd_, data, size) : ::pwrite(fd_, data, size, static_cast<off_t>(offset));
    if (n < 0) {
      if (errno == EINTR) continue;
      return ioError("cannot write", path_, errno);
    }
    data += n;
    size -= static_cast<size_t>(n);
    if (offset >= 0) offset += n;
  }
  return okStatus();
}

Status AtomicFile::writeAll(const char* data, size_t size) {
  Status s = writeFully(data, size, -1);
  if (s) written_ += size;
  return s;
}

Status AtomicFile::flush() {
  Status s = writeAll(buffer_.data(), buffer_.size());
  buffer_.clear();
  return s;
}

Status AtomicFile::write(const void* data, size_t size) {
  assert(fd_ >= 0 && !committed_);
  // Every writer comes through here: an interrupted run stops writing and its output is discarded.
  if (interrupted()) return interruptedError();
  if (buffer_.size() + size > kBufferSize) {
    if (Status s = flush(); !s) return s;
  }
  if (size >= kBufferSize) return writeAll(static_cast<const char*>(data), size);  // no copy
  buffer_.insert(buffer_.end(), static_cast<const char*>(data), static_cast<const char*>(data) + size);
  return okStatus();
}

Status AtomicFile::writeAt(uint64_t offset, const void* data, size_t size) {
  assert(fd_ >= 0 && !committed_ && !direct_ && buffer_.empty() && offset <= uint64_t{INT64_MAX});
  if (interrupted()) return interruptedError();
  return writeFully(static_cast<const char*>(data), size, static_cast<int64_t>(offset));
}

Status AtomicFile::readAt(uint64_t offset, void* data, size_t size) {
  assert(fd_ >= 0 && !committed_ && !direct_);
  if (interrupted()) return interruptedError();
  char* bytes = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t n = ::pread(fd_, bytes, size, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n == 0 ? Error{"cannot read back '" + path_ + "': it is shorter than written"}
                              : ioError("cannot read back", path_, errno);
    bytes += n;
    size -= static_cast<size_t>(n);
    offset += static_cast<uint64_t>(n);
  }
  return okStatus();
}

Status AtomicFile::checkSpace(uint64_t bytes) const {
  assert(fd_ >= 0 && !committed_);
  struct statvfs fs;
  // A file system that reports no size (some FUSE and network ones) cannot say what is free.
  if (direct_ || ::fstatvfs(fd_, &fs) != 0 || fs.f_frsize == 0 || fs.f_blocks == 0) return okStatus();
  const uint64_t blocks = ::geteuid() == 0 ? fs.f_bfree : fs.f_bavail;
  const uint64_t taken = bytesWritten();
  const uint64_t free = blocks > UINT64_MAX / fs.f_frsize ? UINT64_MAX : blocks * fs.f_frsize;
  if (bytes <= taken || bytes - taken <= free) return okStatus();
  return Error{"cannot write '" + path_ + "': it takes at least " + formatBytes(bytes) +
                   ", and the file system holding '" + folderOf(path_) + "' has " + formatBytes(free) + " free",
               ExitCode::kResourceLimit};
}

Status AtomicFile::resize(uint64_t size) {
  assert(fd_ >= 0 && !committed_ && !direct_ && buffer_.empty());
  if (::ftruncate(fd_, static_cast<off_t>(size)) != 0) return ioError("cannot write", path_, errno);
  return okStatus();
}

Status AtomicFile::commit() {
  assert(fd_ >= 0 && !committed_);
  if (interrupted()) return interruptedError();
  if (Status s = flush(); !s) return s;
  if (direct_) {
    ::close(fd_);
    fd_ = -1;
    committed_ = true;
    return okStatus();
  }
  std::string named = temp_path_;
  if (named.empty()) {
    // Give the unnamed file a temporary name, then rename it over the target (rename is atomic;
    // linkat alone would fail on an existing target).
    // Unique in the process too: two outputs with long names share the folder's short form.
    static std::atomic<uint64_t> commits{0};
    named = tempBeside(path_, ".dpoint-" + std::to_string(::getpid()) + "-" + std::to_string(commits++));
    ::unlink(named.c_str());
    registerTemporaryFile(named);
    const std::string proc = "/proc/self/fd/" + std::to_string(fd_);
    if (::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, named.c_str(), AT_SYMLINK_FOLLOW) != 0) {
      unregisterTemporaryFile(named);
      return ioError("cannot create", named, errno);
    }
    temp_path_ = named;
  }
  if (::close(fd_) != 0) {
    fd_ = -1;
    return ioError("cannot write", path_, errno);
  }
  fd_ = -1;
  if (::rename(named.c_str(), path_.c_str()) != 0) return ioError("cannot rename into", path_, errno);
  committed_ = true;
  unregisterTemporaryFile(named);
  temp_path_.clear();
  return okStatus();
}

}  // namespace dpoint
