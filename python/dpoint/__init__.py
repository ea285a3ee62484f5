"""dpoint: double-precision point datasets, from Python.

The same libraries as the ``dpoint`` executable, with NumPy arrays in and out:

    import dpoint
    bulb = dpoint.generate("mandelbulb", resolution=128, offset=(6.371e6, 0, 0))
    result = dpoint.render(bulb, mode="native", error=True)
    print(result.mode, result.predicted_bound_px, result.error_px)
    result.save("bulb.png")

Options are the CLI's, as keyword arguments: ``view_width=0.5`` is ``--view-width 0.5``, a sequence
is a comma list (``eye=(0, 0, 5)`` is ``--eye 0,0,5``), ``True`` gives a flag and ``False`` or
``None`` leaves the option out. They are parsed, checked and defaulted by the CLI's own parser, so
``dpoint generate KIND --help`` and ``dpoint render --help`` document them and a bad one raises the
CLI's message, naming the keyword (``view_width -3: must be ...``).

Errors: ``dpoint.Error`` (a ``ValueError``) for bad input or options, ``MemoryError`` for
resource limits, ``dpoint.DeviceError`` (a ``RuntimeError``) for a missing device or a Vulkan
fault; each carries the CLI's exit code as ``exit_code``. Ctrl-C stops a long call within about a
second with ``KeyboardInterrupt`` and leaves no output file. Long calls release the GIL.
"""

from __future__ import annotations

import difflib as _difflib
import json as _json
import numbers as _numbers
import os as _os
import re as _re
import warnings as _warnings

from ._dpoint import DeviceError, Error, PointSet, RenderResult, __version__  # noqa: F401
from . import _dpoint

__all__ = [
    "DeviceError", "Error", "PointSet", "RenderResult", "Renderer", "RenderWarning", "__version__",
    "bench", "generate", "info", "read", "render", "sample", "write",
]


class RenderWarning(UserWarning):
    """A picture that is likely wrong or poor (render's warnings: a mode over half a pixel, a speck)."""


def _plain(value):
    """A NumPy scalar as the Python value it holds: numpy.True_ as True (a flag), numpy.int64(3) as 3."""
    if getattr(value, "ndim", None) == 0 and hasattr(value, "item"):
        return value.item()
    return value


def _value(value) -> str:
    value = _plain(value)
    if isinstance(value, bool):
        raise TypeError("a flag takes True or False only as the whole value")
    if isinstance(value, str):
        if "\0" in value:
            raise ValueError(f"embedded null byte in {value!r}")
        return value
    # float() and int() first: a subclass's repr is its own (NumPy 2 gives "np.float64(0.5)").
    if isinstance(value, _numbers.Integral):
        return str(int(value))
    if isinstance(value, _numbers.Real):
        return repr(float(value))  # the shortest text that reads back to the same double
    if isinstance(value, _os.PathLike):
        return _fspath(value)
    try:
        items = list(value)
    except TypeError:
        return str(value)
    return ",".join(_value(v if isinstance(v, (_numbers.Real, str)) else float(v)) for v in items)


def _column_names(columns):
    """columns= of read and info: "x,y,z,-,i" or ["x", "y", "z", "-", "i"] as a list of names."""
    if columns is None:
        return None
    if isinstance(columns, str):
        return columns.split(",")
    # bytes were taken as a list of numbers (a review finding: b"x,y,z" gave "--columns 44: named twice").
    if isinstance(columns, (bytes, bytearray)) or not all(isinstance(c, str) for c in columns):
        raise TypeError(f"columns: a str such as 'x,y,z,-,intensity' or a list of str, not {columns!r}")
    return list(columns)


def _usage_error(message: str) -> Error:
    """dpoint.Error with the CLI's exit code of a usage error (1)."""
    error = Error(message)
    error.exit_code = 1
    return error


# Options that take a whole number of 0 or more, and the most each takes: a negative one gave
# pybind11's dump of the whole signature (a review finding).
_WHOLE = {"threads": 2**32 - 1, "count": 2**64 - 1, "seed": 2**64 - 1, "max_points": 2**64 - 1}


