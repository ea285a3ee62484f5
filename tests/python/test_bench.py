"""dpoint.bench runs the CLI's `dpoint bench` (its parser and messages), whose datasets and timed
draws are child processes of $DPOINT_EXECUTABLE, which the module sets to a built dpoint. The ci
suite itself takes minutes on lavapipe: tests/external/bench_ci_suite.py runs it."""
import os
import stat

import pytest

import dpoint
from conftest import EXECUTABLE, cli_error


def test_a_bad_option_is_the_clis_error(tmp_path):
    message, code = cli_error("bench", "--suite", "nightly", "--out", tmp_path / "out")
    with pytest.raises(dpoint.Error) as raised:
        dpoint.bench("nightly", out=tmp_path / "out", progress=False)
    assert message == "--suite nightly: must be ci, paper, hard or all"
    assert str(raised.value) == "suite nightly: must be ci, paper, hard or all"  # the keyword's name
    assert raised.value.exit_code == code == 1
    with pytest.raises(dpoint.Error, match="^frames 0: must be at least 1"):
        dpoint.bench(out=tmp_path / "out", frames=0, progress=False)
    assert not (tmp_path / "out").exists()


def test_an_unknown_keyword_says_did_you_mean(tmp_path):
    with pytest.raises(dpoint.Error) as raised:
        dpoint.bench(out=tmp_path / "out", backnd="raster", progress=False)
    assert str(raised.value) == ("bench: unknown option 'backnd'; did you mean 'backend'? "
                                 "(`dpoint bench --help` lists them)")


def test_the_module_points_bench_at_a_built_dpoint(tmp_path, monkeypatch):
    monkeypatch.delenv("DPOINT_EXECUTABLE", raising=False)
    with pytest.raises(dpoint.Error):
        dpoint.bench("nightly", out=tmp_path / "out", progress=False)
    assert os.environ["DPOINT_EXECUTABLE"] == os.path.realpath(EXECUTABLE)


def test_bench_runs_its_children_with_dpoint_executable(tmp_path, monkeypatch):
    """A stand-in executable that records how it was called and fails: bench's first child (a
    dataset made with `generate`) runs it, and its failure is bench's error."""
    log = tmp_path / "calls.txt"
    stand_in = tmp_path / "dpoint-stand-in"
    stand_in.write_text(f'#!/bin/sh\necho "$@" >> "{log}"\nexit 1\n')
    stand_in.chmod(stand_in.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setenv("DPOINT_EXECUTABLE", str(stand_in))
    cache = tmp_path / "cache"
    with pytest.raises(dpoint.Error) as raised:
        dpoint.bench("ci", out=tmp_path / "out", cache=cache, no_copy_bandwidth=True, progress=False)
    assert "failed (exit 1)" in str(raised.value)
    calls = log.read_text().splitlines()
    assert calls and calls[0].startswith("generate ") and f"-o {cache}/" in calls[0]
    assert not (tmp_path / "out" / "results.json").exists()
