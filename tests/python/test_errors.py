"""The exceptions: what each is a kind of, and the CLI's exit code each carries as exit_code."""
import numpy as np
import pytest

import dpoint


def test_the_exception_classes():
    assert issubclass(dpoint.Error, ValueError)
    assert issubclass(dpoint.DeviceError, RuntimeError)
    assert not issubclass(dpoint.DeviceError, dpoint.Error)
    # raised by the package itself, without a code: bad input, and no device
    assert dpoint.Error("x").exit_code == 2
    assert dpoint.DeviceError("x").exit_code == 3


@pytest.mark.parametrize("call, kind, code", [
    (lambda: dpoint.generate("random2d", count=0), dpoint.Error, 1),                       # usage
    (lambda: dpoint.read("/nonexistent/x.ply"), dpoint.Error, 2),                          # bad input
    (lambda: dpoint.PointSet([[0.0, 0.0, np.nan]]), dpoint.Error, 2),                      # bad data
    (lambda: dpoint.render([[0.0, 0.0, 0.0]], device="99"), dpoint.DeviceError, 3),        # no device
    (lambda: dpoint.generate("random2d", count=10**7, max_memory="1M"), MemoryError, 4),   # resource limit
], ids=["usage", "bad-input", "bad-data", "no-device", "resource-limit"])
def test_each_failure_raises_its_kind_with_the_clis_code(call, kind, code):
    with pytest.raises(kind) as raised:
        call()
    assert raised.value.exit_code == code
    assert str(raised.value)  # a message, never empty


# The Python side of the bad-invocation table (tests/cli/cli_help_test.cpp, CliVoice): the same
# words as the CLI's "dpoint: error: ..." line, with the same exit code, for the same mistakes, but
# each option named as the keyword it is (the CLI's "width 0" was a review finding).
CLOUD = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]


@pytest.mark.parametrize("call, code, words", [
    (lambda: dpoint.generate("menger", level=99), 1, "level 99: must be 0..8 for menger"),
    (lambda: dpoint.generate("menger", method="voxl"), 1,
     "method voxl: must be exact or voxel; did you mean 'voxel'?"),
    (lambda: dpoint.generate("random2d", count=0), 1, "count 0: must be a number from 1 to 1099511627776"),
    (lambda: dpoint.generate("nosuch"), 1, "generate: unknown kind 'nosuch' (kinds: mandelbulb, julia, menger,"),
    (lambda: dpoint.generate("julia", c=(1, 2)), 1, "c 1,2: must be 4 comma-separated finite numbers"),
    (lambda: dpoint.render(CLOUD, shade="edll"), 1, "shade edll: must be auto, none or edl; did you mean 'edl'?"),
    (lambda: dpoint.render(CLOUD, fov=200), 1, "fov 200: must be in (0, 180)"),
    (lambda: dpoint.render(CLOUD, width=0), 1, "width 0: must be at least 1"),
    (lambda: dpoint.render(CLOUD, tolerance=-1), 1, "tolerance -1: must be a number of pixels above 0"),
    (lambda: dpoint.render(CLOUD, mode="emulated"), 1, "mode emulated: must be auto, fp32, split, rte, df64"),
    (lambda: dpoint.info(CLOUD, sample=0), 1, "sample 0: must be a number from 1 to 100000000"),
    (lambda: dpoint.bench(frames=0), 1, "frames 0: must be at least 1"),
    (lambda: dpoint.read("/nonexistent/x.ply"), 2, "/nonexistent/x.ply: file not found"),
    (lambda: dpoint.render(CLOUD, device="99"), 3, "device 99: only "),
    (lambda: dpoint.render(CLOUD, view_width=-3), 1, "view_width -3: must be a finite number above 0"),
    (lambda: dpoint.info(CLOUD, view_width=0), 1, "view_width 0: must be a finite number above 0"),
    (lambda: dpoint.info("/tmp/x.csv", stream="x"), 1, "stream x: must be auto, on or off"),
    # Negative whole numbers gave pybind11's dump of the whole signature (a review finding).
    (lambda: dpoint.read("/tmp/x.csv", threads=-1), 1, "read: threads -1: must be a whole number from 0 to 4294967295"),
    (lambda: dpoint.read("/tmp/x.csv", max_points=-1), 1, "read: max_points -1: must be a whole number from 0"),
    (lambda: dpoint.info(CLOUD, threads=-1), 1, "info: threads -1: must be a whole number from 0"),
    (lambda: dpoint.sample(CLOUD, -5), 1, "sample: count -5: must be a whole number from 0"),
    (lambda: dpoint.sample(CLOUD, 5, seed=2**64), 1, "sample: seed 18446744073709551616: must be a whole number"),
])
def test_bad_calls_speak_the_clis_words(call, code, words):
    with pytest.raises((dpoint.Error, dpoint.DeviceError)) as raised:
        call()
    assert raised.value.exit_code == code
    assert words in str(raised.value)
    assert "\n" not in str(raised.value).strip()
    assert "--" not in str(raised.value).replace("--help", "")


