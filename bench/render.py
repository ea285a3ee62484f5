#!/usr/bin/python3
"""Renderer benchmark (issue #5, DESIGN §5-6): GPU ms/frame and points/s per precision mode at
1920x1080 for 1M, 10M and 16.7M points, with each mode's time as a ratio to fp32 from the same
run; and each mode's error on the hard cases (DESIGN §7). Every number comes from
`dpoint render --json` (GPU timestamps, median of --frames after warm-up).

Usage: bench/render.py DPOINT OUT_PREFIX [--frames N] [--sizes 1m,10m,16m] [--backends raster,compute]
                       [--device auto] [--work DIR]
Writes OUT_PREFIX.json and OUT_PREFIX.md (tables) and OUT_PREFIX.svg (time against error).
Datasets (made with DPOINT itself, so the GPU machine needs nothing else):
  1m   sierpinski --level 9 --unwelded   (1,048,576 points, 3D)
  10m  random2d --count 10000000         (the study's 10M 2D points)
  16m  sierpinski --level 11 --unwelded  (16,777,216 points, the study's largest set)
Hard cases: mandelbulb res 65 moved to the Earth's radius (camera 2 m away), and the
mandelbrot2d grid 512x512 at view width 1e-9 (one point per pixel centre)."""
import argparse
import json
import os
import statistics
import subprocess
import sys

MODES = ["fp32", "split", "rte", "df64", "native", "batch"]
SIZES = {
    "1m": ["sierpinski", "--level", "9", "--unwelded"],
    "10m": ["random2d", "--count", "10000000"],
    "16m": ["sierpinski", "--level", "11", "--unwelded"],
}


def run(argv):
    proc = subprocess.run(argv, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"{' '.join(argv)} failed ({proc.returncode}): {proc.stderr.strip()}")
    return proc.stdout


def generate(dpoint, work, name, args):
    path = os.path.join(work, name + ".ply")
    if not os.path.exists(path):
        run([dpoint, "generate", *args, "--quiet", "-o", path])
    return path


def render(dpoint, work, data, mode, extra):
    out = os.path.join(work, "last.json")
    run([dpoint, "render", data, "-o", os.path.join(work, "last.png"), "--mode", mode, "--quiet", "--json", out, *extra])
    with open(out) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dpoint")
    ap.add_argument("out_prefix")
    ap.add_argument("--frames", type=int, default=20)
    ap.add_argument("--sizes", default="1m,10m,16m")
    ap.add_argument("--backends", default="raster,compute")
    ap.add_argument("--device", default="auto")
    ap.add_argument("--work", default="/tmp/dpoint-bench-render")
    a = ap.parse_args()
    dpoint = os.path.abspath(a.dpoint)
    os.makedirs(a.work, exist_ok=True)
    common = ["--device", a.device]

    backends = a.backends.split(",")
    speed = []
    for size in a.sizes.split(","):
        data = generate(dpoint, a.work, size, SIZES[size])
        for backend in backends:
            rows = {}
            for mode in MODES:
                r = render(dpoint, a.work, data, mode, common + ["--backend", backend, "--width", "1920", "--height",
                                                                 "1080", "--frames", str(a.frames), "--warmup", "2"])
                rows[mode] = r
                print(f"{size} {backend} {mode}: {r['gpu_ms']['median']:.3f} ms", file=sys.stderr, flush=True)
            base = rows["fp32"]["gpu_ms"]["median"]
            for mode, r in rows.items():
                r["dataset"] = size
                r["ratio_to_fp32"] = r["gpu_ms"]["median"] / base
                speed.append(r)

    mb = generate(dpoint, a.work, "mandelbulb_earth", ["mandelbulb", "--resolution", "65", "--offset", "6378137,0,0"])
    zoom = generate(dpoint, a.work, "deepzoom_1e-9", ["mandelbrot2d", "--width", "1e-9", "--resolution", "512", "--max-iter", "1000"])
    hard = []
    for name, data, camera in [
        ("offset 6.378e6 (mandelbulb 65, eye 2 m away)", mb,
         ["--eye", "6378138.2,0.9,1.6", "--target", "6378137,0,0", "--up", "0,1,0", "--width", "1024", "--height", "1024"]),
        ("deepzoom 1e-9 (mandelbrot2d 512²)", zoom,
         ["--view-center", "-0.7436450,0.1318259", "--view-width", "1e-9", "--width", "512", "--height", "512"]),
    ]:
        for backend in backends:
            for mode in MODES:
                r = render(dpoint, a.work, data, mode, common + camera + ["--backend", backend, "--error", "--frames", "5"])
                r["case"] = name
                hard.append(r)

    device = speed[0] if speed else hard[0]
    result = {"device": device["device"], "driver": device["driver"], "driver_version": device["driver_version"],
              "frames": a.frames, "speed": speed, "hard_cases": hard}
    with open(a.out_prefix + ".json", "w") as f:
        json.dump(result, f, indent=1)
    with open(a.out_prefix + ".md", "w") as f:
        f.write(markdown(result))
    with open(a.out_prefix + ".svg", "w") as f:
        f.write(svg(result))
    print(markdown(result))