def _check_whole(name: str, key: str, value) -> None:
    most = _WHOLE.get(key)
    if most is not None and isinstance(value, _numbers.Integral) and not isinstance(value, bool) \
            and not 0 <= value <= most:
        raise _usage_error(f"{name}: {key} {value}: must be a whole number from 0 to {most}")


def _python_words(text: str) -> str:
    """A CLI message with the keyword arguments' names for its flags (every one but --help; every
    option of a command is a keyword): "width -5: ..." for width=-5, where it said "--width -5:
    ..." (a review finding). A flag starts the message or follows a space, a quote or a bracket:
    "--" inside a file's name is left as it is (/tmp/no--such.csv was named /tmp/nosuch.csv)."""
    return _re.sub(r"(?<![^\s'\"(`])--(?!help\b)([a-z][a-z0-9]*(?:-[a-z0-9]+)*)(?![\w-])",
                   lambda m: m.group(1).replace("-", "_"), text)


class _PythonWords:
    """Errors raised inside speak of keyword arguments (_python_words)."""

    def __enter__(self):
        return self

    def __exit__(self, kind, error, trace):
        if isinstance(error, (Error, MemoryError, DeviceError)) and error.args and isinstance(error.args[0], str):
            error.args = (_python_words(error.args[0]),) + error.args[1:]
        return False


def _args(options: dict) -> list[str]:
    """Keyword arguments as the CLI's options: view_width=0.5 is ["--view-width", "0.5"]."""
    if "help" in options or "h" in options:
        raise TypeError("help is the CLI's option: help(dpoint.NAME) documents a function, `dpoint COMMAND --help` "
                        "its options")
    args = []
    for key, value in options.items():
        value = _plain(value)
        if value is None or value is False:
            continue
        flag = "--" + key.replace("_", "-")
        if value is True:
            args.append(flag)
        else:
            args += [flag, _value(value)]
    return args


def _fspath(path):
    """os.fspath, refusing an embedded NUL as open() does: the library would cut the path there and
    read or write another file."""
    text = _os.fspath(path)
    if ("\0" if isinstance(text, str) else b"\0") in text:
        raise ValueError(f"embedded null byte in the path {text!r}")
    return text


def _as_points(points):
    """(PointSet, []) for a set in memory, (None, paths) for files."""
    if isinstance(points, PointSet):
        return points, []
    if isinstance(points, (str, _os.PathLike)):
        return None, [_fspath(points)]
    if isinstance(points, (list, tuple)) and points and all(isinstance(p, (str, _os.PathLike)) for p in points):
        return None, [_fspath(p) for p in points]
    if hasattr(points, "columns") and hasattr(points, "to_numpy"):  # a pandas DataFrame
        return PointSet.from_dataframe(points), []
    return PointSet(points), []


def _from_dataframe(frame, *, allow_nonfinite: bool = False) -> PointSet:
    """A PointSet from a pandas DataFrame with columns x, y[, z][, r, g, b] and any others.

    r, g, b: integers 0..255 (as CSV files hold them) or floats 0..1 (linear). Without z the set is 2D.
    Every other column is an attribute in its dtype (integers, floats, bool), as to_dataframe gives them.
    """
    columns = {}
    for c in frame.columns:
        known = str(c).lower()
        if known in ("x", "y", "z", "r", "g", "b") and known in columns:
            raise Error(f"DataFrame: columns {columns[known]!r} and {c!r} are both {known} (names are taken in any case)")
        columns.setdefault(known, c)
    missing = [c for c in ("x", "y") if c not in columns]
    if missing:
        raise Error(f"DataFrame: no column {', '.join(missing)} (columns: {', '.join(map(str, frame.columns))})")
    axes = ["x", "y"] + (["z"] if "z" in columns else [])
    positions = frame[[columns[a] for a in axes]].to_numpy(dtype="float64")
    colors = None
    if all(c in columns for c in ("r", "g", "b")):
        rgb = frame[[columns[c] for c in ("r", "g", "b")]]
        if all(k.kind in "iu" for k in rgb.dtypes):
            values = rgb.to_numpy()
            if values.size and (values.min() < 0 or values.max() > 255):
                raise Error("DataFrame: integer colours r, g, b must lie in 0..255")
            colors = values.astype("uint8")
        else:
            colors = rgb.to_numpy(dtype="float32")
    points = PointSet(positions, colors, allow_nonfinite=allow_nonfinite)
    used = set(axes) | ({"r", "g", "b"} if colors is not None else set())
    for column in frame.columns:
        if str(column).lower() in used:
            continue
        series = frame[column]
        # pandas' nullable Int64, Float64 and boolean (convert_dtypes) as their NumPy dtypes where no
        # value is missing: to_numpy() gives them as objects.
        numpy_dtype = getattr(series.dtype, "numpy_dtype", None)
        values = series.to_numpy(dtype=numpy_dtype) if numpy_dtype is not None and not series.isna().any() else series.to_numpy()
        if values.dtype.kind not in "biuf":
            raise Error(f"DataFrame: column {column!r} is {values.dtype}, not numbers: "
                        "an attribute holds integers, floats or bools")
        points.set_attribute(str(column), values)
    return points


