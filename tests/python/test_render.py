"""dpoint.render and dpoint.Renderer: the picture and the report `dpoint render` gives for the same
points and options, under the Khronos validation layer (validate=True: any message raises)."""
import json
import pathlib
import threading
import time
import warnings

import numpy as np
import pytest

import dpoint
from conftest import as_keywords, cli, cli_error, options_as_flags

CORPUS = pathlib.Path(__file__).resolve().parents[2].parent / "shared" / "corpus"

# The report's timings and memory, which differ from run to run; every other key must match.
TIMED = {"gpu_ms", "gpu_ms_each", "frame_ms", "upload_ms", "readback_ms", "e2e_ms", "phases_ms", "peak_rss_mb",
         "points_per_s", "warmup"}


def cli_render(tmp_path, inputs, options, report=True):
    """`dpoint render INPUTS` with the options as flags: (PNG bytes, its --json report or None)."""
    png, report_path = tmp_path / "cli.png", tmp_path / "cli.json"
    cli("render", *inputs, "-o", png, "--quiet", *options_as_flags(options),
        *(["--json", report_path] if report else []))
    return png.read_bytes(), json.loads(report_path.read_text()) if report else None


def untimed(report):
    return {k: v for k, v in report.items() if k not in TIMED}


def test_the_result(cloud):
    s, _, _ = cloud
    r = dpoint.render(s, "fp32", width=96, height=64, frames=3, warmup=1, error=True, validate=True)
    assert r.image.shape == (64, 96, 4) and r.image.dtype == np.uint8
    assert r.image[..., 3].min() == 255  # opaque
    assert r.image[..., :3].any()  # something drawn
    assert r.mode == "fp32" and r.backend in ("compute", "raster") and r.device
    assert r.points == 500 and r.point_size == 1.0  # 1 px with error=True
    assert r.predicted_bound_px > 0 and not r.bound_from_boxes
    assert len(r.gpu_ms) == 3 and all(t > 0 for t in r.gpu_ms)
    assert set(r.error_px) == {"max", "p99", "rms", "share_off_half_px", "points", "lost"}
    assert 0 <= r.error_px["max"] <= r.predicted_bound_px and r.error_px["points"] == 500
    assert r.warnings == []
    assert r.report["mode"] == "fp32" and r.report["points"] == 500 and r.report["frames"] == 3
    assert r.report["error_px"]["max"] == r.error_px["max"]
    assert r.png()[:8] == b"\x89PNG\r\n\x1a\n" and r._repr_png_() == r.png()
    assert "96x64, 500 points, mode fp32" in repr(r)
    assert dpoint.render(s, width=32, height=32, validate=True).error_px is None


def test_the_image_is_the_png(tmp_path, cloud):
    s, _, _ = cloud
    r = dpoint.render(s, width=40, height=30, validate=True)
    r.save(tmp_path / "r.png")
    assert (tmp_path / "r.png").read_bytes() == r.png()
    with pytest.raises(dpoint.Error, match="name it .png"):
        r.save(tmp_path / "r.jpg")
    with pytest.raises(dpoint.Error, match="does not exist"):
        r.save(tmp_path / "no" / "r.png")


CASES = [
    ("colours, fp32, error", dict(mode="fp32", error=True)),
    ("default fit, auto", dict()),
    ("native, raster, 2 frames", dict(mode="native", backend="raster", frames=2, warmup=1)),
    ("camera", dict(mode="df64", eye=(6378137.0, 3000.0, 3000.0), target=(6378137.0, 0.0, 0.0), up=(0, 0, 1), fov=30.0)),
    ("ortho", dict(mode="rte", ortho=True, view_center=(6378137.0, 0.0), view_width=5000.0)),
    ("elevation, edl, morton", dict(mode="batch", color="elevation", shade="edl", order="morton", point_size=2)),
    ("adaptive, background", dict(mode="adaptive", tolerance=0.2, background=(10, 20, 30))),
]


@pytest.mark.parametrize("name, options", CASES, ids=[c[0] for c in CASES])
def test_a_render_is_the_clis_picture_and_report(tmp_path, cloud, name, options):
    s, _, _ = cloud
    dpoint.write(s, tmp_path / "s.ply")
    options = dict(width=96, height=64, **options)
    cli_png, cli_report = cli_render(tmp_path, [tmp_path / "s.ply"], dict(validate=True, **options))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dpoint.RenderWarning)
        for points in (s, tmp_path / "s.ply", str(tmp_path / "s.ply")):
            r = dpoint.render(points, validate=True, **options)
            assert r.png() == cli_png, points
            assert untimed(r.report) == untimed(cli_report), points


