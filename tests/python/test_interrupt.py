"""Ctrl-C and the GIL: a long call stops on SIGINT with KeyboardInterrupt and no output, gives
Python its own SIGINT handling back, and lets other Python threads run while it works."""
import os
import queue
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import dpoint

# A child Python that says "started", runs CALL (long: many seconds uninterrupted), and reports on
# stdout how it ended; then checks that a second SIGINT is Python's own KeyboardInterrupt.
CHILD = textwrap.dedent("""
    import signal, sys, time
    import numpy as np
    import dpoint
    out = sys.argv[1]
    handler = signal.getsignal(signal.SIGINT)
    print("started", flush=True)
    try:
        {call}
        print("finished", flush=True)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
    print("handler " + ("restored" if signal.getsignal(signal.SIGINT) is handler else "changed"), flush=True)
    try:
        time.sleep(30)
        print("slept", flush=True)
    except KeyboardInterrupt:
        print("second interrupt", flush=True)
""")

# Calls that run for a minute or more uninterrupted on the 2-core VM, many times the wait for their
# end below: one that ran on past Ctrl-C does not end inside it.
LONG_CALLS = {
    "generate": 'dpoint.write(dpoint.generate("mandelbulb", resolution=1000, device="none"), out)',
    "render": ('dpoint.render(dpoint.PointSet(np.random.default_rng(0).random((2000, 3))), width=64, height=64, '
               'frames=1000000, warmup=0).save(out)'),
    # A Poisson sample of 2M points (about a minute on 2 cores): its grid's sort and its candidates'
    # placement did not stop (a SIGINT a second in took 6 s) before the build of 2026-12-01.
    "sample": 'dpoint.write(dpoint.sample(dpoint.generate("sierpinski", level=6), 2_000_000, method="poisson"), out)',
    # The nearest-neighbour search of every one of 5M points on one core (minutes): it ran to its end
    # before the build of 2026-11-30, and its k-d trees' build ran on (4 s) before that of 2026-12-02.
    "info": ('r = dpoint.info(dpoint.PointSet(np.random.default_rng(0).random((5_000_000, 3))), sample=100_000_000, '
             'threads=1); open(out, "w").write(str(r))'),
}

# How long a call may take to end after Ctrl-C. It tells "stopped" from "ran on" (each call above
# runs far longer), with room for a loaded machine; it is a guard against a hang, not a timing.
STOP_WAIT_S = 10.0


def stderr_of(child):
    """A failing child's stderr, for the assertion's message: ended first, as reading a running
    child's stderr waits for its end."""
    child.kill()
    return child.stderr.read()


class Lines:
    """The child's stdout a line at a time, each waited for at most `timeout` seconds (None: none
    came). A thread reads, so a child that never writes cannot hang the test."""

    def __init__(self, stream):
        self.lines = queue.Queue()
        threading.Thread(target=self._read, args=(stream,), daemon=True).start()

    def _read(self, stream):
        for line in stream:
            self.lines.put(line.strip())
        self.lines.put("")

    def next(self, timeout=STOP_WAIT_S):
        try:
            return self.lines.get(timeout=timeout)
        except queue.Empty:
            return None


