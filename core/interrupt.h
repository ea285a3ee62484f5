// Stopping on SIGINT and SIGTERM: within a second, leaving no output, exit 130 or 143 (issue #12).
//
// watchInterrupts(), called first thing in main, blocks both signals in every thread and starts
// one thread that waits for them. On the first signal it records it and forwards it to the child
// processes registered here (bench's dpoint runs). The work polls interrupted() and returns
// interruptedError(): InputFile reads and AtomicFile writes fail, the render and bench loops stop
// between frames and runs, info's nearest-neighbour search and the Poisson elimination between
// points. (parallelFor does not stop by itself: a pass whose items fill indices that the next one
// follows must not be cut short without its caller knowing.) The error unwinds like any
// other, so every AtomicFile's destructor discards its temporary file, and main exits
// 128 + signal. Work that cannot poll (a library decoding, a GPU frame) is cut short:
// kInterruptGraceMs after the signal, or at a second one, the watcher removes the named temporary
// files still registered (O_TMPFILE ones have no name and vanish with the process) and ends the
// process with _exit(128 + signal).
//
// Libraries only poll; nothing here changes behaviour in a process that never calls
// watchInterrupts() (the tests, other programs linking the libraries).
#pragma once

#include <sys/types.h>

#include <atomic>
#include <string>

#include "core/result.h"

namespace dpoint {

// How long the work gets to stop on its own before the watcher ends the process.
constexpr int kInterruptGraceMs = 500;

// A child started with this variable set to its parent's pid gets SIGTERM when the parent dies
// (bench sets it, so a SIGKILLed bench leaves no run behind).
constexpr const char* kParentPidVariable = "DPOINT_PARENT_PID";

namespace detail {
inline std::atomic<int> g_interrupt_signal{0};  // 0, SIGINT or SIGTERM
}  // namespace detail

// True once SIGINT or SIGTERM arrived. Cheap enough for any loop (one relaxed load).
inline bool interrupted() { return detail::g_interrupt_signal.load(std::memory_order_relaxed) != 0; }

// The signal received (SIGINT or SIGTERM), 0 before one.
inline int interruptSignal() { return detail::g_interrupt_signal.load(std::memory_order_relaxed); }

// "interrupted by SIGINT" with ExitCode::kInterrupted (130), or by SIGTERM with kTerminated (143).
Error interruptedError();

// Status form for loops: interruptedError() once interrupted, else ok.
inline Status checkInterrupted() { return interrupted() ? Status(interruptedError()) : okStatus(); }

// Starts the watcher (above). Call once, before any other thread exists: threads inherit the
// blocked signals. Also honours kParentPidVariable.
void watchInterrupts();

// For a front end that keeps its own signal handling (the Python module), instead of
// watchInterrupts(): while a scope lives, SIGINT sets the flag interrupted() reads (the work stops
// as it does in the CLI, leaving no output) in place of the process's own handler; the scope's end
// puts that handler back and clears the flag. Scopes nest: the outermost one acts. No watcher, so
// no forced exit: work that cannot poll (a GPU frame) ends first.
class InterruptScope {
 public:
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;
  // Whether SIGINT came while this scope (or one around it) lived.
  bool caught() const { return interrupted(); }
};

// main calls this with the error it printed, so that a forced exit does not print a second one.
void noteErrorReported();

// Files the watcher deletes before a forced exit; AtomicFile registers its named temporaries.
void registerTemporaryFile(const std::string& path);
void unregisterTemporaryFile(const std::string& path);

// Child processes the watcher forwards the signal to. A caller that registers a child after the
// signal came must signal it itself (check interrupted() after registering).
void registerChildProcess(pid_t pid);
void unregisterChildProcess(pid_t pid);

}  // namespace dpoint