def test_a_file_name_with_two_dashes_is_named_as_it_is(tmp_path):
    # "--" inside a file's name is not a flag (a review finding: no--such.csv was named nosuch.csv).
    with pytest.raises(dpoint.Error, match="no--such--file.csv: file not found"):
        dpoint.read(tmp_path / "no--such--file.csv")


def test_columns_as_bytes_are_refused_not_read_as_numbers():
    # b"x,y,z" was a list of numbers: "--columns 44: named twice" (a review finding).
    with pytest.raises(TypeError, match="columns: a str such as 'x,y,z,-,intensity' or a list of str, not b'x,y,z'"):
        dpoint.read("/tmp/x.csv", columns=b"x,y,z")


@pytest.mark.parametrize("call, kind, words", [
    # A misspelt keyword of read, write or sample (pybind11 printed write's whole signature).
    (lambda t: dpoint.write(dpoint.PointSet(CLOUD), t / "a.csv", decimal=3), TypeError,
     "write: no option 'decimal'; did you mean 'decimals'?"),
    (lambda t: dpoint.read(t / "a.csv", thread=2), TypeError, "read: no option 'thread'; did you mean 'threads'?"),
    (lambda t: dpoint.sample(dpoint.generate("menger", level=1), 10, sed=1), TypeError,
     "sample: no option 'sed'; did you mean 'seed'?"),
    # help= is the CLI's (render's raised CLI11's "This should be caught in your main function").
    (lambda t: dpoint.render(CLOUD, help=True), TypeError, "help is the CLI's option"),
    (lambda t: dpoint.generate("menger", help=True), TypeError, "help is the CLI's option"),
    (lambda t: dpoint.info(CLOUD, sample=-1), dpoint.Error, "sample -1: must be a number from 1 to 100000000"),
    # Options the file would not use, refused as convert's are (they passed in silence).
    (lambda t: dpoint.write(dpoint.PointSet(CLOUD), t / "a.ply", las_scale=0.01), dpoint.Error,
     "las_scale: only a LAS, LAZ or COPC output (.las, .laz, .copc.laz) has a coordinate step"),
    (lambda t: dpoint.write(dpoint.PointSet(CLOUD), t / "a.las", decimals=3), dpoint.Error,
     "decimals: only a CSV output (.csv, .xyz, .txt, .asc, .pts, .ptx) has decimals"),
    # The LAS writer's advice in the module's words (it said "--drop intensity").
    (lambda t: dpoint.write(_with_intensity(70000), t / "a.las"), dpoint.Error,
     "leave it out with points.remove_attribute('intensity') (on a copy)"),
    # A format read but not written.
    (lambda t: dpoint.write(dpoint.PointSet(CLOUD), t / "a.gltf"), dpoint.Error, "a.gltf: .gltf is read, not written"),
])
def test_python_mistakes_get_python_words(tmp_path, call, kind, words):
    dpoint.write(dpoint.PointSet(CLOUD), tmp_path / "a.csv")
    with pytest.raises(kind) as raised:
        call(tmp_path)
    assert words in str(raised.value)


def _with_intensity(value):
    s = dpoint.PointSet(CLOUD)
    s.set_attribute("intensity", np.array([value, 0], dtype=np.uint32))
    return s


def test_none_leaves_an_option_out_and_numpy_and_nullable_values_are_taken(tmp_path):
    """None leaves read's and write's options out, as everywhere else (pybind11 refused it), and
    a DataFrame of pandas' nullable dtypes (convert_dtypes) gives its attributes (refused as objects)."""
    import pandas as pd
    dpoint.write(dpoint.PointSet(CLOUD), tmp_path / "a.csv", decimals=None, threads=np.int64(1))
    assert len(dpoint.read(tmp_path / "a.csv", scene=None, max_points=None)) == 2
    frame = pd.DataFrame({"x": [1.0, 2.0], "y": [3.0, 4.0], "i": [5, 6], "ok": [True, False]}).convert_dtypes()
    s = dpoint.PointSet.from_dataframe(frame)
    assert s.attributes["i"].tolist() == [5, 6] and s.attributes["ok"].tolist() == [1, 0]
