"""Whole-process timing for the benchmarks: wall time and peak RSS of a child, median of runs."""
import os
import statistics
import subprocess
import sys
import time


def timed(argv, before=None):
    """Wall seconds, peak RSS (bytes) and stdout of one run. `before` runs first, untimed."""
    if before:
        before()
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    stdout, stderr = proc.stdout.read(), proc.stderr.read()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{' '.join(argv)} failed: {stderr.decode()}")
    return wall, usage.ru_maxrss * 1024, stdout.decode()


def median_of(argv, runs, before=None):
    """Median wall seconds, largest peak RSS and the last stdout over `runs` runs."""
    results = [timed(argv, before) for _ in range(runs)]
    return statistics.median(r[0] for r in results), max(r[1] for r in results), results[-1][2]


def remover(path):
    """Deletes `path` before a run, so every run writes a new file (overwriting a large file
    costs the kernel time to drop the old one, which is not the writer's work)."""
    return lambda: os.path.exists(path) and os.remove(path)
