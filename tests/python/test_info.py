"""dpoint.info: the object `dpoint info --json` prints, for a set in memory or files."""
import json

import numpy as np
import pytest

import dpoint
from conftest import as_keywords, cli, cli_error, cli_json, options_as_flags


def without_file(report):
    return {k: v for k, v in report.items() if k != "file"}


@pytest.mark.parametrize("make", [
    lambda rng: dpoint.PointSet(rng.normal(size=(500, 3)) * 1e3 + 6.4e6, rng.integers(0, 256, (500, 3), dtype=np.uint8)),
    lambda rng: dpoint.generate("random2d", count=400),
    lambda rng: dpoint.generate("menger", level=2),
    lambda rng: dpoint.PointSet(rng.random((3, 3)) * 1e-300),
], ids=["colours-far-off", "2d", "mesh", "tiny"])
def test_info_of_a_set_is_the_clis_of_its_file(tmp_path, rng, make):
    s = make(rng)
    dpoint.write(s, tmp_path / "s.ply")
    expected = cli_json("info", tmp_path / "s.ply", "--json")
    got = dpoint.info(s)
    assert got["file"] == "points"
    assert without_file(got) == without_file(expected)
    assert dpoint.info(tmp_path / "s.ply") == expected  # a path: the same, file included


def test_info_with_a_camera_is_the_clis(tmp_path, cloud):
    s, _, _ = cloud
    dpoint.write(s, tmp_path / "s.ply")
    camera = dict(width=320, height=200, eye=(6378137.0, 0.0, 5000.0), target=(6378137.0, 0.0, 0.0), fov=30.0)
    expected = cli_json("info", tmp_path / "s.ply", "--json", *options_as_flags(camera))
    got = dpoint.info(s, **camera)
    assert without_file(got) == without_file(expected)
    assert got["view"]["width"] == 320 and set(got["error_bound_px"]) == {
        "fp32", "split", "rte", "df64", "native", "batch", "adaptive"}
    ortho = dict(ortho=True, view_center=(6378137.0, 0.0), view_width=100.0)
    assert without_file(dpoint.info(s, **ortho)) == without_file(
        cli_json("info", tmp_path / "s.ply", "--json", *options_as_flags(ortho)))


def test_info_of_several_files_is_one_set(tmp_path, rng):
    a, b = rng.random((100, 3)), rng.random((50, 3)) + 5.0
    dpoint.write(a, tmp_path / "a.ply")
    dpoint.write(b, tmp_path / "b.ply")
    both = dpoint.info([tmp_path / "a.ply", tmp_path / "b.ply"])
    assert both == cli_json("info", tmp_path / "a.ply", tmp_path / "b.ply", "--json")
    assert both["points"] == 150


def test_info_options(tmp_path, cloud):
    s, _, _ = cloud
    dpoint.write(s, tmp_path / "s.ply")
    assert dpoint.info(s, sample=10)["neighbor_sample"] == 10
    assert dpoint.info(tmp_path / "s.ply", stream="on")["streamed"]
    with pytest.raises(dpoint.Error, match="sample 0: must be a number from 1 to 100000000"):
        dpoint.info(s, sample=0)
    with pytest.raises(MemoryError, match="more than the limit of 1024 bytes"):
        dpoint.info(tmp_path / "s.ply", max_memory="1K")


@pytest.mark.parametrize("options, flags", [
    (dict(width=0), ["--width", "0"]),
    (dict(eye=(0, 0)), ["--eye", "0,0"]),
    (dict(widht=5), ["--widht", "5"]),
    (dict(fov="wide"), ["--fov", "wide"]),
    (dict(stream="sometimes"), ["--stream", "sometimes"]),
])
def test_a_bad_option_is_the_clis_error(tmp_path, cloud, options, flags):
    s, _, _ = cloud
    dpoint.write(s, tmp_path / "s.ply")
    message, code = cli_error("info", tmp_path / "s.ply", *flags)
    with pytest.raises(dpoint.Error) as raised:
        dpoint.info(tmp_path / "s.ply", **options)
    assert str(raised.value) == as_keywords(message)
    assert raised.value.exit_code == code


def test_info_of_a_missing_file_names_it(tmp_path):
    with pytest.raises(dpoint.Error, match=f"{tmp_path / 'gone.las'}: file not found"):
        dpoint.info(tmp_path / "gone.las")


def test_numpy_scalars_are_options(cloud):
    """numpy.int64 as a size and numpy.True_ as a flag, as their Python values (the build before
    refused the first and passed the second to the CLI as the word True)."""
    s, _, _ = cloud
    assert dpoint.info(s, max_memory=np.int64(10**9))["points"] == len(s)
    assert dpoint.info(s, sample=np.int64(5), width=np.int32(64))["neighbor_sample"] == 5


def test_file_options_for_a_set_in_memory_are_refused():
    # A review finding: stream=, columns= and allow_nonfinite= were passed over in silence.
    s = dpoint.PointSet(np.zeros((3, 3)))
    with pytest.raises(dpoint.Error, match="info: stream applies to files, not to a set in memory") as raised:
        dpoint.info(s, stream="on")
    assert raised.value.exit_code == 1
    with pytest.raises(dpoint.Error, match="info: allow_nonfinite and columns apply to files"):
        dpoint.info(s, columns="x,y,z", allow_nonfinite=True)
    assert dpoint.info(s)["points"] == 3


def test_read_refuses_a_negative_scene_as_the_cli_does(tmp_path):
    dpoint.write(dpoint.PointSet(np.zeros((3, 3)), triangles=np.array([[0, 1, 2]])), tmp_path / "m.glb")
    with pytest.raises(dpoint.Error, match="scene -2: must be 0 or more"):
        dpoint.read(tmp_path / "m.glb", scene=-2)


@pytest.mark.parametrize("stream", ["off", "on"])
def test_info_warns_what_the_cli_notes(tmp_path, stream):
    """What the readers read past comes as a UserWarning at the caller, each of the CLI's notes (the
    build before said nothing: read warned them, info did not)."""
    import warnings

    files = []
    for name, crs in (("a.ply", "EPSG:4326"), ("b.ply", "EPSG:32633")):
        s = dpoint.PointSet(np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.5]]))
        s.crs = crs
        dpoint.write(s, tmp_path / name)
        files.append(tmp_path / name)
    done = cli("info", *files, "--stream", stream, "--json")
    notes = [line[len("dpoint: note: "):] for line in done.stderr.splitlines() if line.startswith("dpoint: note: ")]
    assert notes and any("its coordinate system left out" in note for note in notes), done.stderr
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        report = dpoint.info(files, stream=stream)
    assert [str(w.message) for w in caught] == notes
    assert all(w.category is UserWarning and w.filename == __file__ for w in caught)
    assert report == json.loads(done.stdout)
