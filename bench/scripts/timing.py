"""Whole-process timing for the benchmarks: wall time and peak RSS of a child, median of runs."""
import os
import statistics
import subprocess
import sys
import tempfile
import time


def timed(argv, before=None):
    """Wall seconds, peak RSS (bytes) and stdout of one run. `before` runs first, untimed.

    Peak RSS comes from /usr/bin/time, not from wait4 here: Linux carries the high-water RSS of
    the memory image a process had before exec into its ru_maxrss, and a child forked from this
    Python process would report Python's own size."""
    if before:
        before()
    with tempfile.NamedTemporaryFile(mode="r") as rss_file:
        t0 = time.perf_counter()
        proc = subprocess.run(["/usr/bin/time", "-f", "%M", "-o", rss_file.name, *argv], capture_output=True)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            sys.exit(f"{' '.join(argv)} failed: {proc.stderr.decode()}")
        peak_kib = int(rss_file.read().split()[-1])
    return wall, peak_kib * 1024, proc.stdout.decode()


def median_of(argv, runs, before=None):
    """Median wall seconds, largest peak RSS and the last stdout over `runs` runs."""
    results = [timed(argv, before) for _ in range(runs)]
    return statistics.median(r[0] for r in results), max(r[1] for r in results), results[-1][2]


def remover(path):
    """Deletes `path` before a run, so every run writes a new file (overwriting a large file
    costs the kernel time to drop the old one, which is not the writer's work)."""
    return lambda: os.path.exists(path) and os.remove(path)
