#!/usr/bin/python3
"""An A/B of the default render (every default: --mode auto, round points, eye-dome lighting) of
several sets at several picture sizes, two or more builds alternated in each round on one machine
(lavapipe here, or the GPU machine after `source bench/scripts/gpu_env.sh`).

Per round, set, size and build: one fresh whole process (`render SET -o PNG`, its wall time), then
one `render SET --frames FRAMES --json` for the median host frame (`frame_ms`: the frame with its
shading passes, which the GPU timestamps leave out) and the render phase. Rows go to OUT.tsv, the
medians over the rounds to OUT-median.tsv and as Markdown to stdout.

  bench/scripts/default_render_ab.py OUT NAME=BIN NAME=BIN ... [--data DIR] [--sets mb420 julia]
      [--sizes 1024x768 3840x2160] [--rounds 5] [--frames 5]

SET names DIR/SET.ply (default /dev/shm/lt, as bench/scripts/local_targets.sh makes them)."""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import timed  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out")
    parser.add_argument("builds", nargs="+", help="NAME=BINARY, two or more")
    parser.add_argument("--data", default="/dev/shm/lt")
    parser.add_argument("--sets", nargs="+", default=["mb420", "julia", "menger"])
    parser.add_argument("--sizes", nargs="+", default=["1024x768", "3840x2160"])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--frames", type=int, default=5)
    args = parser.parse_args()
    builds = [b.split("=", 1) for b in args.builds]
    if len(builds) < 2 or any(len(b) != 2 for b in builds):
        sys.exit("give two or more builds as NAME=BINARY")
    rows = []
    with tempfile.TemporaryDirectory() as work:
        png, report = os.path.join(work, "r.png"), os.path.join(work, "r.json")
        for round_ in range(1, args.rounds + 1):
            for name in args.sets:
                path = os.path.join(args.data, name + ".ply")
                for size in args.sizes:
                    width, height = size.split("x")
                    for build, binary in builds:
                        common = [binary, "render", path, "--width", width, "--height", height, "-q"]
                        wall, peak, _ = timed(common + ["-o", png])
                        subprocess.run(common + ["--frames", str(args.frames), "--json", report, "-o", png],
                                       check=True, capture_output=True)
                        j = json.load(open(report))
                        row = [str(round_), name, size, build, f"{wall * 1000:.0f}", f"{j['frame_ms']['median']:.2f}",
                               f"{j['phases_ms']['render']:.1f}", str(j["point_size"]), j["mode"], f"{peak / 2**20:.0f}"]
                        print("\t".join(row), file=sys.stderr)
                        rows.append(row)
    header = ["round", "set", "size", "build", "process_ms", "frame_ms", "render_phase_ms", "point_size", "mode",
              "peak_mb"]
    with open(args.out + ".tsv", "w") as f:
        f.write("\t".join(header) + "\n" + "".join("\t".join(r) + "\n" for r in rows))
    medians = []
    for key in dict.fromkeys((r[1], r[2], r[3]) for r in rows):
        rs = [r for r in rows if (r[1], r[2], r[3]) == key]
        med = [statistics.median(float(r[c]) for r in rs) for c in (4, 5, 6)]
        medians.append([*key, f"{med[0]:.0f}", f"{med[1]:.2f}", f"{med[2]:.1f}", rs[0][7], rs[0][8]])
    with open(args.out + "-median.tsv", "w") as f:
        f.write("set\tsize\tbuild\tprocess_ms\tframe_ms\trender_phase_ms\tpoint_size\tmode\n")
        f.write("".join("\t".join(m) + "\n" for m in medians))
    print(f"| set | size | build | whole process (ms) | frame with shading (ms) | render phase (ms) | point size | mode |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for m in medians:
        print("| " + " | ".join(m) + " |")


if __name__ == "__main__":
    main()
