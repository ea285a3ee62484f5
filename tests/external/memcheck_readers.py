"""Valgrind's memcheck judges that no unset byte of a point set is read or written: PointSet's
positions and colours (core/point_set.h) are sized without zeroing, so every reader and generator
must set each element itself. Each case runs `dpoint` under memcheck on small input of the kinds
that leave coordinates to fill (2D files without z, blank lines, NaN rows dropped, colours of some
parts only, tiles and their merge, streamed blocks); any memcheck error fails the test. Rendering is
left out: the dynamic loader's reads of the Vulkan driver's paths are flagged by memcheck itself."""
import os
import struct
import subprocess
import sys

from common import check, dpoint, scratch

exe = sys.argv[1]
HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "..", "..", "..", "shared", "corpus")
MEMCHECK = ["valgrind", "--tool=memcheck", "--error-exitcode=99", "--undef-value-errors=yes", "-q"]


def under_memcheck(*args):
    result = subprocess.run([*MEMCHECK, exe, *args, "-q", "--threads", "2"] if args[0] in ("convert", "generate", "merge")
                            else [*MEMCHECK, exe, *args], capture_output=True, text=True)
    check(result.returncode == 0 and "==" not in result.stderr,
          f"memcheck: dpoint {' '.join(args)} exited {result.returncode}:\n{result.stderr[-3000:]}")


def write_pcd(path, rows, data):
    with open(path, "wb") as f:
        f.write(b"# .PCD v0.7\nVERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\n")
        f.write(f"WIDTH {len(rows)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(rows)}\nDATA {data}\n".encode())
        if data == "ascii":
            f.write("".join(f"{x!r} {y!r}\n" for x, y in rows).encode())
        else:
            f.write(b"".join(struct.pack("<ff", x, y) for x, y in rows))


with scratch() as d:
    path = lambda name: os.path.join(d, name)
    rows = [(0.5 * i, 1.0 - 0.25 * i) for i in range(40)] + [(float("nan"), 2.0)]
    # 2D PCD, as PCL's PointXY clouds are (no z field): z is 0, never the unset memory.
    write_pcd(path("xy_binary.pcd"), rows, "binary")
    write_pcd(path("xy_ascii.pcd"), rows[:-1], "ascii")
    for name in ("xy_binary.pcd", "xy_ascii.pcd"):
        under_memcheck("convert", path(name), "-o", path(name + ".ply"))
        under_memcheck("info", path(name))
    # CSV with blank lines between rows, in 2 and 3 columns with colours and attribute columns
    # (whose values are not zeroed before the rows are parsed into them).
    with open(path("blank.csv"), "w") as f:
        f.write("x,y,z,r,g,b,intensity,quality\n1,2,3,10,20,30,7,0.5\n\n4,5,6,40,50,60,8,0.25\n   \n"
                "7,8,9,70,80,90,9,0.125\n")
    with open(path("two.xyz"), "w") as f:
        f.write("1 2\n\n3 4\n5 6\n")
    under_memcheck("convert", path("blank.csv"), "-o", path("blank.ply"))
    under_memcheck("convert", path("two.xyz"), "-o", path("two.pcd"))
    under_memcheck("convert", path("two.pcd"), "-o", path("two.csv"))
    # A 2D binary PLY (no z property), read whole and as the streamed renderer reads it.
    dpoint(exe, "convert", path("two.xyz"), "-o", path("two.ply"))
    under_memcheck("convert", path("two.ply"), "-o", path("two-back.csv"))
    under_memcheck("info", path("two.ply"), "--stream", "on")
    # Generators, whole and in tiles, and the merge that welds the tiles.
    under_memcheck("generate", "menger", "--level", "2", "-o", path("menger.ply"))
    under_memcheck("generate", "sierpinski", "--level", "3", "-o", path("sierpinski.csv"))
    for tile in ("0/2", "1/2"):
        under_memcheck("generate", "mandelbulb", "--resolution", "24", "--tile", tile, "-o", path(f"bulb{tile[0]}.ply"))
    under_memcheck("merge", path("bulb0.ply"), path("bulb1.ply"), "-o", path("bulb.ply"))
    under_memcheck("generate", "random2d", "--count", "3000", "--order", "morton", "-o", path("random.csv"))
    # LAS and LAZ, and glTF both ways.
    under_memcheck("convert", os.path.join(CORPUS, "las", "simple.las"), "-o", path("simple.ply"))
    under_memcheck("convert", os.path.join(CORPUS, "las", "simple.laz"), "-o", path("simplez.csv"))
    under_memcheck("convert", path("bulb.ply"), "-o", path("bulb.glb"))
    under_memcheck("convert", path("bulb.glb"), "-o", path("bulb-glb.csv"))
    # glTF read whole (its vertices placed on all cores into unset slots), and a LAS written from a
    # set without a LAS source (the merged-point count's unset entries).
    under_memcheck("convert", path("bulb.glb"), "-o", path("bulb-glb.ply"))
    under_memcheck("convert", path("bulb.ply"), "-o", path("bulb.las"))
    # PLY with dimension columns, binary and ASCII, read whole (vertex rows and their columns placed
    # on all cores into unset slots; ASCII faces fanned into them too) and written as LAS.
    dpoint(exe, "convert", path("simple.ply"), "--ply-ascii", "-o", path("simple-ascii.ply"))
    dpoint(exe, "convert", path("bulb.ply"), "--ply-ascii", "-o", path("bulb-ascii.ply"))
    under_memcheck("convert", path("simple.ply"), "-o", path("simple-back.las"))
    under_memcheck("convert", path("simple-ascii.ply"), "-o", path("simple-ascii-back.las"))
    under_memcheck("convert", path("bulb-ascii.ply"), "-o", path("bulb-ascii-back.ply"))
    # PCD with dimension columns (a LAS's fields), binary, compressed and ASCII, read whole.
    for encoding in ("binary", "binary_compressed", "ascii"):
        dpoint(exe, "convert", os.path.join(CORPUS, "las", "simple.las"), "--pcd-encoding", encoding,
               "-o", path(f"simple-{encoding}.pcd"))
        under_memcheck("convert", path(f"simple-{encoding}.pcd"), "-o", path(f"simple-{encoding}-back.las"))
    # PTX: two scans of other widths (the first without colours: white beside the second's), points
    # with no echo closed up, the rows read as slices of the file, and their 0..1 intensity to LAS.
    with open(path("scans.ptx"), "w") as f:
        ident = "1 0 0\n0 1 0\n0 0 1\n"
        f.write(f"2\n2\n5 6 7\n{ident}0 -1 0 0\n1 0 0 0\n0 0 1 0\n5 6 7 1\n"
                "1 2 3 0.5\n0 0 0 0.5\n4 5 6 0.25\n7 8 9 1\n"
                f"1\n1\n0 0 0\n{ident}1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n1.5 2.5 3.5 0.75 10 20 30\n")
    under_memcheck("convert", path("scans.ptx"), "-o", path("scans.las"))
    # E57: two scans joined (invalid points closed up, a pose, dimensions of other types), and a
    # spherical scan with 16-bit colours; their columns are sized without zeroing too.
    e57 = os.path.join(HERE, "..", "data", "e57")
    under_memcheck("convert", os.path.join(e57, "two_scans.e57"), "-o", path("two_scans.ply"))
    under_memcheck("convert", os.path.join(e57, "spherical.e57"), "-o", path("spherical.pcd"))
    under_memcheck("convert", os.path.join(e57, "spherical.e57"), "-o", path("spherical.e57"))  # written, packed
print("memcheck: no unset byte read or written in 31 runs")
