"""What the tests of the Python module (issue #26) share: the built `dpoint` executable the module
is checked against, a way to run it, and small sets.

Run through CTest (tests/CMakeLists.txt: python.pytest), which puts build/python on PYTHONPATH and
names the executable in DPOINT_EXECUTABLE. By hand, from the repository root:
    PYTHONPATH=build/python DPOINT_EXECUTABLE=build/dpoint /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python
"""
import json
import re
import os
import subprocess

import numpy as np
import pytest

import dpoint

# The executable: CTest's, else the one built beside the package (build/python/dpoint/../../dpoint).
EXECUTABLE = os.environ.get("DPOINT_EXECUTABLE") or os.path.join(
    os.path.dirname(os.path.abspath(dpoint.__file__)), "..", "..", "dpoint")
assert os.access(EXECUTABLE, os.X_OK), f"no dpoint executable at {EXECUTABLE} (set DPOINT_EXECUTABLE)"

# Every kind of `dpoint generate`, with options that keep each set small (milliseconds).
SMALL_GENERATE = {
    "mandelbulb": dict(resolution=24, device="none"),
    "julia": dict(resolution=24, device="none"),
    "menger": dict(level=2),
    "sierpinski": dict(level=3),
    "random2d": dict(count=500, seed=3),
    "mandelbrot2d": dict(resolution=48, center=(-0.75, 0.1), width=1e-3, device="none"),
}


def cli(*args, check=True):
    """Runs `dpoint ARGS`; the CompletedProcess (text)."""
    done = subprocess.run([EXECUTABLE, *map(str, args)], capture_output=True, text=True)
    # No run may die by a signal (an abort, a crash), whatever the caller expects of it.
    assert done.returncode >= 0, f"dpoint {' '.join(map(str, args))} died by signal {-done.returncode}: {done.stderr}"
    if check and done.returncode != 0:
        raise AssertionError(f"dpoint {' '.join(map(str, args))} exited {done.returncode}: {done.stderr}")
    return done


def cli_error(*args):
    """The message `dpoint ARGS` fails with (its "dpoint: error: " line, without the prefix), and its exit code."""
    done = cli(*args, check=False)
    assert done.returncode != 0, f"dpoint {' '.join(map(str, args))} succeeded"
    lines = [line for line in done.stderr.splitlines() if line.startswith("dpoint: error: ")]
    message = lines[0][len("dpoint: error: "):] if lines else done.stderr.splitlines()[0]
    return message, done.returncode


def as_keywords(message):
    """A CLI message as the module raises it: each flag but --help named as its keyword
    (--view-width as view_width)."""
    return re.sub(r"--(?!help\b)([a-z][a-z0-9-]*)", lambda m: m.group(1).replace("-", "_"), message)


def cli_json(*args):
    return json.loads(cli(*args).stdout)


def options_as_flags(options):
    """Keyword options as the CLI's flags, as the module turns them (view_width=0.5: --view-width 0.5)."""
    flags = []
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is True:
            flags.append(flag)
        elif isinstance(value, (tuple, list)):
            flags += [flag, ",".join(repr(float(v)) if isinstance(v, float) else str(v) for v in value)]
        else:
            flags += [flag, repr(value) if isinstance(value, float) else str(value)]
    return flags


@pytest.fixture
def rng():
    return np.random.default_rng(26)


@pytest.fixture
def cloud(rng):
    """500 points near the Earth's radius with uint8 colours (which PLY holds exactly)."""
    positions = rng.normal(size=(500, 3)) * 1000.0 + np.array([6378137.0, 0.0, 0.0])
    colors = rng.integers(0, 256, size=(500, 3), dtype=np.uint8)
    return dpoint.PointSet(positions, colors), positions, colors
