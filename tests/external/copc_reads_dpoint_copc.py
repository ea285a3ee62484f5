"""The npm `copc` package (copc.js, the reader behind viewer.copc.io) judges the COPC files dpoint writes
(issue #35): tests/external/node/copc_walk.mjs walks each file's hierarchy through every page, decodes
every node and checks that its points lie in its node's cube and that the counts add up to the
header's; laz-perf reads each as plain LAZ to the header's count.

The files: those the converter tests write (CONVERTERS_TESTS with DPOINT_COPC_OUT: the corpus's LAS 1.4
files, a 300,000-point surface, a paged hierarchy, 0 and 1 point), and what `dpoint convert` and
`generate` write as .copc.laz: the corpus's LAS 1.4 files, a fractal and 400,000 random points (each
compared, as sorted records, with the same source converted to LAS).

COPC holds point formats 6-8, whose CRS is WKT alone: LAS 1.2 files whose CRS is GeoTIFF keys (the
corpus's 1815.las, EPSG:6580 + EPSG:5703; point-time.las, EPSG:26910 beside a libLAS WKT record) become COPC files
whose WKT copc.js finds and pyproj (PROJ's Python binding) reads as the same CRS; so does a CSV given
one with `--crs EPSG:32633`.
Usage: copc_reads_dpoint_copc.py DPOINT [CONVERTERS_TESTS]
"""
import glob
import json
import os
import struct
import subprocess
import sys

from common import check, dpoint, scratch

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "..", "..", "..", "shared", "corpus")
WALK = os.path.join(HERE, "node", "copc_walk.mjs")
LAZPERF = os.path.join(HERE, "node", "lazperf_records.mjs")


def header(path):
    data = open(path, "rb").read(375)
    count, = struct.unpack_from("<Q", data, 247)
    length, = struct.unpack_from("<H", data, 105)
    return data[104] & 0x3F, length, count


def is_copc(path):
    """The info VLR (user "copc", record 1) at byte 375."""
    data = open(path, "rb").read(400)
    return len(data) == 400 and data[:4] == b"LASF" and data[377:382] == b"copc\0" and data[393:395] == b"\x01\x00"


def sorted_records(data, length):
    return sorted(data[i:i + length] for i in range(0, len(data), length))


def las_records(path):
    data = open(path, "rb").read()
    offset, = struct.unpack_from("<I", data, 96)
    _, length, count = header(path)
    return data[offset:offset + count * length]


def walk(files):
    result = subprocess.run(["node", WALK, *files], capture_output=True, text=True)
    print(result.stdout, end="")
    check(result.returncode == 0, f"copc.js rejects dpoint's COPC: {result.stderr[-3000:]}")
    return result.stdout


def lazperf_reads(path, tmp):
    """laz-perf reads the COPC file as plain LAZ; returns its records."""
    out = os.path.join(tmp, os.path.basename(path) + ".bin")
    result = subprocess.run(["node", LAZPERF, path, out], capture_output=True, text=True)
    check(result.returncode == 0, f"laz-perf cannot read {path} as LAZ ({result.returncode}): {result.stderr[-2000:]}")
    _, length, count = header(path)
    check(f"count={count}" in result.stdout, f"{path}: laz-perf read {result.stdout.strip()}, the header says {count}")
    return open(out, "rb").read()


def from_converter_tests(tests, tmp):
    folder = os.path.join(tmp, "from-tests")
    os.mkdir(folder)
    env = dict(os.environ, DPOINT_COPC_OUT=folder)
    result = subprocess.run([tests, "--gtest_filter=CopcWrite.*"], capture_output=True, text=True, env=env)
    check(result.returncode == 0, f"the COPC writer's tests fail: {result.stdout[-3000:]}")
    files = sorted(glob.glob(os.path.join(folder, "*.copc.laz")))
    check(len(files) >= 7, f"the converter tests wrote {len(files)} COPC files")
    return files


def from_dpoint(exe, tmp):
    """COPC files `dpoint convert` and `dpoint generate` write, with the LAS twin of each."""
    sources = [os.path.join(CORPUS, "las", "simple1_4.las"), os.path.join(CORPUS, "laz", "rand1_6.las"),
               os.path.join(CORPUS, "las", "1_4_w_evlr.las"), os.path.join(CORPUS, "las", "test1_4.las")]
    probe_path = os.path.join(tmp, "probe.copc.laz")
    probe = subprocess.run([exe, "convert", sources[0], "-o", probe_path], capture_output=True, text=True)
    check(probe.returncode == 0, f"`dpoint convert X -o Y.copc.laz` fails: {probe.stderr.strip()[:300]}")
    check(is_copc(probe_path), "`dpoint convert X -o Y.copc.laz` did not write COPC (no info VLR at byte 375)")
    # A fractal and 400,000 random points (several levels of nodes), written by generate itself. A
    # LAS 1.4 source's twin is its own .las (the same records); a generated set's (its format 2
    # becomes COPC's 7) is the COPC file converted back to .las, as dpoint reads it.
    menger = os.path.join(tmp, "menger.copc.laz")
    dpoint(exe, "generate", "menger", "--level", "4", "-q", "-o", menger)
    random = os.path.join(tmp, "random.copc.laz")
    dpoint(exe, "generate", "random2d", "--count", "400000", "--seed", "5", "-q", "-o", random)
    files = []
    for i, source in enumerate(sources):
        name = f"dpoint-{i:02d}-{os.path.basename(source).rsplit('.', 1)[0]}"
        copc, las = os.path.join(tmp, name + ".copc.laz"), os.path.join(tmp, name + ".las")
        dpoint(exe, "convert", source, "-o", copc)
        dpoint(exe, "convert", source, "-o", las)
        files.append((copc, las))
    for copc in (menger, random):
        las = copc[:-len(".copc.laz")] + "-back.las"
        dpoint(exe, "convert", copc, "-o", las)
        files.append((copc, las))
    return files