def _to_dataframe(self):
    """The set as a pandas DataFrame: x, y, z (float64; no z for a 2D set), with colours r, g, b
    (float32, 0..1), then one column per attribute in its own dtype. The values are copied."""
    import pandas as pd

    data = {"x": self.positions[:, 0], "y": self.positions[:, 1]}
    if self.has_z:
        data["z"] = self.positions[:, 2]
    if self.colors is not None:
        data.update(r=self.colors[:, 0], g=self.colors[:, 1], b=self.colors[:, 2])
    # An attribute named as a position's or colour's column (a PLY property r, one named X) gets a
    # column of its own, "r_2", with a warning: it overwrote the colour, or from_dataframe took it
    # for the position.
    known = {"x", "y", "z", "r", "g", "b"}  # in any case, as from_dataframe takes them
    for name, values in self.attributes.items():
        column, k = name, 2
        while column.lower() in known or column in data:
            column, k = f"{name}_{k}", k + 1
        if column != name:
            _warnings.warn(f"to_dataframe: attribute {name!r} is column {column!r} ({name.lower()} names the "
                           "position's or colour's column)", UserWarning, stacklevel=2)
        data[column] = values
    return pd.DataFrame(data, copy=True)


def _restore_point_set(state) -> PointSet:
    """A PointSet from PointSet.__getstate__'s state (pickle's way back)."""
    points = PointSet.__new__(PointSet)
    points.__setstate__(state)
    return points


def _not_pickled(self):
    raise TypeError(f"cannot pickle a dpoint.{type(self).__name__}")


# Pickled by __reduce__ in every protocol: protocols 0 and 1 went through copyreg, which made a
# bare pybind11 object and aborted the interpreter (a review finding).
PointSet.__reduce__ = lambda self: (_restore_point_set, (self.__getstate__(),))
RenderResult.__reduce__ = _not_pickled
_dpoint._Renderer.__reduce__ = _not_pickled
PointSet.from_dataframe = staticmethod(_from_dataframe)
PointSet.to_dataframe = _to_dataframe
RenderResult.report = property(
    lambda self: _json.loads(self._report_json) if self._report_json else None,
    doc="render --json's object as a dict (None for a contact sheet)")
RenderResult.warnings = property(
    lambda self: [_python_words(line) for line in self._warnings],
    doc="What makes the picture wrong or poor, as the CLI's warnings (options named as keywords)")
RenderResult._repr_png_ = lambda self: self.png()


def _result_repr(self: RenderResult) -> str:
    try:
        image = self.image
    except TypeError:  # made by __new__ alone: a repr that raises hides the object in a debugger
        return "<dpoint.RenderResult: holds nothing (made by __new__ without __init__)>"
    return (f"<dpoint.RenderResult: {image.shape[1]}x{image.shape[0]}, {self.points} points, mode {self.mode}, "
            f"{self.backend} backend, bound {self.predicted_bound_px:.3g} px>")


RenderResult.__repr__ = _result_repr


def _warn(result: RenderResult) -> RenderResult:
    # Shown at the caller's line: _warn <- _render <- render or Renderer.render <- the caller.
    for line in result.warnings:
        _warnings.warn(line, RenderWarning, stacklevel=4)
    return result


