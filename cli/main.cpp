// dpoint: one executable, one subcommand per job. The run itself is cli/cli_run.h, which the
// Python module calls too; main only starts the interrupt watcher first.
#include <sys/resource.h>

#include "cli/cli_run.h"
#include "core/interrupt.h"

int main(int argc, char** argv) {
  dpoint::watchInterrupts();  // before any thread starts (core/interrupt.h)
  // A tile set is read with every tile open at once (merge, render, info: up to 1,048,576 files);
  // the soft limit on open files (1024 on many systems) goes up to the hard one, which a user may.
  if (struct rlimit limit {}; ::getrlimit(RLIMIT_NOFILE, &limit) == 0 && limit.rlim_cur < limit.rlim_max) {
    limit.rlim_cur = limit.rlim_max;
    ::setrlimit(RLIMIT_NOFILE, &limit);
  }
  return dpoint::runDpoint(argc, argv);
}
