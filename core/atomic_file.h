// Output that appears whole or not at all (DESIGN §10).
//
// The data goes to an unnamed temporary file (O_TMPFILE) in the target's folder; commit() gives it
// a name beside the target and renames it over the target. A failed run (destructor without
// commit) or a killed one (SIGKILL: the kernel frees the unnamed inode) leaves nothing behind.
// Where the file system lacks O_TMPFILE, a named temporary beside the target is used and removed
// on failure. Targets that are not regular files (/dev/null, a pipe) are written directly.
// SIGINT/SIGTERM (core/interrupt.h): create, write and commit fail once interrupted, and named
// temporaries are registered so that a forced exit removes them too. SIGKILL can leave a named
// temporary (PATH.dpoint-XXXXXX without O_TMPFILE, or PATH.dpoint-PID in the instant between
// commit's link and rename), never a file at PATH.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/result.h"

namespace dpoint {

class AtomicFile {
 public:
  // Opens the temporary file. Fails (with a message naming the path) when the folder does not
  // exist, is not writable, or the target is a folder.
  static Result<AtomicFile> create(const std::string& path);
  // What create checks, without leaving anything behind: the same errors (and exit codes) create
  // would give for `path`, found before any work. The folder's writability is tried the way create
  // writes (an unnamed temporary, or a named one removed at once), so a read-only file system or a
  // folder root cannot write into fails here as it would there.
  static Status checkTarget(const std::string& path);

  AtomicFile(AtomicFile&& other) noexcept;
  AtomicFile& operator=(AtomicFile&&) = delete;
  AtomicFile(const AtomicFile&) = delete;
  ~AtomicFile();  // discards the output unless commit() succeeded

  // Fails (exit 4, a resource limit, the message naming the path, both sizes and the folder) when
  // the file system holding the output has fewer than `bytes` free for this process (root may use
  // the blocks kept for it): called by a writer that knows its file's size, or a lower bound of it,
  // before it makes or writes anything, so that a file too large for the disk is refused at once
  // and does not first fill the disk. The bytes already written count as taken; a pipe or device
  // passes. A file system that cannot say (no size) passes too; one that compresses may be refused a
  // file that would have fitted.
  Status checkSpace(uint64_t bytes) const;
  // The least a value takes in a text format (a digit and a separator): a text writer checks
  // `values × kLeastTextBytesPerValue` plus its header, a lower bound of its file's size.
  static constexpr uint64_t kLeastTextBytesPerValue = 2;

  // Buffered append. Errors (disk full) are reported here or at commit.
  Status write(const void* data, size_t size);
  Status write(std::string_view text) { return write(text.data(), text.size()); }
  // Positional writes and reads, where the output is a file (positional(): not a pipe or a device)
  // and nothing is buffered: a file laid out before its sizes are known (converters/ply.h
  // PlyRowStream). writeAt may be called from one thread while another reads or writes elsewhere.
  bool positional() const { return !direct_; }
  Status writeAt(uint64_t offset, const void* data, size_t size);
  Status readAt(uint64_t offset, void* data, size_t size);
  Status resize(uint64_t size);  // the file's length, cut or extended with zeros
  // Flushes, syncs nothing (page cache is enough for atomicity against crashes of the process),
  // and moves the file into place.
  Status commit();

  const std::string& path() const { return path_; }
  uint64_t bytesWritten() const { return written_ + buffer_.size(); }

 private:
  AtomicFile(std::string path, std::string temp_path, int fd, bool direct);
  Status flush();
  Status writeFully(const char* data, size_t size, int64_t offset);
  Status writeAll(const char* data, size_t size);

  std::string path_;
  std::string temp_path_;  // non-empty only for the named fallback
  int fd_ = -1;
  bool direct_ = false;    // target is not a regular file: no temporary
  bool committed_ = false;
  uint64_t written_ = 0;
  std::vector<char> buffer_;
};

}  // namespace dpoint