def markdown(result):
    lines = [f"Device: {result['device']}, driver {result['driver']} ({result['driver_version']}); "
             f"1920x1080, GPU timestamps, median of {result['frames']} frames after 2 warm-up.", "",
             "| points | backend | mode | B/pt | GPU ms/frame (median) | p95 | points/s | × fp32 |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in result["speed"]:
        lines.append(f"| {r['points']:,} | {r['backend']} | {r['mode']} | {r['bytes_per_point']} | {r['gpu_ms']['median']:.3f} | "
                     f"{r['gpu_ms']['p95']:.3f} | {r['points_per_s']:.3g} | {r['ratio_to_fp32']:.2f} |")
    lines += ["", "| hard case | backend | mode | max px | p99 px | rms px | share ≥ 0.5 px | lost | pixels differing |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in result["hard_cases"]:
        e = r["error_px"]
        lines.append(f"| {r['case']} | {r['backend']} | {r['mode']} | {e['max']:.3g} | {e['p99']:.3g} | {e['rms']:.3g} | "
                     f"{r['share_off_half_px']:.3g} | {r['points_lost']} | {r['pixels_differing'] if r['pixels_differing'] is not None else '–'} |")
    return "\n".join(lines) + "\n"


def svg(result):
    """GPU ms/frame (largest set) against max error on the offset case, one dot per mode and backend."""
    largest = max(r["points"] for r in result["speed"]) if result["speed"] else 0
    key = lambda r: r["mode"] + ("" if r["backend"] == "raster" else " (compute)")
    ratio = {key(r): r["gpu_ms"]["median"] for r in result["speed"] if r["points"] == largest}
    error = {key(r): r["error_px"]["max"] for r in result["hard_cases"] if r["case"].startswith("offset")}
    lost = {key(r): r["points_lost"] for r in result["hard_cases"] if r["case"].startswith("offset")}
    import math
    w, h, pad = 640, 400, 60
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
             f'<rect width="{w}" height="{h}" fill="white"/>',
             f'<text x="{w/2}" y="20" text-anchor="middle">{result["device"]}: time vs error per mode</text>',
             f'<text x="{w/2}" y="{h-10}" text-anchor="middle">GPU ms/frame ({largest:,} points, 1920x1080)</text>',
             f'<text x="15" y="{h/2}" transform="rotate(-90 15 {h/2})" text-anchor="middle">max error, px (Earth-radius offset; log)</text>']
    rmax = max(list(ratio.values()) + [1e-9]) * 1.1
    lo, hi = -7, 4
    for mode in sorted(ratio):
        if mode not in error:
            continue
        e = error[mode] if lost.get(mode, 0) == 0 else 10 ** hi
        y = h - pad - (min(max(math.log10(max(e, 10 ** lo)), lo), hi) - lo) / (hi - lo) * (h - 2 * pad)
        x = pad + ratio[mode] / rmax * (w - 2 * pad)
        label = mode + (" (points lost)" if lost.get(mode, 0) else "")
        parts.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="5" fill="steelblue"/>')
        parts.append(f'<text x="{x+8:.1f}" y="{y+4:.1f}">{label}</text>')
    for k in range(lo, hi + 1, 2):
        y = h - pad - (k - lo) / (hi - lo) * (h - 2 * pad)
        parts.append(f'<text x="{pad-8}" y="{y+4:.1f}" text-anchor="end">1e{k}</text>')
    parts.append(f'<line x1="{pad}" y1="{h-pad}" x2="{w-pad}" y2="{h-pad}" stroke="black"/>')
    parts.append(f'<line x1="{pad}" y1="{pad}" x2="{pad}" y2="{h-pad}" stroke="black"/>')
    parts.append("</svg>\n")
    return "\n".join(parts)


if __name__ == "__main__":
    main()
