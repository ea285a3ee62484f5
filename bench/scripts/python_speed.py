#!/usr/bin/python3
"""The Python module's figures of issue #26, in one run on this machine:

  render   the whole call `dpoint.render(PointSet(array, colours), ...)` on N points from NumPy,
           against the same render through the CLI from a file (`dpoint render F.ply -o X.png`,
           the process's wall time: start, read, device, render, PNG), interleaved, and against
           Open3D's offscreen capture of the same arrays (the legacy Visualizer in a Python process
           of its own, as Open3D in this one slowed dpoint's 10M call by a third: arrays to a
           PointCloud, add_geometry, capture_screen_float_buffer, to uint8; its window is made once,
           before the timing); median of --runs each;
  reuse    a Renderer reused over 10 views of the 1M set against 10 separate dpoint.render calls;
  memory   the peak resident memory a PointSet adds over the (N, 3) float64 array it is made from
           (a child process each: a fresh peak).
Every picture is 1920x1080 with each tool's defaults (dpoint: --mode auto, point size and shading
auto; Open3D: 5-px points, its default camera). Points: uniform in the unit cube, uint8 colours.

Usage: PYTHONPATH=build/python /usr/bin/python3 bench/scripts/python_speed.py build/dpoint OUT.json
       [--sizes 1000000,10000000] [--runs 5] [--no-open3d]
Needs Debian's Open3D and, with no X display, Xvfb (bench/scripts/open3d_capture.py says why).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import dpoint

W, H = 1920, 1080


def dataset(n):
    rng = np.random.default_rng(n)
    return rng.random((n, 3)), rng.integers(0, 256, (n, 3), dtype=np.uint8)


def time_module(positions, colors):
    t = time.perf_counter()
    result = dpoint.render(dpoint.PointSet(positions, colors), width=W, height=H)
    wall = time.perf_counter() - t
    assert result.image.shape == (H, W, 4)
    return wall


def time_cli(exe, path, png):
    t = time.perf_counter()
    subprocess.run([exe, "render", path, "-o", png, "--width", str(W), "--height", str(H), "--quiet"], check=True,
                   stdout=subprocess.DEVNULL)
    return time.perf_counter() - t


class Open3D:
    def __init__(self):
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import open3d_capture  # noqa: E402  (its Xvfb starter)
        import open3d as o3d

        self.o3d = o3d
        self.xvfb = None if os.environ.get("DISPLAY") else open3d_capture.start_xvfb(W, H)
        self.vis = o3d.visualization.Visualizer()
        if not self.vis.create_window(width=W, height=H, visible=False):
            raise RuntimeError("Open3D: create_window failed")

    def time(self, positions, colors):
        o3d = self.o3d
        t = time.perf_counter()
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(positions))
        cloud.colors = o3d.utility.Vector3dVector(colors / 255.0)
        self.vis.clear_geometries()
        self.vis.add_geometry(cloud)
        image = (np.asarray(self.vis.capture_screen_float_buffer(do_render=True)) * 255.0).astype(np.uint8)
        wall = time.perf_counter() - t
        assert image.shape[:2] == (H, W)
        return wall

    def close(self):
        self.vis.destroy_window()
        if self.xvfb:
            self.xvfb.terminate()


def open3d_child(positions_npy, colors_npy, runs):
    """The --open3d-child mode: one warm capture, then `runs` timed ones, as JSON on stdout."""
    positions, colors = np.load(positions_npy), np.load(colors_npy)
    o3d = Open3D()
    o3d.time(positions, colors)
    times = [o3d.time(positions, colors) for _ in range(runs)]
    print(json.dumps(times), flush=True)
    o3d.close()
    os._exit(0)  # Open3D 0.16's GLFW teardown reports a lost X connection at interpreter exit


def time_open3d(tmp, positions, colors, runs):
    files = [os.path.join(tmp, "positions.npy"), os.path.join(tmp, "colors.npy")]
    np.save(files[0], positions)
    np.save(files[1], colors)
    out = subprocess.run([sys.executable, os.path.abspath(__file__), "--open3d-child", *files, str(runs)],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def peak_memory(n):
    """MB of peak RSS: after the array, and after the PointSet made from it (a fresh child)."""
    # VmHWM, not ru_maxrss: the latter keeps the parent's peak across fork and exec.
    code = (f"import numpy as np, dpoint\n"
            f"def hwm(): return [int(l.split()[1]) for l in open('/proc/self/status') if l.startswith('VmHWM')][0]\n"
            f"a = np.random.default_rng(1).random(({n}, 3))\n"
            f"r0 = hwm()\n"
            f"s = dpoint.PointSet(a)\n"
            f"r1 = hwm()\n"
            f"print(r0 / 1024, r1 / 1024)\n")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout.split()
    array_mb, set_mb = float(out[0]), float(out[1])
    return dict(points=n, array_mb=n * 24 / 2**20, peak_after_array_mb=array_mb, peak_after_pointset_mb=set_mb,
                added_mb=set_mb - array_mb)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dpoint")
    parser.add_argument("out")
    parser.add_argument("--sizes", default="1000000,10000000")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--no-open3d", action="store_true")
    if len(sys.argv) == 5 and sys.argv[1] == "--open3d-child":
        open3d_child(sys.argv[2], sys.argv[3], int(sys.argv[4]))
    args = parser.parse_args()
    exe = os.path.abspath(args.dpoint)
    report = dict(device=dpoint.Renderer().device, width=W, height=H, runs=args.runs, render=[], memory=[])
    with tempfile.TemporaryDirectory() as tmp:
        for n in (int(s) for s in args.sizes.split(",")):
            positions, colors = dataset(n)
            path = os.path.join(tmp, f"points{n}.ply")
            dpoint.write(dpoint.PointSet(positions, colors), path)
            png = os.path.join(tmp, "cli.png")
            time_module(positions, colors), time_cli(exe, path, png)  # warm: page cache, shader caches
            rows = dict(module=[], cli=[], open3d=[])
            for _ in range(args.runs):
                rows["module"].append(time_module(positions, colors))
                rows["cli"].append(time_cli(exe, path, png))
            if not args.no_open3d:
                rows["open3d"] = time_open3d(tmp, positions, colors, args.runs)
            entry = dict(points=n, **{f"{k}_s": v for k, v in rows.items() if v},
                         **{f"{k}_median_s": statistics.median(v) for k, v in rows.items() if v})
            entry["module_over_cli"] = entry["module_median_s"] / entry["cli_median_s"]
            if rows["open3d"]:
                entry["module_over_open3d"] = entry["module_median_s"] / entry["open3d_median_s"]
            print(json.dumps(entry), flush=True)
            report["render"].append(entry)
            if n == 1_000_000:  # a Renderer over 10 views against 10 renders
                ps = dpoint.PointSet(positions, colors)
                eyes = [(0.5 + 2 * np.cos(a), 0.5 + 2 * np.sin(a), 1.5) for a in np.linspace(0, 2 * np.pi, 10, endpoint=False)]
                views = dict(target=(0.5, 0.5, 0.5), up=(0, 0, 1), width=W, height=H)
                t = time.perf_counter()
                with dpoint.Renderer() as r:
                    for eye in eyes:
                        r.render(ps, eye=eye, **views)
                reused = (time.perf_counter() - t) / 10
                t = time.perf_counter()
                for eye in eyes:
                    dpoint.render(ps, eye=eye, **views)
                separate = (time.perf_counter() - t) / 10
                report["reuse"] = dict(points=n, views=10, renderer_s_per_view=reused, render_s_per_view=separate,
                                       ratio=reused / separate)
                print(json.dumps(report["reuse"]), flush=True)
        for n in (int(s) for s in args.sizes.split(",")):
            report["memory"].append(peak_memory(n))
            print(json.dumps(report["memory"][-1]), flush=True)
    with open(args.out, "w", encoding="utf-8") as f:
        json.dump(report, f, indent=1)


if __name__ == "__main__":
    main()
