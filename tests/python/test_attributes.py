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


def same_values(a, b):
    """Equal value for value, NaN equal to NaN (rand1_6.las has NaN GPS times)."""
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype.kind == "f" or b.dtype.kind == "f":
        return np.array_equal(a.astype("float64"), b.astype("float64"), equal_nan=True)
    return np.array_equal(a, b)


def test_las_to_dataframe_to_las_keeps_every_field(tmp_path):
    for path in sorted((CORPUS / "las").glob("*.las")) + sorted((CORPUS / "laz").glob("*.las")):
        s = dpoint.read(path)
        frame = s.to_dataframe()
        assert list(frame.columns)[:3] == ["x", "y", "z"], path.name
        for name, values in s.attributes.items():
            assert frame[name].dtype == values.dtype, (path.name, name)
        t = dpoint.PointSet.from_dataframe(frame)
        assert t.attributes.keys() == s.attributes.keys(), path.name
        dpoint.write(t, tmp_path / "back.las")
        back = dpoint.read(tmp_path / "back.las")
        for name, values in s.attributes.items():
            assert same_values(back.attributes[name], values), (path.name, name)
        # The coordinates are the same integers of the file's own frame (the frame itself stays
        # with the file: a DataFrame has no place for it).
        header = pathlib.Path(path).read_bytes()
        scale = np.array(struct.unpack_from("<3d", header, 131))
        offset = np.array(struct.unpack_from("<3d", header, 155))
        assert np.array_equal(np.rint((back.positions - offset) / scale), np.rint((s.positions - offset) / scale)), path.name


def test_set_and_remove_attribute(tmp_path):
    s = dpoint.PointSet(np.array([[0.0, 0, 0], [1, 2, 3]]))
    s.set_attribute("classification", np.array([2, 6], dtype=np.uint8))
    s.set_attribute("Amplitude", np.array([1.5, -2.25], dtype=np.float32))
    s.set_attribute("ok", np.array([True, False]))
    assert s.attributes["ok"].dtype == np.uint8
    view = s.attributes["classification"]
    s.set_attribute("classification", np.array([9, 9], dtype=np.uint8))
    assert list(view) == [9, 9]  # same dtype: written in place, the view sees it
    s.set_attribute("classification", np.array([1, 2], dtype=np.int64))
    assert s.attributes["classification"].dtype == np.int64 and list(view) == [9, 9]  # the old view stays readable
    dpoint.write(s, tmp_path / "a.las")
    back = dpoint.read(tmp_path / "a.las")
    assert list(back.attributes["classification"]) == [1, 2]
    assert list(back.attributes["Amplitude"]) == [1.5, -2.25]
    s.remove_attribute("ok")
    assert "ok" not in s.attributes
    for bad, error in [(("x", [1, 2]), ValueError), (("a", [1, 2, 3]), ValueError), (("a", ["p", "q"]), TypeError)]:
        try:
            s.set_attribute(*bad)
        except error:
            pass
        else:
            raise AssertionError(f"set_attribute{bad} was accepted")
    try:
        s.remove_attribute("missing")
    except KeyError:
        pass
    else:
        raise AssertionError("remove_attribute('missing') was accepted")


def test_an_extra_bytes_record_the_reader_cannot_follow_is_a_warning(tmp_path):
    """Read as one attribute a byte, with a UserWarning naming the file and the descriptor (the
    build before read it so without a word)."""
    import warnings
    s = dpoint.PointSet(np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]))
    s.set_attribute("amplitude", np.array([258, 772], dtype=np.uint16))
    dpoint.write(s, tmp_path / "good.las")
    b = bytearray((tmp_path / "good.las").read_bytes())
    at = b.index(b"LASF_Spec") - 2 + 54  # the first descriptor: after the VLR's 54-byte header
    b[at + 2] = 31  # data type 31: not one of LAS's 0 to 30
    (tmp_path / "broken.las").write_bytes(bytes(b))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        back = dpoint.read(tmp_path / "broken.las")
        dpoint.read(tmp_path / "good.las")
    assert len(caught) == 1 and issubclass(caught[0].category, UserWarning)
    assert "broken.las: extra bytes descriptor 0 ('amplitude'): data type 31" in str(caught[0].message)
    assert "amplitude" not in back.attributes
    assert list(back.attributes["extra_byte_1"]) == [1, 3]


def test_big_endian_arrays_are_their_values():
    """A column in the other byte order (FITS, HDF5) is its values (the build before copied its bytes:
    258 for 1), through set_attribute and from_dataframe."""
    import pandas as pd
    s = dpoint.PointSet(np.zeros((3, 3)))
    s.set_attribute("a", np.array([1, 2, 3], dtype=">u2"))
    s.set_attribute("w", np.array([1.5, 2.0, -3.25], dtype=">f8"))
    assert s.attributes["a"].tolist() == [1, 2, 3] and s.attributes["a"].dtype == np.uint16
    assert s.attributes["w"].tolist() == [1.5, 2.0, -3.25]
    frame = pd.DataFrame({"x": np.zeros(2), "y": np.zeros(2), "c": np.array([7, 9], dtype=">i4")})
    assert dpoint.PointSet.from_dataframe(frame).attributes["c"].tolist() == [7, 9]
