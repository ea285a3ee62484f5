#!/usr/bin/env python3
"""How fast generate, convert, render and bench stop on SIGINT and SIGTERM (issue #12).

Usage: bench/scripts/interrupt_latency.py build/dpoint [REPEATS]

Each command is started on work that lasts many seconds, signalled once it has used 0.5 s of CPU,
and timed from the signal to its exit. Prints one JSON object: per command and signal the exit
codes seen, the median and the largest stop time in ms, and whether anything was left in the
output folder. The watcher (core/interrupt.h) forces the exit 500 ms after the signal, so a time
near 500 ms means the work did not poll in time and was cut short; under it, it stopped itself.
"""
import json, os, signal, statistics, struct, subprocess, sys, tempfile, time


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
    subprocess.run([dpoint, "generate", "random2d", "--count", "200000", "-o", os.path.join(inputs, "in.ply"),
                    "--quiet"], check=True)
    commands = {
        "generate": lambda out: ["generate", "mandelbulb", "--resolution", "1200", "--threads", "1", "-o",
                                 os.path.join(out, "out.ply")],
        "convert": lambda out: ["convert", os.path.join(inputs, "in.glb"), "-o", os.path.join(out, "out.csv")],
        "render": lambda out: ["render", os.path.join(inputs, "in.ply"), "-o", os.path.join(out, "out.png"),
                               "--frames", "1000000"],
        "bench": lambda out: ["bench", "--suite", "ci", "--out", os.path.join(out, "report"), "--cache",
                              os.path.join(out, "cache"), "--no-copy-bandwidth"],
    }
    results = {}
    for name, args in commands.items():
        for sig in (signal.SIGINT, signal.SIGTERM):
            times, codes, left = [], set(), []
            for r in range(repeats):
                out = tempfile.mkdtemp(dir=work)
                p = subprocess.Popen([dpoint] + args(out), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                while p.poll() is None and cpu_seconds(p.pid) < 0.5:
                    time.sleep(0.01)
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
    print(json.dumps({"repeats": repeats, "results": results}, indent=1))


if __name__ == "__main__":
    main()