@pytest.mark.parametrize("name", sorted(LONG_CALLS))
def test_ctrl_c_stops_a_long_call_leaving_no_output(tmp_path, name):
    out = tmp_path / "out.ply"
    if name == "render":
        out = tmp_path / "out.png"
    child = subprocess.Popen([sys.executable, "-c", CHILD.format(call=LONG_CALLS[name]), str(out)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=os.environ)
    lines = Lines(child.stdout)
    try:
        assert lines.next(timeout=60) == "started", stderr_of(child)
        time.sleep(1.0)  # well inside the call
        assert child.poll() is None, child.stderr.read()
        child.send_signal(signal.SIGINT)
        ended = lines.next()
        assert ended is not None, f"no end {STOP_WAIT_S:.0f} s after SIGINT: the call ran on"
        assert ended == "interrupted", stderr_of(child)
        assert lines.next() == "handler restored"
        assert not out.exists()
        assert os.listdir(tmp_path) == []  # no temporary file left either
        time.sleep(0.2)  # the child is in time.sleep now
        child.send_signal(signal.SIGINT)
        assert lines.next() == "second interrupt"
        assert child.wait(timeout=10) == 0
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def start_child(code, *args):
    """A child Python running `code`; returns it once it printed "started"."""
    child = subprocess.Popen([sys.executable, "-c", textwrap.dedent(code), *map(str, args)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=os.environ)
    assert child.stdout.readline().strip() == "started", child.stderr.read()
    return child


def test_the_programs_own_handler_hears_ctrl_c(tmp_path):
    """A SIGINT handler the program installed runs (here: SystemExit 7), not a KeyboardInterrupt of ours."""
    child = start_child("""
        import signal, sys
        import dpoint
        def leave(signum, frame):
            print("handler", flush=True)
            sys.exit(7)
        signal.signal(signal.SIGINT, leave)
        print("started", flush=True)
        dpoint.write(dpoint.generate("mandelbulb", resolution=1000, device="none"), sys.argv[1])
        print("finished", flush=True)
    """, tmp_path / "out.ply")
    try:
        time.sleep(0.5)
        child.send_signal(signal.SIGINT)
        assert child.wait(timeout=STOP_WAIT_S) == 7, stderr_of(child)  # a minute and more uninterrupted
        assert child.stdout.read().strip() == "handler"
        assert os.listdir(tmp_path) == []
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def test_an_ignored_sigint_stays_ignored(tmp_path):
    """A process that ignores SIGINT (SIG_IGN: a script's background job) finishes its work."""
    child = start_child("""
        import signal, sys
        import dpoint
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        print("started", flush=True)
        dpoint.write(dpoint.generate("mandelbulb", resolution=140, device="none"), sys.argv[1])
        print("finished", flush=True)
    """, tmp_path / "out.ply")
    try:
        time.sleep(0.2)
        child.send_signal(signal.SIGINT)
        assert child.wait(timeout=60) == 0, child.stderr.read()
        assert child.stdout.read().strip() == "finished"
        assert (tmp_path / "out.ply").exists()
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def count_while(call, rounds_wanted=0.2):
    """Runs `call` in this (the main) thread while another Python thread counts; returns the count the
    other thread reached during the call, the count a free-running thread reaches in the same time,
    and the call's duration."""
    count = 0
    stop = threading.Event()

    def counter():
        nonlocal count
        while not stop.is_set():
            count += 1

    thread = threading.Thread(target=counter)
    thread.start()
    try:
        time.sleep(0.1)
        start, free_start = count, time.monotonic()
        time.sleep(rounds_wanted)  # the rate when this thread holds nothing
        free_rate = (count - start) / (time.monotonic() - free_start)
        before, began = count, time.monotonic()
        call()
        took = time.monotonic() - began
        during = count - before
    finally:
        stop.set()
        thread.join()
    return during, free_rate * took, took


@pytest.mark.parametrize("name", ["generate", "render"])
def test_other_threads_run_while_a_call_works(name):
    """With the GIL held through a call, the counter would stall for all of it (at most a few 5 ms
    switch intervals of counting); released, it counts for most of it."""
    points = dpoint.PointSet(np.random.default_rng(0).random((300_000, 3)))
    calls = {
        "generate": lambda: dpoint.generate("mandelbulb", resolution=110, device="none", threads=1),
        "render": lambda: dpoint.render(points, width=128, height=128, frames=8, warmup=0, threads=1),
    }
    during, free, took = count_while(calls[name])
    assert took > 0.15, f"the call took {took:.3f} s: too short to tell"
    print(f"{name}: counted {during} during the {took:.2f} s call, {free:.0f} when free")
    assert during > 0.25 * free, f"counted {during} during the {took:.2f} s call, {free:.0f} when free"


def test_a_call_from_another_thread_works_and_raises_there(tmp_path):
    results = {}

    def work():
        results["set"] = dpoint.generate("random2d", count=100)
        try:
            dpoint.read(tmp_path / "missing.ply")
        except dpoint.Error as e:
            results["error"] = str(e)

    thread = threading.Thread(target=work)
    thread.start()
    thread.join()
    assert len(results["set"]) == 100
    assert results["error"].endswith("missing.ply: file not found")
