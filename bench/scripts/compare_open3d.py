#!/usr/bin/python3
"""dpoint's default picture beside Open3D's default offscreen capture, timed and measured (issue #24).

Usage: /usr/bin/python3 bench/scripts/compare_open3d.py build/dpoint RESULTS.md FILE... [--runs 5]
       [--pictures DIR]

For each FILE (PLY or CSV; Open3D reads no LAS, so convert a survey first with
`dpoint convert X.las -o X.ply`):
  dpoint   `dpoint render FILE -o DIR/NAME.dpoint.png`, every default (1024x768);
  Open3D   `/usr/bin/python3 open3d_capture.py FILE DIR/NAME.open3d.png`, Open3D 0.16's legacy
           Visualizer with every default (see that script), 1024x768.
Each is run once untimed (warm-up: the file in the page cache, the shader caches filled), then
--runs times (5); the table gives the median wall seconds of the whole process (start to exit,
PNG written), and beside it the in-process seconds each tool reports: dpoint's `time to picture`
phases summed (read, order, camera, device, mode, render, png), Open3D's load + capture (window,
upload, draw, read-back, PNG; Python's start and `import open3d`, about 0.35 s, are outside it).
Peak RSS is the largest of the timed runs (/usr/bin/time).

The pictures of the last timed run are measured as the issue's fill test does
(tests/viewer/picture_metrics.h): a pixel is drawn when its RGB differs from the background's
(dpoint: 0,0,0; Open3D: its RenderOption.background_color, white, checked against the corner
pixel); span is the larger side of the drawn pixels' bounding box over the picture's smaller
side; gap is the background pixels that a 7x7 binary closing of the drawn mask covers, over the
closed area (outside the picture counts as not drawn for the dilation and as drawn for the
erosion).

Open3D needs an X display here (no EGL headless in Debian's build): when $DISPLAY is unset, one
Xvfb is started for all runs, outside the timings. Prints the Markdown table and writes it, with
a line on the machine and the command, to RESULTS.md.
"""
import argparse
import datetime
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile

import numpy as np
import open3d as o3d

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
from open3d_capture import start_xvfb  # noqa: E402
from timing import remover, timed  # noqa: E402

CAPTURE = os.path.join(here, "open3d_capture.py")
PYTHON = "/usr/bin/python3"


def read_rgb(path):
    image = np.asarray(o3d.io.read_image(path))
    if image.ndim != 3 or image.shape[2] < 3 or image.dtype != np.uint8:
        sys.exit(f"{path}: expected an 8-bit RGB(A) picture, got {image.shape} {image.dtype}")
    return image[:, :, :3]


def square_filter(mask, size, dilate):
    """Max (dilate) or min (erode) over a size x size square, a row pass then a column pass, with
    the picture padded by size // 2 pixels of 0 (dilation) or 1 (erosion)."""
    h, w = mask.shape
    r = size // 2
    padded = np.pad(mask, r, constant_values=not dilate)
    combine = np.logical_or if dilate else np.logical_and
    rows = padded[:, 0:w].copy()
    for k in range(1, size):
        combine(rows, padded[:, k:k + w], out=rows)
    out = rows[0:h].copy()
    for k in range(1, size):
        combine(out, rows[k:k + h], out=out)
    return out


def fill_metrics(rgb, background, size=7):
    """(span, gap share, drawn pixels, closed pixels, gap pixels) of a picture."""
    drawn = np.any(rgb != np.asarray(background, dtype=np.uint8), axis=2)
    h, w = drawn.shape
    if not drawn.any():
        return 0.0, 0.0, 0, 0, 0
    ys, xs = np.nonzero(drawn)
    span = max(int(xs.max() - xs.min()) + 1, int(ys.max() - ys.min()) + 1) / min(h, w)
    closed = square_filter(square_filter(drawn, size, True), size, False)
    gaps = int(np.count_nonzero(closed & ~drawn))
    n_closed = int(np.count_nonzero(closed))
    return span, gaps / n_closed, int(np.count_nonzero(drawn)), n_closed, gaps


def median_runs(argv, runs, output, after=None):
    """One untimed run, then `runs` timed ones: (median wall s, max peak RSS bytes, outs) where outs
    holds what `after(stdout)` returned for each timed run."""
    subprocess.run(argv, check=True, capture_output=True)
    walls, peaks, outs = [], [], []
    for _ in range(runs):
        wall, peak, stdout = timed(argv, remover(output))
        walls.append(wall)
        peaks.append(peak)
        outs.append(after(stdout) if after else stdout)
    return statistics.median(walls), max(peaks), outs


