"""`dpoint bench --baseline` (issue #38) flags a deliberately slowed build: a small bench run (the paper
suite's 1M sets, compute backend) is the baseline, then the same run with every frame's splat
recorded four times (DPOINT_TEST_SPLAT_REPEAT=4: the same pictures, several times the work) must be
marked slower in every row, in report.md, results.json and on stderr. The slowed frames take several
times as long, so no load on the machine can hide it; nothing here asserts a time itself."""
import json
import os
import subprocess
import sys

from common import check, scratch

exe = sys.argv[1]
ARGS = ["bench", "--suite", "paper", "--sizes", "1M", "--backend", "compute", "--no-error", "--no-copy-bandwidth",
        "--frames", "3", "--warmup", "1ms", "--quiet"]

with scratch() as d:
    base, slow, cache = (os.path.join(d, name) for name in ("base", "slow", "cache"))
    ran = subprocess.run([exe, *ARGS, "--out", base, "--cache", cache], capture_output=True, text=True)
    check(ran.returncode == 0, f"the baseline run failed ({ran.returncode}): {ran.stderr}")
    env = dict(os.environ, DPOINT_TEST_SPLAT_REPEAT="4")
    ran = subprocess.run([exe, *ARGS, "--out", slow, "--cache", cache, "--baseline", os.path.join(base, "results.json")],
                         capture_output=True, text=True, env=env)
    check(ran.returncode == 0, f"the slowed run failed ({ran.returncode}): {ran.stderr}")
    results = json.load(open(os.path.join(slow, "results.json")))
    baseline = results.get("baseline")
    check(baseline is not None, "results.json has no baseline object")
    check(len(baseline["rows"]) == len(results["rows"]) == 14,
          f"{len(baseline['rows'])} rows compared of {len(results['rows'])}, expected 14")
    unflagged = [f"{r['case']} {r['mode']} ({r['ratio']:.2f}x)" for r in baseline["rows"] if not r["slower"]]
    check(not unflagged, f"rows of the slowed build not marked slower: {unflagged}")
    check(baseline["slower"] == 14, f"slower = {baseline['slower']}")
    report = open(os.path.join(slow, "report.md")).read()
    check("14 of 14 rows more than 5% slower" in report, "report.md does not sum up the baseline")
    check(report.count("**slower**") == 14, f"report.md marks {report.count('**slower**')} rows")
    warned = [line for line in ran.stderr.splitlines() if "against the baseline's" in line]
    check(len(warned) == 14, f"{len(warned)} warnings on stderr: {ran.stderr}")
    # A baseline of other cases (its 1M sets against a run of 10K ones) compares nothing: a warning
    # says so (the build before summed up "0 rows compared, 0 more than 5% slower" without a word).
    small = [a if a != "1M" else "10K" for a in ARGS]
    ran = subprocess.run([exe, *small, "--out", os.path.join(d, "small"), "--cache", cache, "--baseline",
                          os.path.join(base, "results.json")], capture_output=True, text=True)
    check(ran.returncode == 0 and "no timed row of this run (its case, backend and mode) is in the baseline (14 timed "
          "rows there): nothing was compared" in ran.stderr, f"a baseline of other cases: exit {ran.returncode}, {ran.stderr}")
    # A file that is no results.json is refused before any work, naming it.
    bad = os.path.join(d, "bad.json")
    open(bad, "w").write("{}")
    ran = subprocess.run([exe, *ARGS, "--out", slow, "--cache", cache, "--baseline", bad], capture_output=True, text=True)
    check(ran.returncode == 2 and "bad.json: not a dpoint bench results.json" in ran.stderr,
          f"bad baseline: exit {ran.returncode}, {ran.stderr}")
print("ok: the slowed build's 14 rows are marked slower than the baseline")