class Renderer:
    """One Vulkan device kept across renders: a loop over views or modes starts the device once.

    Renderer(device="auto", validate=False, max_device_memory=None); render() takes what
    dpoint.render takes but device, validate and max_device_memory, which are the Renderer's.
    Use it as a context manager, or close() it, to give the device back.
    """

    def __init__(self, device: str | int = "auto", *, validate: bool = False, max_device_memory=None):
        limit = _dpoint._memory_size("max_device_memory", max_device_memory)
        self._renderer = _dpoint._Renderer(str(device), validate, limit)

    @property
    def device(self) -> str:
        """The device's name."""
        return self._renderer.device

    def render(self, points, mode: str = "auto", *, progress: bool = False, **options) -> RenderResult:
        for own in ("device", "validate", "max_device_memory"):
            if own in options:
                raise TypeError(f"Renderer.render: {own} is the Renderer's (Renderer({own}=...))")
        return _render(points, mode, self._renderer, progress, options)

    def close(self) -> None:
        self._renderer.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _render(points, mode, renderer, progress, options) -> RenderResult:
    if "json" in options or "output" in options or "o" in options:
        raise TypeError("render: the picture and the report come back in the result (result.save(path), result.report)")
    in_memory, inputs = _as_points(points)
    args = _args({"mode": mode, **options})
    with _PythonWords():
        return _warn(_dpoint._render(in_memory, inputs, args, renderer, progress))


def render(points, mode: str = "auto", *, progress: bool = False, **options) -> RenderResult:
    """Renders a set offscreen with Vulkan, as ``dpoint render`` does, and returns the picture.

    points: a PointSet, an (N, 3) array, a pandas DataFrame, or a file path (or a list of them,
    drawn as one). mode: auto or a precision mode (fp32, split, rte, df64, native, batch,
    adaptive). Every other option of ``dpoint render`` is a keyword: width, height, eye, target,
    up, fit, fov, ortho, view_center, view_width, tolerance, backend, point_size, background,
    shade, color, order, views, error, frames, warmup, device, validate, … Each call starts a
    Vulkan device; a Renderer keeps one across calls.
    """
    return _render(points, mode, None, progress, options)


