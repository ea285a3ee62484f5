// Several input files read as one point set (`dpoint render` and `dpoint info` with several
// inputs, e.g. the tiles of `dpoint generate --tile`).
#pragma once

#include <string>
#include <vector>

#include "converters/point_io.h"
#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

// The files one after another, as one set: points concatenated in the order given, triangles
// offset to their file's first point. Tiles of one run, all N of them (core/tile.h), are welded as
// `dpoint merge` welds them, so the set is the whole one, each seam vertex once; any other mix of
// files is read file by file (a tile then brings its copies of seam vertices too). Colours: kept
// when every file with points has them, none when none has; in a mix, the files without get white,
// the colour the renderer gives a set without colours. One path is readPoints(path). Errors are
// the files' own, naming the file.
Result<PointSet> readPointInputs(const std::vector<std::string>& paths, const ReadOptions& options = {});

// "a.ply" for one path, "a.ply and 3 more" for several: for messages and reports.
std::string describeInputs(const std::vector<std::string>& paths);

}  // namespace dpoint
