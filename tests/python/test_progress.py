"""progress=False (the default) prints nothing, on stderr or stdout; progress=True may."""
import numpy as np

import dpoint


def test_progress_false_prints_nothing(tmp_path, capfd):
    bulb = dpoint.generate("mandelbulb", resolution=48, device="none", progress=False)
    dpoint.generate("julia", resolution=16, device="cpu", validate=True)
    dpoint.write(bulb, tmp_path / "b.ply", progress=False)
    dpoint.write(bulb, tmp_path / "b.csv", order="morton")
    dpoint.read(tmp_path / "b.ply", progress=False)
    dpoint.read(tmp_path / "b.csv")
    dpoint.info(bulb, progress=False)
    dpoint.info(tmp_path / "b.ply", stream="on")
    dpoint.render(bulb, width=64, height=48, validate=True, progress=False)
    dpoint.render(tmp_path / "b.ply", width=64, height=48, error=True, validate=True)
    with dpoint.Renderer(validate=True) as renderer:
        renderer.render(bulb, width=32, height=32)
    out, err = capfd.readouterr()
    assert err == "" and out == ""


def test_progress_true_may_print(tmp_path, capfd):
    bulb = dpoint.generate("mandelbulb", resolution=48, device="none", progress=True)
    _, err = capfd.readouterr()
    assert "points" in err  # generate's time line
    dpoint.write(bulb, tmp_path / "b.ply", progress=True)
    assert len(dpoint.read(tmp_path / "b.ply", progress=True)) == len(bulb)
    dpoint.info(bulb, progress=True)
    assert dpoint.render(bulb, width=64, height=48, validate=True, progress=True).image.any()
    assert np.array_equal(dpoint.read(tmp_path / "b.ply").positions, bulb.positions)