def _keywords(name: str, function, options: dict) -> dict:
    """read's, write's and sample's options checked against the names `function` takes (its
    signature), with "did you mean" for a misspelt one (pybind11 printed its whole signature), None
    leaving an option out as everywhere else, and NumPy scalars as their Python values."""
    known = _re.findall(r"(\w+): ", function.__doc__.splitlines()[0].split("*,", 1)[1])
    out = {}
    for key, value in options.items():
        if key not in known:
            close = _difflib.get_close_matches(key, known, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else f" (its options: {', '.join(known)})"
            raise TypeError(f"{name}: no option {key!r}{hint}")
        value = _plain(value)
        _check_whole(name, key, value)
        if value is not None:
            out[key] = value
    return out


def read(path, **options) -> PointSet:
    options = _keywords("read", _dpoint.read, options)
    if "columns" in options:
        options["columns"] = _column_names(options["columns"])
    with _PythonWords():
        return _dpoint.read(_fspath(path), **options)


def write(points, path, **options) -> None:
    options = _keywords("write", _dpoint.write, options)
    points, _ = _as_points(points) if not isinstance(points, PointSet) else (points, None)
    if points is None:
        raise TypeError("write: points must be a PointSet or an array, not a file name")
    try:
        _dpoint.write(points, _fspath(path), **options)
    except (Error, MemoryError) as e:  # the CLI's advice and flags in the module's words
        e.args = (_python_words(_re.sub(r"--drop (\w+)", r"points.remove_attribute('\1') (on a copy)", str(e))),)
        raise


def sample(mesh, count, **options) -> PointSet:
    options = _keywords("sample", _dpoint.sample, options)
    count = _plain(count)
    _check_whole("sample", "count", count)
    with _PythonWords():
        if isinstance(mesh, (str, _os.PathLike)):  # read with its textures, which colour the samples
            return _dpoint._sample_file(_fspath(mesh), count, **options)
        return _dpoint.sample(mesh, count, **options)


read.__doc__ = _dpoint.read.__doc__
write.__doc__ = _dpoint.write.__doc__
sample.__doc__ = _dpoint.sample.__doc__


def generate(kind: str, *, progress: bool = False, **options) -> PointSet:
    """Generates a dataset as ``dpoint generate KIND`` does, and returns it instead of writing it.

    kind: mandelbulb, menger, sierpinski, julia, random2d, mandelbrot2d. Every option of
    ``dpoint generate KIND`` is a keyword (``dpoint generate KIND --help`` lists them), e.g.
    resolution=200, variant="seed", colors="noise", offset=(6.371e6, 0, 0), order="morton",
    device="none". The points are the bytes the CLI writes: ``write(generate(k, **o), path)`` gives
    the file ``dpoint generate k ... -o path`` gives. progress: lines on stderr.
    """
    if not isinstance(kind, str):
        raise TypeError("generate: kind must be a string such as 'mandelbulb'")
    with _PythonWords():
        return _dpoint._generate(kind, _args(options), progress)


def info(points, *, sample: int = 10000, threads: int = 0, allow_nonfinite: bool = False, stream: str = "auto",
         max_memory=None, columns=None, progress: bool = False, **camera) -> dict:
    """The facts ``dpoint info --json`` prints, as a dict: counts, bounds, whether float32 holds the
    set, and each mode's predicted error bound in pixels for the view (error_bound_px).

    points: a PointSet, an array, a DataFrame, or files. camera: render's camera options (width,
    height, eye, target, up, fit, fov, ortho, view_center, view_width, tolerance). sample: points
    sampled for the nearest-neighbour distance. columns: text files, what each column holds (as
    read's columns).
    """
    sample, threads = _plain(sample), _plain(threads)
    _check_whole("info", "threads", threads)
    if isinstance(sample, bool) or not isinstance(sample, _numbers.Integral) or not 1 <= sample <= 100_000_000:
        raise _usage_error(f"sample {sample!r}: must be a number from 1 to 100000000")
    in_memory, inputs = _as_points(points)
    if in_memory is not None:  # options of reading files (a review finding: passed over in silence)
        given = [name for name, value, default in (("stream", stream, "auto"), ("allow_nonfinite", allow_nonfinite, False),
                                                   ("columns", columns, None))
                 if value != default]
        if given:
            raise _usage_error(f"info: {' and '.join(given)} {'applies' if len(given) == 1 else 'apply'} to files, "
                              "not to a set in memory")
    limit = _dpoint._memory_size("max_memory", max_memory)
    with _PythonWords():
        text = _dpoint._info(in_memory, inputs, _args(camera), sample, threads, allow_nonfinite, stream, limit,
                             _column_names(columns) or [], progress)
    return _json.loads(text)


def _executable() -> str:
    """The dpoint executable bench runs its draws with: $DPOINT_EXECUTABLE, the build tree's, the
    installed one, or the PATH's."""
    import shutil

    here = _os.path.dirname(_os.path.abspath(__file__))
    for candidate in (_os.environ.get("DPOINT_EXECUTABLE"), _os.path.join(here, "..", "..", "dpoint"),
                      _os.path.join(_dpoint._install_prefix, "bin", "dpoint"), shutil.which("dpoint")):
        if candidate and _os.path.isfile(candidate) and _os.access(candidate, _os.X_OK):
            return _os.path.realpath(candidate)
    raise Error("bench: no dpoint executable found (set DPOINT_EXECUTABLE)")


def bench(suite: str = "ci", out="bench-out", *, progress: bool = False, **options) -> dict:
    """Runs ``dpoint bench`` (the speed-against-error report) and returns its results.json as a dict.

    suite: ci, paper, hard or all; out: the report's folder (report.md, results.json, charts,
    montage). Every other option of ``dpoint bench`` is a keyword (cache, device, backend, frames,
    warmup, sizes, no_error, validate, …). Its timed draws run the dpoint executable
    (``DPOINT_EXECUTABLE``, else the one built or installed with this module).
    """
    _os.environ["DPOINT_EXECUTABLE"] = _executable()
    with _PythonWords():
        _dpoint._bench(_args({"suite": suite, "out": _fspath(out), **options}), progress)
    with open(_os.path.join(_fspath(out), "results.json"), encoding="utf-8") as f:
        return _json.load(f)
