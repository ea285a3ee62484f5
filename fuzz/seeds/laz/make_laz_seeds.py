#!/usr/bin/env python3
"""Writes the small LAZ seeds beside this script (committed; rerun to remake them):
    fuzz/seeds/laz/make_laz_seeds.py [DPOINT]   (DPOINT: a built dpoint, default build/dpoint)

The corpus' .laz files (../shared/corpus/laz) hold 1,065 to 110,000 points each: every input the
fuzzer tries decodes all of them, which is slow under the sanitizers, and the one multi-chunk file
(autzen_trim.laz, 600 KB) is past any sensible -max_len. These seeds are the same files cut to a
few points: each chunk is a prefix of one of the file's chunks (an arithmetic code decodes its
first k points from its first bytes alone), ended where dpoint's decoder has read the k points,
with a new chunk table (LASzip's encoder, written here for the table's few integers) and only the
laszip VLR (and the extra bytes one). Between them they reach fixed and variable chunks, several
chunks, a table written at the file's end (offset -1), LAS 1.2 and 1.4 headers and point formats
0-3 with extra bytes. Each is checked to read, through `dpoint convert`, as exactly the twin .las's
rows it was cut from.

Where a chunk's k points end is asked of dpoint itself: given more bytes than k points need, it
says how many are left over. The encoder below follows LASzip's arithmeticencoder.cpp and
integercompressor.cpp (Apache 2.0); the models are converters/laz_codec.cpp's.
"""
import os, re, struct, subprocess, sys, tempfile

here = os.path.dirname(os.path.abspath(__file__))
top = os.path.dirname(os.path.dirname(os.path.dirname(here)))
corpus = os.path.join(top, "..", "shared", "corpus", "laz")
dpoint = sys.argv[1] if len(sys.argv) > 1 else os.path.join(top, "build", "dpoint")
M32 = 0xFFFFFFFF
MIN_LENGTH = 1 << 24


# ---- LASzip's models, encoder and integer compressor (just what a chunk table needs) ----
class SymbolModel:
    def __init__(self, n):
        self.n, self.last = n, n - 1
        self.total, self.cycle, self.counts = 0, n, [1] * n
        self.update()
        self.until = self.cycle = (n + 6) >> 1

    def update(self):
        self.total += self.cycle
        if self.total > 1 << 15:
            self.counts = [(c + 1) >> 1 for c in self.counts]
            self.total = sum(self.counts)
        scale, s, self.dist = 0x80000000 // self.total, 0, []
        for c in self.counts:
            self.dist.append((scale * s) >> 16)
            s += c
        self.cycle = min((5 * self.cycle) >> 2, (self.n + 6) << 3)
        self.until = self.cycle

    def count(self, sym):
        self.counts[sym] += 1
        self.until -= 1
        if self.until == 0:
            self.update()


