#include "cli/cli_output.h"

#include <sys/stat.h>

#include <cstdio>
#include <filesystem>
#include <vector>

#include "converters/point_io.h"
#include "core/atomic_file.h"

namespace dpoint {

std::string pointOutputHelp() { return "Output file (.csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .las, .laz, .e57); written whole or not at all"; }

Status checkPointOutput(const std::string& path) {
  if (Status s = AtomicFile::checkTarget(path); !s) return s;  // first: a folder is no file of any type
  Result<FileFormat> format = formatOf(path);
  if (!format) {
    const std::string ext = std::filesystem::path(path).extension().string();
    return Error{path + ": unknown file type '" + ext + "' (write " + kPointOutputFormats + ")", ExitCode::kUsage};
  }
  return checkWrittenFormat(path, *format);
}

Status checkOutputFolder(const std::string& flag, const std::string& path) {
  std::filesystem::path at = path.empty() ? std::filesystem::path(".") : std::filesystem::path(path);
  struct stat st {};
  if (::stat(at.c_str(), &st) == 0 && !S_ISDIR(st.st_mode))
    return Error{flag + " " + path + ": is a file, not a folder", ExitCode::kUsage};
  // The nearest folder that exists is where the first folder will be made (or the files written).
  while (::stat(at.c_str(), &st) != 0 && at.has_parent_path() && at.parent_path() != at) at = at.parent_path();
  if (::stat(at.c_str(), &st) != 0) at = ".";
  if (Status s = AtomicFile::checkTarget((at / "dpoint-check").string()); !s)
    return Error{flag + " " + path + ": " + s.error().message, s.error().code};
  return okStatus();
}

Status checkNotAlso(const std::string& flag, const std::string& path,
                    const std::vector<std::pair<std::string, std::string>>& others) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path mine = fs::weakly_canonical(fs::absolute(path, ec), ec);
  for (const auto& [what, other] : others) {
    std::error_code e1, e2;
    const bool same = fs::exists(path, e1) && fs::exists(other, e2) ? fs::equivalent(path, other, e1)
                                                                    : mine == fs::weakly_canonical(fs::absolute(other, e2), e2);
    if (same && !e1) return Error{flag + " " + path + ": is also " + what + " (" + other + ")", ExitCode::kUsage};
  }
  return okStatus();
}

Status writePointsWithNotes(const std::string& path, const PointSet& points, WriteOptions options) {
  std::vector<std::string> notices;
  options.notices = &notices;
  if (Status s = writePoints(path, points, options); !s) return s;
  for (const std::string& notice : notices) std::fprintf(stderr, "dpoint: note: %s\n", notice.c_str());
  return okStatus();
}

}  // namespace dpoint