def test_a_set_without_colours_is_the_clis(tmp_path):
    """Coloured by elevation along its up axis: y for a set made in memory, as for a PLY file."""
    bulb = dpoint.generate("mandelbulb", resolution=40, device="none", colors="none")
    dpoint.write(bulb, tmp_path / "b.ply")
    cli_png, cli_report = cli_render(tmp_path, [tmp_path / "b.ply"], dict(width=96, height=64))
    r = dpoint.render(bulb, width=96, height=64, validate=True)
    assert r.png() == cli_png and untimed(r.report) == untimed(cli_report)


def test_a_las_set_renders_z_up_as_the_cli_renders_the_file(tmp_path):
    survey = dpoint.generate("random2d", count=3000, offset=(6e5, 4e6, 100), colors="none")
    survey.positions[:, 2] += np.sin(survey.positions[:, 0] * 100.0) * 20.0  # some relief
    dpoint.write(survey, tmp_path / "s.las", las_scale=0.01)
    read = dpoint.read(tmp_path / "s.las")
    assert read.z_up
    cli_png, _ = cli_render(tmp_path, [tmp_path / "s.las"], dict(width=96, height=64))
    assert dpoint.render(read, width=96, height=64, validate=True).png() == cli_png


def test_a_contact_sheet(tmp_path):
    bulb = dpoint.generate("mandelbulb", resolution=32, device="none")
    dpoint.write(bulb, tmp_path / "b.ply")
    cli_png, _ = cli_render(tmp_path, [tmp_path / "b.ply"], dict(width=128, height=96, views=4), report=False)
    r = dpoint.render(bulb, width=128, height=96, views=4, validate=True)
    assert r.image.shape == (96, 128, 4)
    assert r.report is None
    assert r.png() == cli_png
    with pytest.raises(dpoint.Error, match="^views 4 makes a contact sheet; error measures one view"):
        dpoint.render(bulb, views=4, error=True)


def test_a_million_points_from_numpy_give_the_clis_png(tmp_path):
    rng = np.random.default_rng(1)
    sphere = rng.normal(size=(1_000_000, 3))
    sphere = sphere / np.linalg.norm(sphere, axis=1)[:, None] * 100.0 + np.array([6378137.0, 0.0, 0.0])
    s = dpoint.PointSet(sphere, rng.integers(0, 256, size=(1_000_000, 3), dtype=np.uint8))
    dpoint.write(s, tmp_path / "m.ply")
    options = dict(width=320, height=240)
    cli("render", tmp_path / "m.ply", "-o", tmp_path / "cli.png", "--mode", "fp32", "--quiet",
        *options_as_flags(options))
    with pytest.warns(dpoint.RenderWarning, match="^mode fp32: predicted error up to"):
        r = dpoint.render(s, mode="fp32", validate=True, **options)
    r.save(tmp_path / "py.png")
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()
    assert r.png() == (tmp_path / "cli.png").read_bytes()
    assert r.points == 1_000_000


def test_several_files_are_drawn_as_one(tmp_path, cloud):
    s, positions, colors = cloud
    dpoint.write(dpoint.PointSet(positions[:200], colors[:200]), tmp_path / "a.ply")
    dpoint.write(dpoint.PointSet(positions[200:], colors[200:]), tmp_path / "b.ply")
    cli_png, _ = cli_render(tmp_path, [tmp_path / "a.ply", tmp_path / "b.ply"], dict(width=64, height=48))
    r = dpoint.render([tmp_path / "a.ply", tmp_path / "b.ply"], width=64, height=48, validate=True)
    assert r.points == 500 and r.png() == cli_png


def test_a_streamed_file_is_the_clis(tmp_path, cloud):
    dpoint.write(cloud[0], tmp_path / "s.ply")
    cli_png, cli_report = cli_render(tmp_path, [tmp_path / "s.ply"], dict(width=64, height=48, stream="on"))
    r = dpoint.render(tmp_path / "s.ply", width=64, height=48, stream="on", validate=True)
    assert r.bound_from_boxes and r.report["predicted_from"] == "batch_boxes"
    assert r.png() == cli_png and untimed(r.report) == untimed(cli_report)


