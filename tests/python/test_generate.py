"""dpoint.generate: every kind, and the very bytes `dpoint generate` writes."""
import re

import numpy as np
import pytest

import dpoint
from conftest import as_keywords, SMALL_GENERATE, cli, cli_error, options_as_flags


def test_every_kind_is_covered():
    """The kinds the CLI lists are the kinds these tests generate."""
    with pytest.raises(dpoint.Error) as raised:
        dpoint.generate("no-such-kind")
    listed = re.search(r"\(kinds: ([^)]*)\)", str(raised.value)).group(1).split(", ")
    assert sorted(listed) == sorted(SMALL_GENERATE)
    for kind in listed:  # the options used here are the kind's own (`dpoint generate KIND --help`)
        help_text = cli("generate", kind, "--help").stdout
        for option in SMALL_GENERATE[kind]:
            assert f"--{option.replace('_', '-')} " in help_text, (kind, option)


@pytest.mark.parametrize("kind", sorted(SMALL_GENERATE))
def test_each_kind_gives_a_set(kind):
    s = dpoint.generate(kind, **SMALL_GENERATE[kind])
    assert isinstance(s, dpoint.PointSet) and len(s) > 0
    assert np.isfinite(s.positions).all()
    assert s.has_z == (kind not in ("random2d", "mandelbrot2d"))
    # Surfaces and solids are meshes; random2d and the Mandelbrot grid are points.
    assert (s.triangles is not None) == (kind in ("mandelbulb", "julia", "menger", "sierpinski"))
    again = dpoint.generate(kind, **SMALL_GENERATE[kind])
    assert np.array_equal(again.positions, s.positions)  # deterministic


def test_options_reach_the_generator():
    assert len(dpoint.generate("random2d", count=123)) == 123
    assert len(dpoint.generate("sierpinski", level=2)) == 2 * 4**2 + 2
    assert len(dpoint.generate("sierpinski", level=2, unwelded=True)) == 4**3
    a = dpoint.generate("random2d", count=50, seed=1).positions
    assert not np.array_equal(a, dpoint.generate("random2d", count=50, seed=2).positions)
    assert (np.abs(a) <= 1.0).all()
    moved = dpoint.generate("random2d", count=50, seed=1, offset=(6378137.0, -2.5, 7))
    assert np.array_equal(moved.positions, a + np.array([6378137.0, -2.5, 7.0]))
    assert dpoint.generate("menger", level=1, colors="none").colors is None
    assert dpoint.generate("menger", level=1, colors="noise").colors is not None
    # a NumPy array and NumPy scalars are options as well as tuples and floats
    c = dpoint.generate("mandelbrot2d", resolution=16, center=np.array([-0.75, 0.1]), width=np.float64(1e-3),
                        device="none")
    assert np.array_equal(c.positions, dpoint.generate("mandelbrot2d", resolution=16, center=(-0.75, 0.1),
                                                       width=1e-3, device="none").positions)


class FloatWithOwnRepr(float):
    """A float whose repr is not its value's text, as NumPy 2's float64 ("np.float64(0.001)")."""

    def __repr__(self):
        return f"FloatWithOwnRepr({float(self)!r})"


def test_a_float_subclass_is_passed_by_value():
    a = dpoint.generate("mandelbrot2d", resolution=16, width=FloatWithOwnRepr(1e-3), center=(FloatWithOwnRepr(-0.75), 0.1),
                        device="none")
    b = dpoint.generate("mandelbrot2d", resolution=16, width=1e-3, center=(-0.75, 0.1), device="none")
    assert np.array_equal(a.positions, b.positions)


SAME_BYTES = [
    ("mandelbulb", dict(resolution=24, device="none"), "ply"),
    ("mandelbulb", dict(resolution=20, variant="fast", device="none", colors="noise", order="morton"), "ply"),
    ("julia", dict(resolution=20, device="none", offset=(6378137.0, 0, 0)), "glb"),
    ("menger", dict(level=2, offset=(1e6, 2e6, -3e6)), "ply"),
    ("menger", dict(level=2, method="voxel", resolution=12, colors="none"), "glb"),
    ("sierpinski", dict(level=3, order="morton"), "csv"),
    ("random2d", dict(count=400, seed=9, colors="noise"), "las"),
    ("random2d", dict(count=400, order="morton", offset=(0.5, 0.25, 0)), "csv"),
    ("mandelbrot2d", dict(resolution=40, center=(-0.75, 0.1), width=1e-3, device="none", colors="noise"), "ply"),
]


