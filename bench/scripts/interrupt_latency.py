#!/usr/bin/env python3
"""How fast every long command stops on SIGINT and SIGTERM (issue #12): generate (on the CPU, and
meshed by the device path), convert (glTF to CSV; to LAZ, COPC and PTX; LAZ decoded), info (whole
and streamed), render (whole and streamed), merge and bench.

Usage: bench/scripts/interrupt_latency.py build/dpoint [REPEATS] [NAME_PREFIX]

Each command is started on work that lasts seconds on one thread, signalled once it has used its
share of CPU (0.5 s, or more where the phase to stop in comes later), and timed from the signal to
its exit. Prints one JSON object: per command and signal the exit codes seen, the median and the
largest stop time in ms, and whether anything was left in the output folder. The watcher
(core/interrupt.h) forces the exit 500 ms after the signal, so a time near 500 ms means the work
did not poll in time and was cut short; under it, it stopped itself. The test suite's Ctrl-C test
(tests/cli/cli_interrupt_test.cpp) checks the exit codes and what is left, never the time: this
is where a stop that takes seconds shows.
"""
import json, os, shutil, signal, statistics, struct, subprocess, sys, tempfile, time


def cpu_seconds(pid):
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def instanced_glb(path, points=20000, instances=5000):
    """A 20,000-point mesh placed 5,000 times: 100M points of CSV from 300 KB."""
    binary = b"".join(struct.pack("<3f", i % 100, i // 100, 0.5) for i in range(points))
    binary += b"".join(struct.pack("<3f", 0, 0, i) for i in range(instances))
    doc = {"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 1}}}}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 0}]}],
           "buffers": [{"byteLength": len(binary)}],
           "bufferViews": [{"buffer": 0, "byteLength": 12 * points},
                           {"buffer": 0, "byteOffset": 12 * points, "byteLength": 12 * instances}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": points, "type": "VEC3"},
                         {"bufferView": 1, "componentType": 5126, "count": instances, "type": "VEC3"}]}
    js = json.dumps(doc).encode()
    js += b" " * ((4 - len(js) % 4) % 4)
    chunks = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(binary), 0x004E4942) + binary
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks)


def main():
    dpoint = os.path.abspath(sys.argv[1])
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    work = tempfile.mkdtemp(prefix="dpoint-interrupt-")
    inputs = os.path.join(work, "inputs")
    os.mkdir(inputs)
    instanced_glb(os.path.join(inputs, "in.glb"))
    i = lambda name: os.path.join(inputs, name)
    quiet = dict(check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    subprocess.run([dpoint, "generate", "random2d", "--count", "200000", "-o", i("in.ply"), "--quiet"], **quiet)
    subprocess.run([dpoint, "generate", "random2d", "--count", "6000000", "-o", i("big.ply"), "--quiet"], **quiet)
    subprocess.run([dpoint, "convert", i("big.ply"), "-o", i("big.laz"), "--quiet"], **quiet)
    for t in range(2):
        subprocess.run([dpoint, "generate", "mandelbulb", "--resolution", "500", "--tile", "%d/2" % t, "-o",
                        i("t%d.ply" % t), "--quiet"], **quiet)
    one = ["--threads", "1"]
    # name: (arguments given the output folder, CPU seconds used before the signal)
    commands = {
        "generate": (lambda out: ["generate", "mandelbulb", "--resolution", "1200", "-o", os.path.join(out, "out.ply")] + one, 0.5),
        "generate --mesh device": (lambda out: ["generate", "julia", "--resolution", "600", "--device", "cpu", "--mesh",
                                                "device", "-o", os.path.join(out, "out.ply")] + one, 0.5),
        "convert": (lambda out: ["convert", i("in.glb"), "-o", os.path.join(out, "out.csv")], 0.5),
        "convert to LAZ": (lambda out: ["convert", i("big.ply"), "-o", os.path.join(out, "out.laz")] + one, 0.5),
        "convert to COPC": (lambda out: ["convert", i("big.ply"), "-o", os.path.join(out, "out.copc.laz")] + one, 2.0),
        "convert to PTX": (lambda out: ["convert", i("big.ply"), "-o", os.path.join(out, "out.ptx")] + one, 0.5),
        "convert LAZ": (lambda out: ["convert", i("big.laz"), "-o", os.path.join(out, "out.ply")] + one, 0.5),
        "info": (lambda out: ["info", i("big.laz"), "--stream", "off"] + one, 0.5),
        "info --stream": (lambda out: ["info", i("big.laz"), "--stream", "on"] + one, 0.5),
        "render": (lambda out: ["render", i("in.ply"), "-o", os.path.join(out, "out.png"), "--frames", "1000000"], 0.5),
        "render --stream": (lambda out: ["render", i("big.laz"), "--stream", "on", "-o", os.path.join(out, "out.png"),
                                         "--width", "320", "--height", "240", "--frames", "1000000"] + one, 0.5),
        "merge": (lambda out: ["merge", i("t0.ply"), i("t1.ply"), "-o", os.path.join(out, "out.laz")] + one, 0.5),
        "bench": (lambda out: ["bench", "--suite", "ci", "--out", os.path.join(out, "report"), "--cache",
                               os.path.join(out, "cache"), "--no-copy-bandwidth"], 0.5),
    }
    prefix = sys.argv[3] if len(sys.argv) > 3 else ""
    results = {}
    for name, (args, cpu) in commands.items():
        if not name.startswith(prefix):
            continue
        for sig in (signal.SIGINT, signal.SIGTERM):
            times, codes, left = [], set(), []
            for r in range(repeats):
                out = tempfile.mkdtemp(dir=work)
                p = subprocess.Popen([dpoint] + args(out), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                while p.poll() is None and cpu_seconds(p.pid) < cpu:
                    time.sleep(0.01)
                if p.poll() is not None:
                    sys.exit("%s ended before it was signalled: make its work longer" % name)
                t0 = time.monotonic()
                p.send_signal(sig)
                codes.add(p.wait())
                times.append(1000 * (time.monotonic() - t0))
                for root, _, files in os.walk(out):
                    # A bench's finished datasets stay in its cache, made to be reused.
                    left += [os.path.join(root, f) for f in files
                             if not root.endswith("cache") or ".dpoint-" in f]
            results["%s %s" % (name, sig.name)] = {
                "exit_codes": sorted(codes), "stop_ms_median": round(statistics.median(times), 1),
                "stop_ms_max": round(max(times), 1), "left_behind": left}
    shutil.rmtree(work)
    print(json.dumps({"repeats": repeats, "results": results}, indent=1))


if __name__ == "__main__":
    main()
