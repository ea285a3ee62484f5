// The interrupt watcher: a thread in sigwait() instead of a signal handler, so that what it does
// on a signal (forwarding it, waiting out the grace, removing files) is ordinary code.
#include "core/interrupt.h"

#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <set>
#include <thread>

namespace dpoint {
namespace {

std::mutex g_mutex;                  // guards the two sets
std::set<std::string> g_temporaries;
std::set<pid_t> g_children;
std::atomic<bool> g_error_reported{false};

const char* signalName(int signal) { return signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : "a signal"; }

void forwardToChildren(int signal) {
  std::lock_guard<std::mutex> lock(g_mutex);
  for (pid_t child : g_children) ::kill(child, signal);
}

// The work did not stop in time: remove what has a name and end the process now.
[[noreturn]] void forceExit(int signal) {
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    for (const std::string& path : g_temporaries) ::unlink(path.c_str());
  }
  if (!g_error_reported.load()) {
    const std::string line = "dpoint: error: " + interruptedError().message + "\n";
    (void)!::write(STDERR_FILENO, line.data(), line.size());
  }
  ::_exit(128 + signal);
}

void watch(sigset_t signals) {
  int signal = 0;
  while (::sigwait(&signals, &signal) != 0 || (signal != SIGINT && signal != SIGTERM)) {
  }
  detail::g_interrupt_signal.store(signal);
  forwardToChildren(signal);
  // A second signal, or the end of the grace, forces the exit. sigtimedwait is the clock.
  const timespec grace = {kInterruptGraceMs / 1000, (kInterruptGraceMs % 1000) * 1000000L};
  siginfo_t info;
  (void)::sigtimedwait(&signals, &info, &grace);
  forceExit(signal);
}

}  // namespace

Error interruptedError() {
  const int signal = interruptSignal();
  return Error{std::string("interrupted by ") + signalName(signal),
               signal == SIGTERM ? ExitCode::kTerminated : ExitCode::kInterrupted};
}

void watchInterrupts() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::thread(watch, signals).detach();
  if (const char* parent = std::getenv(kParentPidVariable)) {
    // The parent may have died before prctl: then nobody would send the signal.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (std::to_string(::getppid()) != parent) ::kill(::getpid(), SIGTERM);
  }
}

void noteErrorReported() { g_error_reported.store(true); }

void registerTemporaryFile(const std::string& path) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_temporaries.insert(path);
}

void unregisterTemporaryFile(const std::string& path) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_temporaries.erase(path);
}

void registerChildProcess(pid_t pid) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_children.insert(pid);
}

void unregisterChildProcess(pid_t pid) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_children.erase(pid);
}

namespace {
std::mutex g_scope_mutex;
int g_scope_depth = 0;         // guarded by g_scope_mutex
struct sigaction g_saved_sigint;  // the handler an outermost scope replaced

void onScopedSignal(int signal) { detail::g_interrupt_signal.store(signal); }  // lock-free: async-signal-safe
}  // namespace

InterruptScope::InterruptScope() {
  std::lock_guard<std::mutex> lock(g_scope_mutex);
  if (g_scope_depth++ > 0) return;
  detail::g_interrupt_signal.store(0);
  struct sigaction action = {};
  action.sa_handler = onScopedSignal;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, &g_saved_sigint);
}

InterruptScope::~InterruptScope() {
  std::lock_guard<std::mutex> lock(g_scope_mutex);
  if (--g_scope_depth > 0) return;
  ::sigaction(SIGINT, &g_saved_sigint, nullptr);
  detail::g_interrupt_signal.store(0);
}

}  // namespace dpoint