@pytest.mark.parametrize("kind, options, ext", SAME_BYTES,
                         ids=[f"{k}-{'-'.join(o)}-{e}" for k, o, e in SAME_BYTES])
def test_generate_then_write_gives_the_clis_bytes(tmp_path, kind, options, ext):
    dpoint.write(dpoint.generate(kind, **options), tmp_path / f"py.{ext}")
    cli("generate", kind, *options_as_flags(options), "-o", tmp_path / f"cli.{ext}", "--quiet")
    assert (tmp_path / f"py.{ext}").read_bytes() == (tmp_path / f"cli.{ext}").read_bytes()


@pytest.mark.parametrize("kind, options, flags", [
    ("mandelbulb", dict(resolution=1), ["--resolution", "1"]),
    ("menger", dict(level=9), ["--level", "9"]),
    ("menger", dict(method="bogus"), ["--method", "bogus"]),
    ("julia", dict(c=(1, 2)), ["--c", "1,2"]),
    ("random2d", dict(count=0), ["--count", "0"]),
    ("random2d", dict(colors="rainbow"), ["--colors", "rainbow"]),
    ("random2d", dict(offset="a,b,c"), ["--offset", "a,b,c"]),
    ("random2d", dict(order="hilbert"), ["--order", "hilbert"]),
    ("mandelbulb", dict(variant="seed", device="cpu", resolution=8), ["--variant", "seed", "--device", "cpu",
                                                                      "--resolution", "8"]),
])
def test_a_bad_option_is_the_clis_error(tmp_path, kind, options, flags):
    message, code = cli_error("generate", kind, *flags, "-o", tmp_path / "x.ply")
    with pytest.raises(dpoint.Error) as raised:
        dpoint.generate(kind, **options)
    assert str(raised.value) == as_keywords(message)
    assert raised.value.exit_code == code == 1


def test_an_unknown_option_says_did_you_mean():
    with pytest.raises(dpoint.Error) as raised:
        dpoint.generate("mandelbulb", resolutoin=10)
    assert str(raised.value) == ("generate mandelbulb: unknown option 'resolutoin'; did you mean 'resolution'? "
                                 "(`dpoint generate mandelbulb --help` lists them)")
    with pytest.raises(dpoint.Error, match="unknown kind 'mandelbulp'; did you mean 'mandelbulb'"):
        dpoint.generate("mandelbulp")


def test_outputs_are_refused():
    with pytest.raises(dpoint.Error, match="hands the points back to its caller"):
        dpoint.generate("random2d", count=5, output="x.ply")
    with pytest.raises(dpoint.Error, match="a tile is a part file"):
        dpoint.generate("random2d", count=5, tile="0/2")
    with pytest.raises(TypeError, match="kind must be a string"):
        dpoint.generate(3)


def test_beyond_max_memory_is_a_memory_error():
    with pytest.raises(MemoryError) as raised:
        dpoint.generate("mandelbulb", resolution=100, device="none", max_memory="10K")
    assert str(raised.value) == "mandelbulb at resolution 100 needs about 2.9 MiB, more than the limit of 10240 bytes " \
                                "(max_memory)"
    assert raised.value.exit_code == 4
    with pytest.raises(MemoryError):
        dpoint.generate("random2d", count=10**6, max_memory=4096)


def test_no_such_device_is_a_device_error():
    with pytest.raises(dpoint.DeviceError) as raised:
        dpoint.generate("julia", resolution=8, device="99")
    assert isinstance(raised.value, RuntimeError)
    assert raised.value.exit_code == 3
    assert "device 99" in str(raised.value) and "--" not in str(raised.value)


def test_on_the_vulkan_device_the_counts_are_the_cpus():
    """lavapipe here: the same set bit for bit (generate --device), under the validation layer."""
    on_cpu = dpoint.generate("julia", resolution=20, device="none")
    on_device = dpoint.generate("julia", resolution=20, device="cpu", validate=True)
    assert np.array_equal(on_cpu.positions, on_device.positions)