def walked_wkt(output, path):
    """The WKT copc_walk.mjs printed for the file (None when copc.js found none)."""
    for line in output.splitlines():
        if line.startswith(os.path.basename(path) + ":"):
            return json.loads(line.split(" wkt=", 1)[1])
    check(False, f"copc.js printed no line for {path}")


def crs_kept(exe, tmp):
    """LAS 1.2 CRS records (GeoTIFF keys, libLAS WKT) reach COPC as WKT that copc.js and pyproj read."""
    import pyproj  # Debian's python3-pyproj (scripts/setup)
    cases = [("laz/1815.las", lambda crs: [s.to_epsg() for s in crs.sub_crs_list] == [6580, 5703],
              "a compound CRS of EPSG:6580 and EPSG:5703"),
             ("laz/point-time.las", lambda crs: crs.to_epsg() == 26910,
              "EPSG:26910, its GeoTIFF keys' (the libLAS WKT beside them is not the LAS 1.2 record)")]
    files = []
    for source, _, _ in cases:
        out = os.path.join(tmp, "crs-" + os.path.basename(source)[:-4] + ".copc.laz")
        result = subprocess.run([exe, "convert", os.path.join(CORPUS, source), "-o", out], capture_output=True, text=True)
        check(result.returncode == 0, f"convert {source} to COPC fails: {result.stderr[-1000:]}")
        check("holds its CRS as WKT" in result.stderr, f"convert {source}: no note on its CRS: {result.stderr!r}")
        files.append(out)
    # A CSV, which has no CRS, given one with --crs.
    csv = os.path.join(tmp, "utm33.csv")
    with open(csv, "w") as f:
        f.write("x,y,z\n" + "".join(f"{500000 + i * 0.25},{5400000 + i * 0.5},{i % 7}\n" for i in range(1000)))
    out = os.path.join(tmp, "crs-utm33.copc.laz")
    dpoint(exe, "convert", csv, "--crs", "EPSG:32633", "-o", out)
    cases.append(("utm33.csv --crs EPSG:32633", lambda crs: crs.to_epsg() == 32633, "EPSG:32633"))
    files.append(out)
    output = walk(files)
    for (source, judge, meant), path in zip(cases, files):
        wkt = walked_wkt(output, path)
        check(wkt is not None, f"{path}: copc.js finds no WKT (the source {source} has a CRS)")
        crs = pyproj.CRS.from_wkt(wkt)
        check(judge(crs), f"{path}: pyproj reads the WKT as {crs.name!r}, not {meant}")
        print(f"{os.path.basename(path)}: copc.js's WKT is {crs.name!r} ({meant}) for pyproj")
    return len(files)


def main():
    exe = sys.argv[1]
    tests = sys.argv[2] if len(sys.argv) > 2 else None
    checked = 0
    with scratch() as tmp:
        if tests:
            files = from_converter_tests(tests, tmp)
            walk(files)
            for path in files:
                lazperf_reads(path, tmp)
            checked += len(files)
        converted = from_dpoint(exe, tmp)
        if converted:
            walk([copc for copc, _ in converted])
            for copc, las in converted:
                fmt, length, count = header(copc)
                check(fmt in (6, 7, 8), f"{copc}: point format {fmt} (COPC holds 6 to 8)")
                got = lazperf_reads(copc, tmp)
                meant = las_records(las)
                check(sorted_records(got, length) == sorted_records(meant, length),
                      f"{copc}: laz-perf's records differ from the LAS twin's ({len(got)} vs {len(meant)} bytes)")
                print(f"{os.path.basename(copc)}: {count} points, the records of its LAS twin, "
                      f"{os.path.getsize(copc) / max(1, os.path.getsize(las)):.3f} of its size")
            checked += len(converted)
        checked += crs_kept(exe, tmp)
    check(checked > 0, "no COPC file was checked (pass CONVERTERS_TESTS, or let dpoint write .copc.laz)")
    print(f"{checked} COPC files pass copc.js's walk and read as plain LAZ")


if __name__ == "__main__":
    main()
