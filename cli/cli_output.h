// Where the commands write, checked as the options are parsed, before any work (issue #24): a
// long generation or read no longer ends in "cannot write". One list of the formats a point set
// is written as, for every help text and error.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "converters/point_io.h"
#include "core/result.h"

namespace dpoint {

// The formats a point set is written as (.gltf and .laz are read only), as help and errors
// list them.
inline constexpr const char* kPointOutputFormats = ".csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .las, .laz or .e57";
// "Output file (.csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .las, .laz, .e57); written whole or not at all": the -o help of the commands
// that write a point set.
std::string pointOutputHelp();

// -o of a point set: a place it can be written (AtomicFile::checkTarget: a missing folder, a folder
// given as the file, a folder that cannot be written into), then a written format ("PATH: unknown
// file type '.dat' (write .csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .las, .laz or .e57)"). As validators, both are usage errors (exit 1).
Status checkPointOutput(const std::string& path);
// An output folder that is created when missing (bench --out): not a file, and the nearest folder
// that exists can be written into. `flag` names the option in the message.
Status checkOutputFolder(const std::string& flag, const std::string& path);

// An output that is the same file as another path the command reads or writes (`others`: each
// with what it is, "the input", "-o"): a usage error (exit 1) before any work, so that `render
// IN -o p.png --json IN` does not replace its input by the report. Compared as files where both
// exist, else by their absolute, normalised paths.
Status checkNotAlso(const std::string& flag, const std::string& path,
                    const std::vector<std::pair<std::string, std::string>>& others);

// writePoints, then each notice the writer gave ("dpoint: note: …" on stderr).
Status writePointsWithNotes(const std::string& path, const PointSet& points, WriteOptions options);

}  // namespace dpoint
