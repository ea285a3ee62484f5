// Output made in parallel and written in order: the file's chunks are formatted on all cores while
// the calling thread writes the ones before them, so a writer runs at the speed of its slowest
// stage (formatting on N cores, or the one write() stream) instead of their sum.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "core/atomic_file.h"
#include "core/result.h"

namespace dpoint {

// Makes chunk k (0 ≤ k < chunks) with make(k, bytes) on one of `threads` workers (0: all cores) and
// appends the chunks to `file` in order, k = 0, 1, ..., calling written(k) (if set) after each on
// the calling thread. `bytes` holds whatever an earlier chunk left in it (its capacity is reused):
// make sets its size. At most 2·threads chunks are held at once. The first failing chunk (by index)
// or write ends the work and is returned; the file is then not committed by the caller and nothing
// appears. The bytes written do not depend on the thread count.
Status writeChunksInOrder(AtomicFile& file, size_t chunks, unsigned threads,
                          const std::function<Status(size_t chunk, std::vector<char>& bytes)>& make,
                          const std::function<void(size_t chunk)>& written = {});

}  // namespace dpoint
