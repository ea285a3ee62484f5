"""The README's claims about what commands print, checked against the commands (issue #36 item 4).

Each claim is run and compared: the number of precision modes (the word the README uses, and the
rows of its mode table) against `dpoint render --help`'s --mode list; the exit-code line against
`dpoint --help`'s; the tour's Mandelbulb (its point count and float32's worst error, run as the
tour runs it); the corpus pictures' captions (points and extents of simple.las and
autzen_trim.laz). A README figure that drifts from the program fails here, naming the line.

    check_claims.py PROJECT_DIR DPOINT CORPUS_DIR
"""
import json
import os
import re
import subprocess
import sys
import tempfile

NUMBERS = {"five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9}


def run(*args):
    done = subprocess.run(args, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(args)}: exit {done.returncode}: {done.stderr.strip()}")
    return done.stdout


def main():
    project, dpoint, corpus = sys.argv[1], sys.argv[2], sys.argv[3]
    readme = open(os.path.join(project, "README.md"), encoding="utf-8").read()
    failures = []

    def claim(ok, what):
        if not ok:
            failures.append(what)

    # The modes: "--mode TEXT=auto  auto|fp32|...". The README says their number in words, and
    # its mode table has a row per mode.
    modes = re.search(r"--mode TEXT=auto\s+auto\|([\w|]+)", run(dpoint, "render", "--help")).group(1).split("|")
    for word in re.findall(r"in (\w+) precision modes", readme):
        claim(NUMBERS.get(word) == len(modes), f"README says '{word} precision modes'; render --mode has {len(modes)}")
    rows = [m for m in modes if re.search(r"^\| `" + m + r"` \|", readme, re.M)]
    claim(rows == modes, f"README's mode table rows {rows} != render's modes {modes}")

    # The exit codes, as `dpoint --help` states them.
    helped = " ".join(run(dpoint, "--help").split())
    codes = re.search(r"Exit codes: (.*?), 130/143", helped).group(1)
    claim(f"Exit codes: {codes}, 130/143" in " ".join(readme.split()), f"README's exit codes differ from --help's: {codes}")

    with tempfile.TemporaryDirectory() as work:
        # The tour: the Mandelbulb's count and float32's worst error, as the tour runs them.
        bulb = os.path.join(work, "bulb.ply")
        run(dpoint, "generate", "mandelbulb", "--resolution", "200", "--offset", "6378137,0,0", "-o", bulb, "-q")
        info = json.loads(run(dpoint, "info", bulb, "--json", "--sample", "10"))
        count = f"{info['points']:,}"
        claim(f"Mandelbulb surface ({count} points)" in readme, f"the tour's Mandelbulb has {count} points")
        report = os.path.join(work, "fp32.json")
        run(dpoint, "render", bulb, "-o", os.path.join(work, "fp32.png"), "--mode", "fp32", "--error", "--width",
            "480", "--height", "480", "--point-size", "2", "--json", report, "-q")
        worst = json.load(open(report))["error_px"]["max"]
        said = re.search(r"float32 instead: points up to (\d+) px off", readme)
        claim(said and int(said.group(1)) == int(worst), f"the tour's fp32 error is {worst:.1f} px, README says "
              f"{said.group(1) if said else 'nothing'}")

    # The corpus captions: points and extent.
    simple = json.loads(run(dpoint, "info", os.path.join(corpus, "las", "simple.las"), "--json", "--sample", "10"))
    extent_km = f"{simple['extent'][0] / 1000:.1f} × {simple['extent'][1] / 1000:.1f} km"
    claim(f"a LAS survey ({simple['points']:,} returns, {extent_km})" in readme,
          f"simple.las: {simple['points']:,} returns, {extent_km}")
    autzen = json.loads(run(dpoint, "info", os.path.join(corpus, "laz", "autzen_trim.laz"), "--json", "--sample",
                            "10"))
    claim(f"{autzen['points']:,} returns" in readme, f"autzen_trim.laz: {autzen['points']:,} returns")

    for f in failures:
        print(f"README drift: {f}")
    if failures:
        sys.exit(1)
    print(f"README claims hold: {len(modes)} modes, exit codes, the tour's Mandelbulb ({count} points, fp32 "
          f"{worst:.1f} px), the corpus captions")


if __name__ == "__main__":
    main()