def dpoint_in_process(stdout):
    """dpoint's `time to picture (ms): read 18.3, ..., png 26.3` summed, in seconds; its point size
    and point count."""
    m = re.search(r"time to picture \(ms\): ([^;\n]*)", stdout)
    phases = sum(float(v) for v in re.findall(r"[a-z]+ ([0-9.]+)", m.group(1))) / 1000 if m else float("nan")
    size = re.search(r"(\d+(?:\.\d+)?) px points", stdout)
    points = re.search(r": (\d+) points", stdout)
    return phases, size.group(1) if size else "?", points.group(1) if points else "?"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dpoint")
    ap.add_argument("results", help="Markdown file to write the table to")
    ap.add_argument("files", nargs="+")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--pictures", help="folder for the PNGs (default: RESULTS's folder/open3d_pictures)")
    args = ap.parse_args()
    dpoint = os.path.abspath(args.dpoint)
    pictures = args.pictures or os.path.join(os.path.dirname(os.path.abspath(args.results)), "open3d_pictures")
    os.makedirs(pictures, exist_ok=True)
    xvfb = None if os.environ.get("DISPLAY") else start_xvfb(1024, 768)
    rows, notes = [], []
    try:
        for path in args.files:
            name = os.path.splitext(os.path.basename(path))[0]
            print(f"{name}: dpoint ...", file=sys.stderr, flush=True)
            dp_png = os.path.join(pictures, f"{name}.dpoint.png")
            dp_wall, dp_peak, dp_outs = median_runs([dpoint, "render", path, "-o", dp_png], args.runs, dp_png,
                                                    dpoint_in_process)
            print(f"{name}: Open3D ...", file=sys.stderr, flush=True)
            o3_png = os.path.join(pictures, f"{name}.open3d.png")
            with tempfile.NamedTemporaryFile(suffix=".json") as js:
                def read_json(_stdout):
                    with open(js.name) as f:
                        return json.load(f)
                o3_wall, o3_peak, o3_outs = median_runs([PYTHON, CAPTURE, path, o3_png, "--json", js.name],
                                                        args.runs, o3_png, read_json)
            o3_bg = [round(255 * c) for c in o3_outs[-1]["background"]]
            o3_rgb = read_rgb(o3_png)
            if list(o3_rgb[0, 0]) != o3_bg:
                notes.append(f"{name}: Open3D's corner pixel is {list(o3_rgb[0, 0])}, not its background {o3_bg}")
            for tool, png, bg, wall, inproc, peak, size in (
                    ("dpoint", dp_png, (0, 0, 0), dp_wall, statistics.median(o[0] for o in dp_outs), dp_peak,
                     dp_outs[-1][1]),
                    ("Open3D", o3_png, o3_bg, o3_wall, statistics.median(o["load_capture_s"] for o in o3_outs),
                     o3_peak, "5")):
                span, gap, drawn, closed, gaps = fill_metrics(read_rgb(png), bg)
                rows.append((name, dp_outs[-1][2], tool, wall, inproc, peak, size, span,
                             gap, os.path.relpath(png, os.path.dirname(os.path.abspath(args.results)))))
                print(f"{name} {tool}: {wall:.3f} s, span {100 * span:.1f}%, gap {100 * gap:.2f}% "
                      f"({gaps} of {closed} px; {drawn} drawn)", file=sys.stderr, flush=True)
    finally:
        if xvfb:
            xvfb.terminate()
            xvfb.wait()

    header = ("| file | points | tool | seconds (whole process, median of {n}) | in-process s | peak RSS MB "
              "| point px | span % | gap % | picture |\n"
              "| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |").format(n=args.runs)
    lines = [header] + [
        f"| {r[0]} | {int(r[1]):,} | {r[2]} | {r[3]:.3f} | {r[4]:.3f} | {r[5] / 2**20:.0f} | {r[6]} | "
        f"{100 * r[7]:.1f} | {100 * r[8]:.2f} | {r[9]} |" for r in rows]
    table = "\n".join(lines)
    print(table)
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    dp_version = subprocess.run([dpoint, "--version"], capture_output=True, text=True).stdout.strip()
    with open(args.results, "w") as f:
        f.write(f"# dpoint's default render beside Open3D's default capture\n\n"
                f"{datetime.date.today()}, {platform.node()}: {cpu}, {os.cpu_count()} cores; dpoint "
                f"({dp_version}) on Mesa lavapipe, Open3D {o3d.__version__} (Debian) Visualizer(visible=False) "
                f"on Mesa llvmpipe under Xvfb. Command: `{' '.join(sys.argv)}`.\n\n"
                f"Seconds: the whole process, start to exit with the PNG written, median of {args.runs} after one "
                f"warm-up run. In-process: dpoint's `time to picture` phases summed; Open3D's load + capture "
                f"(Python's start and `import open3d` excluded). Span: the drawn pixels' bounding box, larger side "
                f"over the picture's smaller side. Gap: background pixels a 7×7 closing of the drawn mask covers, "
                f"share of the closed area (dpoint background 0,0,0; Open3D's white).\n\n{table}\n")
        for n in notes:
            f.write(f"\n{n}\n")
    for n in notes:
        print(n, file=sys.stderr)


if __name__ == "__main__":
    main()
