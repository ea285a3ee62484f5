#include "core/ordered_write.h"

#include <condition_variable>
#include <exception>
#include <new>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>

#include "core/parallel.h"

namespace dpoint {
namespace {

// make(k, bytes), an exception (out of memory on a worker, where nothing would catch it) turned into
// the error the CLI gives for one on its own thread.
Status makeCaught(const std::function<Status(size_t, std::vector<char>&)>& make, size_t k, std::vector<char>& bytes) {
  try {
    return make(k, bytes);
  } catch (const std::bad_alloc&) {
    return Error{"out of memory", ExitCode::kResourceLimit};
  } catch (const std::exception& e) {
    return Error{std::string("internal error: ") + e.what(), ExitCode::kBadInput};
  }
}

}  // namespace

Status writeChunksInOrder(AtomicFile& file, size_t chunks, unsigned threads,
                          const std::function<Status(size_t chunk, std::vector<char>& bytes)>& make,
                          const std::function<void(size_t chunk)>& written) {
  threads = resolveThreads(threads);
  auto one_thread = [&]() -> Status {
    std::vector<char> bytes;
    for (size_t k = 0; k < chunks; ++k) {
      if (Status s = make(k, bytes); !s) return s;
      if (Status s = file.write(bytes.data(), bytes.size()); !s) return s;
      if (written) written(k);
    }
    return okStatus();
  };
  if (threads <= 1 || chunks <= 1) return one_thread();
  // Chunk k lives in slot k % window from when a worker takes it until it has been written.
  const size_t window = 2 * size_t{threads};
  struct Slot {
    std::vector<char> bytes;
    bool ready = false;
    Status status = okStatus();
  };
  std::vector<Slot> slots(window);
  std::mutex mutex;
  std::condition_variable changed;
  size_t next = 0;          // the next chunk a worker takes
  size_t done_writing = 0;  // chunks [0, done_writing) are written; their slots are free
  bool stop = false;

  auto work = [&] {
    for (;;) {
      size_t k;
      {
        std::unique_lock lock(mutex);
        changed.wait(lock, [&] { return stop || next >= chunks || next < done_writing + window; });
        if (stop || next >= chunks) return;
        k = next++;
      }
      Slot& slot = slots[k % window];
      Status s = makeCaught(make, k, slot.bytes);
      {
        std::lock_guard lock(mutex);
        slot.status = std::move(s);
        slot.ready = true;
      }
      changed.notify_all();
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(threads);
  // A thread the system will not make (a process or address-space limit, --threads 30000): the
  // chunks go to the workers made, or, with none, are made on this thread.
  try {
    for (unsigned t = 0; t < threads; ++t) pool.emplace_back(work);
  } catch (const std::system_error&) {
  }
  if (pool.empty()) return one_thread();

  Status result = okStatus();
  for (size_t k = 0; k < chunks; ++k) {
    Slot& slot = slots[k % window];
    {
      std::unique_lock lock(mutex);
      changed.wait(lock, [&] { return slot.ready; });
    }
    if (!slot.status) {
      result = slot.status;
    } else if (Status s = file.write(slot.bytes.data(), slot.bytes.size()); !s) {
      result = s;
    }
    if (!result) break;
    if (written) written(k);
    {
      std::lock_guard lock(mutex);
      slot.ready = false;
      done_writing = k + 1;
    }
    changed.notify_all();
  }
  {
    std::lock_guard lock(mutex);
    stop = true;
  }
  changed.notify_all();
  for (std::thread& t : pool) t.join();
  return result;
}

}  // namespace dpoint