class BitModel:
    def __init__(self):
        self.zeros, self.total, self.p0, self.cycle, self.until = 1, 2, 1 << 12, 4, 4

    def count(self, bit):
        self.zeros += bit == 0
        self.until -= 1
        if self.until:
            return
        self.total += self.cycle
        if self.total > 1 << 13:
            self.total, self.zeros = (self.total + 1) >> 1, (self.zeros + 1) >> 1
            self.total += self.zeros == self.total
        self.p0 = (self.zeros * (0x80000000 // self.total)) >> 18
        self.cycle = self.until = min((5 * self.cycle) >> 2, 64)


class Encoder:
    def __init__(self):
        self.base, self.length, self.out = 0, M32, bytearray()

    def _add(self, x):
        before, self.base = self.base, (self.base + x) & M32
        if before > self.base:  # carry into the bytes already written
            p = len(self.out) - 1
            while self.out[p] == 0xFF:
                self.out[p] = 0
                p -= 1
            self.out[p] += 1

    def _renorm(self):
        while self.length < MIN_LENGTH:
            self.out.append(self.base >> 24)
            self.base = (self.base << 8) & M32
            self.length = (self.length << 8) & M32

    def symbol(self, m, sym):
        if sym == m.last:
            x = m.dist[sym] * (self.length >> 15)
            self._add(x)
            self.length -= x
        else:
            self.length >>= 15
            x = m.dist[sym] * self.length
            self._add(x)
            self.length = m.dist[sym + 1] * self.length - x
        self._renorm()
        m.count(sym)

    def bit(self, m, b):
        x = m.p0 * (self.length >> 13)
        if b == 0:
            self.length = x
        else:
            self._add(x)
            self.length -= x
        self._renorm()
        m.count(b)

    def bits(self, n, v):
        if n > 19:
            self.bits(16, v & 0xFFFF)
            v, n = v >> 16, n - 16
        self.length >>= n
        self._add(v * self.length)
        self._renorm()

    def done(self):
        another = self.length > 2 * MIN_LENGTH
        if another:
            self._add(MIN_LENGTH)
            self.length = MIN_LENGTH >> 1
        else:
            self._add(MIN_LENGTH >> 1)
            self.length = MIN_LENGTH >> 9
        self._renorm()
        return bytes(self.out) + b"\0" * (3 if another else 2)


class Decoder:  # to read the corpus files' chunk tables
    def __init__(self, data):
        self.data, self.pos, self.length = data, 4, M32
        self.value = int.from_bytes(data[:4], "big")

    def _renorm(self):
        while self.length < MIN_LENGTH:
            byte = self.data[self.pos] if self.pos < len(self.data) else 0
            self.pos += 1
            self.value = ((self.value << 8) | byte) & M32
            self.length = (self.length << 8) & M32

    def symbol(self, m):
        unit = self.length >> 15
        sym = max(k for k in range(m.n) if m.dist[k] * unit <= self.value)
        x = m.dist[sym] * unit
        y = self.length if sym == m.last else m.dist[sym + 1] * unit
        self.value -= x
        self.length = y - x
        self._renorm()
        m.count(sym)
        return sym

    def bit(self, m):
        x = m.p0 * (self.length >> 13)
        b = int(self.value >= x)
        if b:
            self.value -= x
            self.length -= x
        else:
            self.length = x
        self._renorm()
        m.count(b)
        return b

    def bits(self, n):
        if n > 19:
            low = self.bits(16)
            return (self.bits(n - 16) << 16) | low
        self.length >>= n
        v = self.value // self.length
        self.value -= self.length * v
        self._renorm()
        return v


class IntegerCompressor:  # 32 bits, no range: the chunk table's
    def __init__(self, contexts):
        self.classes = [SymbolModel(33) for _ in range(contexts)]
        self.zero = BitModel()
        self.correctors = [SymbolModel(1 << min(k, 8)) for k in range(1, 33)]

    def compress(self, enc, pred, real, context):
        c = ((real - pred + (1 << 31)) & M32) - (1 << 31)
        k = (-c if c <= 0 else c - 1).bit_length()
        enc.symbol(self.classes[context], k)
        if k == 0:
            enc.bit(self.zero, c)
        elif k < 32:
            c = c + (1 << k) - 1 if c < 0 else c - 1
            if k <= 8:
                enc.symbol(self.correctors[k - 1], c)
            else:
                enc.symbol(self.correctors[k - 1], c >> (k - 8))
                enc.bits(k - 8, c & ((1 << (k - 8)) - 1))


    def decompress(self, dec, pred, context):
        k = dec.symbol(self.classes[context])
        if k == 0:
            c = dec.bit(self.zero)
        elif k < 32:
            if k <= 8:
                c = dec.symbol(self.correctors[k - 1])
            else:
                c = dec.symbol(self.correctors[k - 1]) << (k - 8)
                c |= dec.bits(k - 8)
            c = c + 1 if c >= 1 << (k - 1) else c - ((1 << k) - 1)
        else:
            c = -(1 << 31)
        return ((pred + c + (1 << 31)) & M32) - (1 << 31)


def chunk_table(chunks, variable):
    """The table's bytes: version 0, count, then the coded (points,) bytes of each chunk."""
    enc, ic, last_points, last_bytes = Encoder(), IntegerCompressor(2), 0, 0
    for points, size in chunks:
        if variable:
            ic.compress(enc, last_points, points, 0)
            last_points = points
        ic.compress(enc, last_bytes, size, 1)
        last_bytes = size
    return struct.pack("<II", 0, len(chunks)) + enc.done()


# ---- Cutting a corpus file ----
def vlrs_of(b):
    """(header size, [(offset, total bytes, user id, record id)]) of the VLRs."""
    at, out = struct.unpack_from("<H", b, 94)[0], []
    for _ in range(struct.unpack_from("<I", b, 100)[0]):
        size = 54 + struct.unpack_from("<H", b, at + 20)[0]
        out.append((at, size, b[at + 2:at + 18].rstrip(b"\0"), struct.unpack_from("<H", b, at + 18)[0]))
        at += size
    return struct.unpack_from("<H", b, 94)[0], out


def convert_error(data):
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "cut.laz")
        with open(path, "wb") as f:
            f.write(data)
        r = subprocess.run([dpoint, "convert", path, "-o", os.path.join(d, "out.csv"), "-q"],
                           capture_output=True, text=True)
        if r.returncode == 0:
            with open(os.path.join(d, "out.csv")) as f:
                return None, f.read()
        return r.stderr.strip(), None


def assemble(b, keep, chunks, chunk_size, count, at_end):
    """A LAZ file: b's header and the VLRs `keep` accepts, the laszip VLR's chunk size set, the
    header's count(s) set to `count`, then `chunks` (Chunk: the bytes, with .points) and their
    table (after the chunks, or at the file's end with the offset -1 before the chunks)."""
    header_size, vlrs = vlrs_of(b)
    head = bytearray(b[:header_size])
    kept = b"".join(b[at:at + size] for at, size, uid, rid in vlrs if uid == b"laszip encoded" or keep(uid, rid))
    vlr_count = sum(1 for _, _, uid, rid in vlrs if uid == b"laszip encoded" or keep(uid, rid))
    body = bytearray(kept)
    # The laszip VLR's chunk size, found again in the kept bytes.
    at = 0
    while at < len(body):
        if body[at + 2:at + 18].rstrip(b"\0") == b"laszip encoded":
            struct.pack_into("<I", body, at + 54 + 12, chunk_size)
        at += 54 + struct.unpack_from("<H", body, at + 20)[0]
    point_offset = header_size + len(body)
    struct.pack_into("<I", head, 96, point_offset)
    struct.pack_into("<I", head, 100, vlr_count)
    struct.pack_into("<I", head, 107, count)
    struct.pack_into("<5I", head, 111, count, 0, 0, 0, 0)  # points by return: all first returns
    if head[25] >= 4:
        struct.pack_into("<Q", head, 247, count)
        struct.pack_into("<15Q", head, 255, count, *([0] * 14))
    data = b"".join(c for c in chunks)
    table_at = point_offset + 8 + len(data)
    table = chunk_table([(c.points, len(c)) for c in chunks], chunk_size == M32)
    if at_end:
        return bytes(head) + bytes(body) + struct.pack("<q", -1) + data + table + struct.pack("<q", table_at)
    return bytes(head) + bytes(body) + struct.pack("<q", table_at) + data + table


class Chunk(bytes):
    points = 0


def chunk(data, points):
    c = Chunk(data)
    c.points = points
    return c


LEFT = re.compile(r"chunk (\d+) of \d+ \((\d+) bytes at byte (\d+).*: (\d+) of the chunk's \d+ bytes are left over")


def cut(name, source, parts, chunk_size, keep=lambda uid, rid: False, at_end=False):
    """`parts`: [(source chunk's start, its bytes, points)], each cut to the bytes its points need."""
    b = open(os.path.join(corpus, source), "rb").read()
    chunks = [chunk(b[start:start + size], points) for start, size, points in parts]
    count = sum(c.points for c in chunks)
    while True:
        data = assemble(b, keep, chunks, chunk_size, count, at_end)
        err, csv = convert_error(data)
        if err is None:
            break
        m = LEFT.search(err)
        if not m:
            sys.exit("make_laz_seeds: %s: %s" % (name, err))
        i, left = int(m.group(1)), int(m.group(4))
        chunks[i] = chunk(chunks[i][:len(chunks[i]) - left], chunks[i].points)
    with open(os.path.join(here, name), "wb") as f:
        f.write(data)
    return csv


def rows(csv):
    lines = csv.splitlines()
    return lines[0], lines[1:]


def source_chunks(source):
    """[(start, bytes)] of a corpus file's chunks, from its chunk table."""
    b = open(os.path.join(corpus, source), "rb").read()
    po = struct.unpack_from("<I", b, 96)[0]
    table = struct.unpack_from("<q", b, po)[0]
    version, count = struct.unpack_from("<II", b, table)
    assert version == 0
    dec, ic, size, at, out = Decoder(b[table + 8:]), IntegerCompressor(2), 0, po + 8, []
    for _ in range(count):  # the corpus' files have fixed chunks: byte counts only
        size = ic.decompress(dec, size, 1)
        out.append((at, size))
        at += size
    assert at == table, source
    return out


def check(name, twin, csv, picks):
    """The cut file's rows are the twin's rows `picks`."""
    err, full = convert_error(open(os.path.join(corpus, twin), "rb").read())
    assert err is None, err
    head, want = rows(full)
    got_head, got = rows(csv)
    assert got_head == head, (name, got_head, head)
    expected = [want[i] for i in picks]
    assert got == expected, name


made = []
(start, size), = source_chunks("point10.las.laz")
csv = cut("format0_5_points.laz", "point10.las.laz", [(start, size, 5)], 50000)
check("format0_5_points.laz", "point10.las", csv, range(5))
made.append("format0_5_points.laz")

(start, size), = source_chunks("point-time-1.4.las.laz")
csv = cut("las14_format1_4_points.laz", "point-time-1.4.las.laz", [(start, size, 4)], 50000)
check("las14_format1_4_points.laz", "point-time.las", csv, range(4))
made.append("las14_format1_4_points.laz")

(start, size), = source_chunks("point-color.las.laz")
csv = cut("format2_6_points_table_at_end.laz", "point-color.las.laz", [(start, size, 6)], 50000, at_end=True)
check("format2_6_points_table_at_end.laz", "point-color.las", csv, range(6))
made.append("format2_6_points_table_at_end.laz")

(start, size), = source_chunks("extrabytes.laz")
csv = cut("format3_extra_bytes_3_points.laz", "extrabytes.laz", [(start, size, 3)], 50000,
          keep=lambda uid, rid: uid == b"LASF_Spec" and rid == 4)
check("format3_extra_bytes_3_points.laz", "extrabytes.las", csv, range(3))
made.append("format3_extra_bytes_3_points.laz")

a = source_chunks("autzen_trim.laz")
# Fixed chunks of 8 points: 8, 8 and a last one of 5, each the start of one of autzen's chunks.
csv = cut("format3_fixed_chunks_8_8_5.laz", "autzen_trim.laz",
          [(a[0][0], a[0][1], 8), (a[1][0], a[1][1], 8), (a[2][0], a[2][1], 5)], 8)
check("format3_fixed_chunks_8_8_5.laz", "autzen_trim.las", csv,
      list(range(8)) + list(range(50000, 50008)) + list(range(100000, 100005)))
made.append("format3_fixed_chunks_8_8_5.laz")
# Variable chunks (chunk size 0xFFFFFFFF): 7, 12 and 4 points, the table giving each its count.
csv = cut("format3_variable_chunks_7_12_4.laz", "autzen_trim.laz",
          [(a[0][0], a[0][1], 7), (a[1][0], a[1][1], 12), (a[2][0], a[2][1], 4)], M32)
check("format3_variable_chunks_7_12_4.laz", "autzen_trim.las", csv,
      list(range(7)) + list(range(50000, 50012)) + list(range(100000, 100004)))
made.append("format3_variable_chunks_7_12_4.laz")

print("make_laz_seeds: wrote %s (each reads as its twin's rows)" % ", ".join(
    "%s (%d bytes)" % (n, os.path.getsize(os.path.join(here, n))) for n in made))
