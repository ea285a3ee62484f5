"""PointSet.attributes (issue #34): a LAS file's fields and extra bytes as NumPy views in their own
dtypes, kept through dpoint.write: LAS -> Python -> LAS writes the same point records."""
import pathlib
import struct

import numpy as np

import dpoint

CORPUS = pathlib.Path(__file__).resolve().parents[2].parent / "shared" / "corpus"


def records(path):
    """The point record bytes of a LAS file, with its point format."""
    b = pathlib.Path(path).read_bytes()
    offset, = struct.unpack_from("<I", b, 96)
    length, = struct.unpack_from("<H", b, 105)
    count, = struct.unpack_from("<I", b, 107)
    if b[25] >= 4 and struct.unpack_from("<Q", b, 247)[0]:
        count, = struct.unpack_from("<Q", b, 247)
    return b[104], b[offset:offset + length * count]


def test_las_fields_are_attributes_in_their_own_dtypes():
    s = dpoint.read(CORPUS / "las" / "simple.las")
    a = s.attributes
    assert a["intensity"].dtype == np.uint16 and a["intensity"][0] == 143
    assert a["classification"].dtype == np.uint8 and a["classification"][0] == 1
    assert a["gps_time"].dtype == np.float64 and len(a["gps_time"]) == len(s)
    assert a["scan_angle_rank"].dtype == np.int8


def test_las_to_python_to_las_writes_the_same_records(tmp_path):
    for path in sorted((CORPUS / "las").glob("*.las")) + sorted((CORPUS / "laz").glob("*.las")):
        s = dpoint.read(path)
        dpoint.write(s, tmp_path / "back.las")
        assert records(tmp_path / "back.las") == records(path), path.name


def test_attributes_are_views_whose_changes_are_written(tmp_path):
    s = dpoint.read(CORPUS / "las" / "simple.las")
    classes = s.attributes["classification"]
    classes[:] = 6  # every point a building
    assert (s.attributes["classification"] == 6).all()
    dpoint.write(s, tmp_path / "b.las")
    assert (dpoint.read(tmp_path / "b.las").attributes["classification"] == 6).all()
    assert dpoint.PointSet(np.zeros((2, 3))).attributes == {}
