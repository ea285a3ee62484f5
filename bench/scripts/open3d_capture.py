#!/usr/bin/python3
"""Open3D's default offscreen capture of a point file, timed (issue #24: dpoint's default picture
beside Open3D's).

Usage: /usr/bin/python3 bench/scripts/open3d_capture.py FILE OUT.png [--width 1024] [--height 768]
       [--json OUT.json]

Runs under Debian's Open3D (python3-open3d 0.16.1, for /usr/bin/python3). What it does, exactly:
  load     open3d.io.read_point_cloud(FILE) for .ply/.pcd/.xyz/.pts (a PLY's faces are ignored:
           its vertices are the points, with their colours); a .csv (dpoint's `x,y,z,r,g,b`,
           `x,y,z` or `x,y`, header optional, colours 0..1 or 0..255) through numpy.loadtxt into a
           PointCloud.
  capture  the legacy visualizer, the one behind open3d.visualization.draw_geometries:
             vis = open3d.visualization.Visualizer()
             vis.create_window(width=1024, height=768, visible=False)
             vis.add_geometry(cloud)              # resets the view to fit the bounding box
             vis.capture_screen_image(OUT, do_render=True)
             vis.destroy_window()
           Nothing else is set: every RenderOption and ViewControl value stays Open3D's default:
           point size 5 px, white background (1, 1, 1), PointColorOption.Default (the file's
           colours, else a jet colour map along z), no lighting for a cloud without normals, a
           60-degree perspective camera looking down -z with +y up, framed on the bounding box.

Headless: Debian's build cannot use the EGL/filament OffscreenRenderer ("EGL Headless is not
supported on this platform", with or without EGL_PLATFORM=surfaceless), and its GLFW 3.3 needs an X
display even for a hidden window. So the window is a hidden GLFW window on an X server: $DISPLAY
when set, else an Xvfb (Debian package `xvfb`) this script starts before any timing and stops at
the end; Mesa's llvmpipe (software OpenGL) draws it. bench/scripts/compare_open3d.py starts one Xvfb
for all its runs and passes DISPLAY.

Prints the wall seconds of the load, of the capture (window, upload, draw, read-back and PNG
write) and of both, plus `import open3d` apart; --json writes them as one object.
"""
import argparse
import json
import os
import subprocess
import sys
import time

t_import0 = time.perf_counter()
import numpy as np  # noqa: E402
import open3d as o3d  # noqa: E402
import_s = time.perf_counter() - t_import0


def start_xvfb(width, height):
    """Starts Xvfb on a free display (it picks the number and reports it through -displayfd).
    Returns the process, or exits when Xvfb is not installed."""
    read_fd, write_fd = os.pipe()
    screen = f"{max(1280, width)}x{max(1024, height)}x24"
    try:
        proc = subprocess.Popen(["Xvfb", "-displayfd", str(write_fd), "-screen", "0", screen, "-nolisten", "tcp"],
                                pass_fds=(write_fd,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except FileNotFoundError:
        sys.exit("no $DISPLAY and no Xvfb: Open3D 0.16's visualizer needs an X display here "
                 "(apt-get install -y xvfb)")
    os.close(write_fd)
    with os.fdopen(read_fd) as f:
        number = f.readline().strip()
    if not number:
        proc.kill()
        sys.exit("Xvfb did not start")
    os.environ["DISPLAY"] = ":" + number
    return proc


def read_csv(path):
    with open(path) as f:
        first = f.readline()
    try:
        float(first.split(",")[0])
        has_header = False
    except ValueError:
        has_header = True
    data = np.loadtxt(path, delimiter=",", skiprows=1 if has_header else 0, ndmin=2)
    if data.shape[1] not in (2, 3, 6):
        sys.exit(f"{path}: {data.shape[1]} columns (expected 2, 3 or 6)")
    xyz = data[:, :3] if data.shape[1] >= 3 else np.column_stack([data, np.zeros(len(data))])
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.ascontiguousarray(xyz)))
    if data.shape[1] == 6:
        rgb = data[:, 3:6]
        if rgb.size and rgb.max() > 1.0:
            rgb = rgb / 255.0
        cloud.colors = o3d.utility.Vector3dVector(np.ascontiguousarray(rgb))
    return cloud


def load(path):
    if path.lower().endswith(".csv"):
        return read_csv(path)
    cloud = o3d.io.read_point_cloud(path)
    if not cloud.has_points():
        sys.exit(f"{path}: Open3D read no points")
    return cloud


def capture(cloud, out, width, height):
    vis = o3d.visualization.Visualizer()
    if not vis.create_window(window_name="open3d_capture", width=width, height=height, visible=False):
        sys.exit("Open3D could not create its (hidden) window: no usable X display / OpenGL")
    vis.add_geometry(cloud)
    vis.capture_screen_image(out, do_render=True)
    background = [float(c) for c in vis.get_render_option().background_color]
    vis.destroy_window()
    return background


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("input")
    ap.add_argument("output", help="PNG to write")
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--height", type=int, default=768)
    ap.add_argument("--json", help="write the timings to this file")
    args = ap.parse_args()
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    xvfb = None if os.environ.get("DISPLAY") else start_xvfb(args.width, args.height)
    try:
        t0 = time.perf_counter()
        cloud = load(args.input)
        t1 = time.perf_counter()
        background = capture(cloud, args.output, args.width, args.height)
        t2 = time.perf_counter()
    finally:
        if xvfb:
            xvfb.terminate()
            xvfb.wait()
    if not os.path.exists(args.output):
        sys.exit(f"Open3D wrote no {args.output}")
    result = {"points": len(cloud.points), "colours": cloud.has_colors(), "import_s": import_s,
              "load_s": t1 - t0, "capture_s": t2 - t1, "load_capture_s": t2 - t0,
              "width": args.width, "height": args.height,
              "background": background}
    print(f"{args.output}: {result['points']} points, Open3D {o3d.__version__} Visualizer(visible=False), "
          f"{args.width}x{args.height}, defaults")
    print(f"time (s): load {result['load_s']:.3f}, capture {result['capture_s']:.3f}, "
          f"load+capture {result['load_capture_s']:.3f} (import open3d {import_s:.3f}, not included)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
