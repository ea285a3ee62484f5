// dpoint: one executable, one subcommand per job. The run itself is cli/cli_run.h, which the
// Python module calls too; main only starts the interrupt watcher first.
#include "cli/cli_run.h"
#include "core/interrupt.h"

int main(int argc, char** argv) {
  dpoint::watchInterrupts();  // before any thread starts (core/interrupt.h)
  return dpoint::runDpoint(argc, argv);
}