def test_a_warning_is_a_render_warning_at_the_callers_line(cloud):
    s, _, _ = cloud
    with pytest.warns(dpoint.RenderWarning) as caught:
        r = dpoint.render(s, mode="fp32", width=2000, height=1500, eye=(6378137.0, 0.0, 1e-3),
                          target=(6378137.0, 0.0, 0.0), validate=True)
    assert r.warnings and [str(w.message) for w in caught] == r.warnings
    assert all(w.filename == __file__ for w in caught)


def test_renderer_keeps_one_device_across_renders(cloud):
    s, _, _ = cloud
    bulb = dpoint.generate("mandelbulb", resolution=24, device="none")
    with dpoint.Renderer(validate=True) as renderer:
        assert renderer.device == dpoint.render(s, width=8, height=8).device
        for mode in ("fp32", "rte", "df64", "native", "batch", "adaptive"):
            for points in (s, bulb):
                alone = dpoint.render(points, mode, width=64, height=48, validate=True)
                reused = renderer.render(points, mode, width=64, height=48)
                assert reused.mode == mode
                assert np.array_equal(reused.image, alone.image), mode
                assert untimed(reused.report) == untimed(alone.report), mode
        assert renderer.render(bulb, width=64, height=48, views=4).report is None
        with pytest.raises(TypeError, match="device is the Renderer's"):
            renderer.render(s, device="cpu")
    with pytest.raises(dpoint.Error, match="this Renderer is closed"):
        renderer.render(s)
    renderer.close()  # twice is fine


def test_renderer_close_then_render_raises(cloud):
    renderer = dpoint.Renderer("auto", validate=True, max_device_memory="1G")
    assert renderer.render(cloud[0], width=16, height=16).points == 500
    renderer.close()
    with pytest.raises(dpoint.Error) as raised:
        renderer.render(cloud[0], width=16, height=16)
    assert str(raised.value) == "this Renderer is closed" and raised.value.exit_code == 1
    with pytest.raises(dpoint.Error, match="closed"):
        renderer.device


def test_renderer_shared_by_threads_renders_one_at_a_time():
    """Python threads may share a Renderer (renders release the GIL): each render is whole, and no
    two submit to the device's queue at once (the validation layer's threading checks say so)."""
    bulb = dpoint.generate("mandelbulb", resolution=32, device="none")
    failures = []
    with dpoint.Renderer(validate=True) as renderer:
        expected = renderer.render(bulb, width=48, height=32).image.copy()

        def work():
            for _ in range(5):
                try:
                    if not np.array_equal(renderer.render(bulb, width=48, height=32).image, expected):
                        failures.append("another picture")
                except Exception as e:  # noqa: BLE001 - every failure is reported below
                    failures.append(str(e))

        threads = [threading.Thread(target=work) for _ in range(3)]
        for t in threads:
            t.start()
        assert renderer.device  # waits its turn, with the GIL released
        for t in threads:
            t.join()
    assert failures == []


def test_closing_a_renderer_while_another_thread_renders(cloud):
    renderer = dpoint.Renderer(validate=True)
    results = []
    worker = threading.Thread(target=lambda: results.append(
        renderer.render(cloud[0], width=32, height=32, frames=40, warmup=0)))
    worker.start()
    time.sleep(0.05)
    renderer.close()  # waits for the render, then closes
    worker.join()
    assert len(results) == 1 and len(results[0].gpu_ms) == 40
    with pytest.raises(dpoint.Error, match="this Renderer is closed"):
        renderer.render(cloud[0])


@pytest.mark.parametrize("options, flags", [
    (dict(width=0), ["--width", "0"]),
    (dict(width="wide"), ["--width", "wide"]),
    (dict(mode="fp16"), ["--mode", "fp16"]),
    (dict(shade="phong"), ["--shade", "phong"]),
    (dict(views=3), ["--views", "3"]),
    (dict(eye=(1, 2)), ["--eye", "1,2"]),
    (dict(background=(300, 0, 0)), ["--background", "300,0,0"]),
    (dict(widht=10), ["--widht", "10"]),
    (dict(pointsize=2), ["--pointsize", "2"]),
])
def test_a_bad_option_is_the_clis_error(tmp_path, cloud, options, flags):
    s, _, _ = cloud
    dpoint.write(s, tmp_path / "s.ply")
    message, code = cli_error("render", tmp_path / "s.ply", "-o", tmp_path / "x.png", *flags)
    with pytest.raises(dpoint.Error) as raised:
        dpoint.render(s, **options)
    assert str(raised.value) == as_keywords(message)
    assert raised.value.exit_code == code == 1


