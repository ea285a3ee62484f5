"""laz-perf (npm: LASzip's codec compiled to WASM) judges every LAZ file dpoint writes (issue #35).

For each LAS file of the corpus (point formats 0-3 and 6-8, LAS 1.0-1.4, extra bytes, EVLRs), for
generated sets (2^20+ points across many chunks, a fractal with colours), for an empty set and one
point: `dpoint convert IN -o OUT.laz` and `-o OUT.las`; laz-perf decodes OUT.laz (one Node process
per file: it aborts the process on a bad file) and its records must equal OUT.las's byte for byte,
i.e. exactly the records dpoint meant. Usage: lazperf_reads_dpoint_laz.py DPOINT
"""
import glob
import os
import struct
import subprocess
import sys

from common import check, dpoint, scratch

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "..", "..", "..", "shared", "corpus")
SCRIPT = os.path.join(HERE, "node", "lazperf_records.mjs")


def las_records(path):
    data = open(path, "rb").read()
    offset, = struct.unpack_from("<I", data, 96)
    length, = struct.unpack_from("<H", data, 105)
    count, = struct.unpack_from("<I", data, 107)
    if data[25] >= 4:
        count64, = struct.unpack_from("<Q", data, 247)
        count = count64 or count
    return data[104] & 0x3F, data[offset:offset + count * length]


def lazperf_records(laz, out):
    result = subprocess.run(["node", SCRIPT, laz, out], capture_output=True, text=True)
    check(result.returncode == 0, f"laz-perf could not decode {laz} ({result.returncode}): {result.stderr[-2000:]}")
    return result.stdout.strip(), open(out, "rb").read()


def judge(exe, source, tmp, name):
    laz, las, raw = (os.path.join(tmp, name + ext) for ext in (".laz", ".las", ".bin"))
    dpoint(exe, "convert", source, "-o", laz)
    dpoint(exe, "convert", source, "-o", las)
    fmt, meant = las_records(las)
    if fmt in (4, 5, 9, 10):
        # LAZ holds no waveform format: dpoint writes its base format with the wave packet fields as
        # extra bytes. What it meant: those records, as its LAS writer gives them from the LAZ's
        # points; that every value came through is checked on their CSV (all dimensions).
        back, csv_a, csv_b = (os.path.join(tmp, name + ext) for ext in ("-back.las", "-a.csv", "-b.csv"))
        dpoint(exe, "convert", laz, "-o", back)
        dpoint(exe, "convert", las, "-o", csv_a)
        dpoint(exe, "convert", back, "-o", csv_b)
        check(open(csv_a).read() == open(csv_b).read(), f"{name}: format {fmt} through LAZ changes a value")
        fmt, meant = las_records(back)
    line, got = lazperf_records(laz, raw)
    check(got == meant, f"{name}: laz-perf's records differ from dpoint's ({len(got)} vs {len(meant)} bytes; {line})")
    ratio = os.path.getsize(laz) / max(1, os.path.getsize(las))
    print(f"{name}: format {fmt}, {len(meant)} record bytes, laz-perf agrees ({line}); LAZ/LAS size {ratio:.3f}")
    return fmt


def main():
    exe = sys.argv[1]
    formats = set()
    with scratch() as tmp:
        sources = sorted(glob.glob(os.path.join(CORPUS, "las", "*.las")) + glob.glob(os.path.join(CORPUS, "laz", "*.las")))
        check(len(sources) >= 15, f"the corpus has {len(sources)} LAS files")
        for i, source in enumerate(sources):
            formats.add(judge(exe, source, tmp, f"{i:02d}-{os.path.basename(source)[:-4]}"))
        # 2^20 + 1000 points: 22 chunks of 50,000.
        big = os.path.join(tmp, "random.ply")
        dpoint(exe, "generate", "random2d", "--count", str((1 << 20) + 1000), "--seed", "3", "-o", big)
        formats.add(judge(exe, big, tmp, "random2d-1049576"))
        menger = os.path.join(tmp, "menger.ply")
        dpoint(exe, "generate", "menger", "--level", "3", "-o", menger)
        formats.add(judge(exe, menger, tmp, "menger-3"))
        empty, one = os.path.join(tmp, "empty.csv"), os.path.join(tmp, "one.csv")
        open(empty, "w").write("x,y,z\n")
        open(one, "w").write("x,y,z,r,g,b\n637012.25,849028.5,431.75,0.5,0.25,1\n")
        # Format 8 (RGB and near infrared) with LAS 1.4 classes and GPS times from a CSV's columns.
        nir = os.path.join(tmp, "nir.csv")
        with open(nir, "w") as f:
            f.write("x,y,z,r,g,b,nir,classification,gps_time,intensity\n")
            for i in range(70000):
                f.write(f"{500000 + i * 0.01:.2f},{4000000 + (i * 7919) % 1000 * 0.01:.2f},{(i % 97) * 0.25:.2f},"
                        f"{(i % 256) / 255:.6f},{(i * 3 % 256) / 255:.6f},{0.5:.6f},{(i * 11) % 65536},"
                        f"{40 + i % 50},{300000.0 + i * 1e-5:.5f},{i % 4096}\n")
        formats.add(judge(exe, nir, tmp, "nir-70000"))
        formats.add(judge(exe, empty, tmp, "empty"))
        formats.add(judge(exe, one, tmp, "one-point"))
    print("point formats written and checked:", sorted(formats))
    check({0, 1, 2, 3, 6, 7, 8}.issubset(formats), f"formats 0-3 and 6-8 among those checked ({sorted(formats)})")


if __name__ == "__main__":
    main()
