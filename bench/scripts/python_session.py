#!/usr/bin/env python3
"""A long-lived Python process that draws many times (issue #26): does a later draw run slower
than the first? The last round found that after one process drew and probed a 10M-point set, its
later draws ran 4-6x slower on the H100 (docs/performance.md); a Python session is such a process.

In one process: the dataset is generated (dpoint.generate, in memory), then
  renderer: RENDERS renders with one dpoint.Renderer (one device), each FRAMES timed frames;
  fresh:    3 renders with dpoint.render (a device each);
  probed:   one render with error=True (the probe and the exact reference), then RENDERS more
            with the same Renderer, as the bench's process did.
  views:    10 views of the set (one frame each, the whole call timed) with one Renderer, then
            with dpoint.render (a device each).
One JSON line per render: phase, index, GPU median/min/p95 of its frames, wall time of the call.

    PYTHONPATH=build/python /usr/bin/python3 bench/scripts/python_session.py --kind sierpinski --level 11
"""
import argparse
import json
import math
import statistics
import sys
import time

import dpoint

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--kind", default="sierpinski")
parser.add_argument("--level", type=int, default=11, help="sierpinski/menger level (11: 16.7M points)")
parser.add_argument("--renders", type=int, default=10)
parser.add_argument("--frames", type=int, default=50)
parser.add_argument("--warmup", default="300ms")
parser.add_argument("--mode", default="fp32")
parser.add_argument("--order", default="morton")
parser.add_argument("--width", type=int, default=1920)
parser.add_argument("--height", type=int, default=1080)
parser.add_argument("--probe-points", type=int, default=10_000_000,
                    help="points of the probed set (a random2d set; 0: skip the probed phase)")
args = parser.parse_args()

options = dict(width=args.width, height=args.height, frames=args.frames, warmup=args.warmup,
               backend="compute", order=args.order)


def row(phase, index, result, wall):
    g = result.gpu_ms
    line = dict(phase=phase, index=index, points=result.points, mode=result.mode, device=result.device,
                gpu_ms_median=statistics.median(g), gpu_ms_min=min(g),
                gpu_ms_p95=sorted(g)[max(0, int(round(0.95 * len(g))) - 1)], wall_s=round(wall, 3))
    print(json.dumps(line), flush=True)


t = time.perf_counter()
points = dpoint.generate(args.kind, level=args.level, unwelded=True)
print(json.dumps(dict(generated=len(points), seconds=round(time.perf_counter() - t, 2))), flush=True)

with dpoint.Renderer() as renderer:
    for i in range(args.renders):
        t = time.perf_counter()
        r = renderer.render(points, args.mode, **options)
        row("renderer", i, r, time.perf_counter() - t)
for i in range(3):
    t = time.perf_counter()
    r = dpoint.render(points, args.mode, **options)
    row("fresh", i, r, time.perf_counter() - t)
if args.probe_points:
    probed = dpoint.generate("random2d", count=args.probe_points)
    with dpoint.Renderer() as renderer:
        t = time.perf_counter()
        r = renderer.render(probed, args.mode, width=args.width, height=args.height, error=True)
        row("probe", 0, r, time.perf_counter() - t)
        for i in range(args.renders):
            t = time.perf_counter()
            r = renderer.render(points, args.mode, **options)
            row("after_probe", i, r, time.perf_counter() - t)
# Ten views, each a whole call of one frame: a Renderer's device against a device per call.
eyes = [(0.24 + 3.0 * math.cos(a), 1.5, 0.33 + 3.0 * math.sin(a)) for a in (2 * math.pi * k / 10 for k in range(10))]
view = dict(width=args.width, height=args.height, target=(0.24, 0.0, 0.33), up=(0, 1, 0), order=args.order)
with dpoint.Renderer() as renderer:
    for i, eye in enumerate(eyes):
        t = time.perf_counter()
        r = renderer.render(points, args.mode, eye=eye, **view)
        row("views_renderer", i, r, time.perf_counter() - t)
for i, eye in enumerate(eyes):
    t = time.perf_counter()
    r = dpoint.render(points, args.mode, eye=eye, **view)
    row("views_render", i, r, time.perf_counter() - t)
sys.stdout.flush()