def test_an_unknown_keyword_says_did_you_mean(cloud):
    with pytest.raises(dpoint.Error) as raised:
        dpoint.render(cloud[0], view_widht=3.0)
    assert str(raised.value) == ("render: unknown option 'view_widht'; did you mean 'view_width'? "
                                 "(`dpoint render --help` lists them)")


def test_outputs_go_through_the_result(cloud):
    for option in ("json", "output", "o"):
        with pytest.raises(TypeError, match="come back in the result"):
            dpoint.render(cloud[0], **{option: "x"})


def test_no_such_device_is_a_device_error(tmp_path, cloud):
    s, _, _ = cloud
    dpoint.write(s, tmp_path / "s.ply")
    message, code = cli_error("render", tmp_path / "s.ply", "-o", tmp_path / "x.png", "--device", "99")
    with pytest.raises(dpoint.DeviceError) as raised:
        dpoint.render(s, device="99")
    assert isinstance(raised.value, RuntimeError)
    assert str(raised.value) == as_keywords(message) and raised.value.exit_code == code == 3
    with pytest.raises(dpoint.DeviceError, match="device 99"):
        dpoint.Renderer(device=99)


def test_bad_data_for_render(tmp_path, rng):
    with pytest.raises(dpoint.Error, match="points: color rgb: the set has no colours"):
        dpoint.render(dpoint.PointSet(rng.random((5, 3))), color="rgb")
    with pytest.raises(dpoint.Error, match="^color intensity: points has no dimension 'intensity' \\(it has none"):
        dpoint.render(dpoint.PointSet(rng.random((5, 3))), color="intensity")
    with pytest.raises(dpoint.Error, match="file not found"):
        dpoint.render(tmp_path / "gone.ply")
    with pytest.raises(MemoryError, match="picture"):
        dpoint.render(dpoint.PointSet(rng.random((5, 3))), width=4096, height=4096, max_memory="1M")


def _pixels(image, rgb):
    """How many pixels of an (H, W, 4) uint8 picture have this RGB."""
    return int(np.all(image[:, :, :3] == np.array(rgb, dtype=np.uint8), axis=2).sum())


def test_render_by_any_attribute_draws_its_legend(tmp_path):
    """render --color NAME (issue #34): a survey by class in the ASPRS colours, by intensity in viridis
    over its 1st-99th percentile, each with a legend box in the top-right corner; and a set's own
    attribute made in Python."""
    survey = CORPUS / "laz" / "autzen_trim.las"
    by_class = dpoint.render(survey, color="classification", width=600, height=400, shade="none", validate=True)
    by_intensity = dpoint.render(survey, color="intensity", width=600, height=400, shade="none", validate=True)
    for picture in (by_class.image, by_intensity.image):
        corner = picture[:40, 300:]
        assert _pixels(corner, (0x10, 0x10, 0x10)) > 100  # the legend's dark box
    assert _pixels(by_class.image, (139, 90, 43)) > 1000  # ground, in points and its swatch
    assert _pixels(by_class.image, (160, 160, 160)) > 1000  # unclassified
    assert _pixels(by_intensity.image, (0xfd, 0xe7, 0x25)) > 50  # viridis' top: the brightest 1% and the bar
    s = dpoint.PointSet(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 1]]))
    s.set_attribute("temperature", np.array([10.0, 20, 30, 40]))
    one = dpoint.render(s, color="temperature", width=200, height=150, point_size=15)
    assert _pixels(one.image, (0x10, 0x10, 0x10)) > 50
    assert "temperature" in s.attributes and s.colors is None  # the caller's set stays as it was
    # Streamed (a binary PLY read a block at a time): the same classes and legend.
    dpoint.write(dpoint.read(survey), tmp_path / "survey.ply")
    streamed = dpoint.render(tmp_path / "survey.ply", color="classification", stream="on", width=600, height=400,
                             shade="none", validate=True)
    assert _pixels(streamed.image[:40, 300:], (0x10, 0x10, 0x10)) > 100
    assert _pixels(streamed.image, (139, 90, 43)) > 1000
    with pytest.raises(dpoint.Error, match="^color nope: .*survey.ply has no dimension 'nope' \\(it has intensity, "):
        dpoint.render(tmp_path / "survey.ply", color="nope", stream="on")
