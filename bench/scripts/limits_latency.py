#!/usr/bin/env python3
"""How fast the issue's resource-limit examples fail (issue #12): "within a second".

Usage: bench/scripts/limits_latency.py build/dpoint [REPEATS]

Runs each example of tests/cli/cli_limits_test.cpp (a PLY header claiming 10^12 vertices, glTF
accessors of 2^40 elements with and without a buffer view, `render --width 1000000`, `generate
--resolution 100000`) REPEATS times (default 5) on the same small inputs the test writes, timed
from start to exit (wall clock, the process's whole life: exec, Vulkan set-up where the command
makes a device, parse, refusal). Prints a Markdown table: exit codes seen, median and largest
time in ms, whether every run's one stderr line named the number, and files left in the output
folder. Tests assert no timings (project rule); this is where the second is checked.
"""
import os, shutil, statistics, subprocess, sys, tempfile, time


def write_inputs(folder):
    """The inputs of CliLimits.hugeCountsFailAtOnceNamingTheNumber, byte for byte."""
    with open(os.path.join(folder, "huge.ply"), "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
                b"property double x\nproperty double y\nproperty double z\nend_header\n" + b"\0" * 240)
    gltf = ('{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],'
            '"meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":0}]}],'
            '"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,' + "A" * 48 + '"}],'
            '"bufferViews":[{"buffer":0,"byteLength":36}],')
    with open(os.path.join(folder, "huge.gltf"), "w") as f:
        f.write(gltf + '"accessors":[{"bufferView":0,"componentType":5126,"count":1099511627776,"type":"VEC3"}]}')
    with open(os.path.join(folder, "unbacked.gltf"), "w") as f:
        f.write(gltf + '"accessors":[{"componentType":5126,"count":1099511627776,"type":"VEC3"}]}')
    with open(os.path.join(folder, "small.csv"), "w") as f:
        f.write("x,y\n0,0\n1,1\n")


def main():
    dpoint = os.path.abspath(sys.argv[1])
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    work = tempfile.mkdtemp(prefix="dpoint-limits-")
    inputs = os.path.join(work, "inputs")
    os.mkdir(inputs)
    write_inputs(inputs)
    source = lambda name: os.path.join(inputs, name)
    # (example, arguments with OUT for the output folder, the number the message must name)
    examples = [
        ("PLY header of 10^12 vertices (convert)", ["convert", source("huge.ply"), "-o", "OUT/out.csv"],
         "1000000000000"),
        ("glTF accessor of 2^40 in a 36-byte view (convert)", ["convert", source("huge.gltf"), "-o", "OUT/out.csv"],
         "1099511627776"),
        ("glTF accessor of 2^40 without a view (convert)", ["convert", source("unbacked.gltf"), "-o", "OUT/out.ply"],
         "1099511627776"),
        ("render --width 1000000", ["render", source("small.csv"), "-o", "OUT/out.png", "--width", "1000000"],
         "1000000x768"),
        ("generate mandelbulb --resolution 100000", ["generate", "mandelbulb", "--resolution", "100000", "-o",
                                                     "OUT/out.ply"], "100000"),
    ]
    try:
        run(dpoint, repeats, work, examples)
    finally:
        shutil.rmtree(work)


def run(dpoint, repeats, work, examples):
    print("| example | exit | median ms | max ms | one line naming the number | left |")
    print("| --- | --- | --- | --- | --- | --- |")
    for name, args, number in examples:
        times, codes, named, left = [], set(), True, 0
        for _ in range(repeats):
            out = tempfile.mkdtemp(dir=work)
            argv = [dpoint] + [out + a[3:] if a.startswith("OUT/") else a for a in args]
            t0 = time.monotonic()
            p = subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            times.append(1000 * (time.monotonic() - t0))
            codes.add(p.returncode)
            named = named and p.stderr.count("\n") == 1 and number in p.stderr
            left += len(os.listdir(out))
        print("| %s | %s | %.1f | %.1f | %s | %d |" % (name, ",".join(map(str, sorted(codes))),
                                                     statistics.median(times), max(times), "yes" if named else "NO",
                                                     left))


if __name__ == "__main__":
    main()
