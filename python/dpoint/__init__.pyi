# Type stub of the dpoint package (python/dpoint/__init__.py over the extension dpoint._dpoint).
from os import PathLike
from typing import Any, Iterable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathType = Union[str, PathLike[str]]
Points = Union["PointSet", npt.ArrayLike, PathType, Sequence[PathType], Any]  # Any: a pandas DataFrame

class Error(ValueError):
    """Bad input or a bad option: the CLI's message."""
    exit_code: int

class DeviceError(RuntimeError):
    """No usable Vulkan device, or a Vulkan fault."""
    exit_code: int

class RenderWarning(UserWarning): ...

class PointSet:
    def __init__(
        self,
        positions: npt.ArrayLike,
        colors: npt.ArrayLike | None = None,
        triangles: npt.ArrayLike | None = None,
        *,
        allow_nonfinite: bool = False,
    ) -> None: ...
    def __len__(self) -> int: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]: ...
    @property
    def colors(self) -> npt.NDArray[np.float32] | None: ...
    @colors.setter
    def colors(self, colors: npt.ArrayLike | None) -> None: ...
    @property
    def attributes(self) -> dict[str, npt.NDArray[Any]]: ...
    def set_attribute(self, name: str, values: npt.ArrayLike) -> None: ...
    def remove_attribute(self, name: str) -> None: ...
    @property
    def triangles(self) -> npt.NDArray[np.uint32] | None: ...
    @triangles.setter
    def triangles(self, triangles: npt.ArrayLike | None) -> None: ...
    @property
    def has_z(self) -> bool: ...
    z_up: bool
    viewpoint: tuple[float, float, float, float, float, float, float] | None
    crs: str | None
    def copy(self) -> PointSet: ...
    def __copy__(self) -> PointSet: ...
    def __deepcopy__(self, memo: dict[int, Any]) -> PointSet: ...
    @staticmethod
    def from_dataframe(frame: Any, *, allow_nonfinite: bool = False) -> PointSet: ...
    def to_dataframe(self) -> Any: ...

class RenderResult:
    @property
    def image(self) -> npt.NDArray[np.uint8]: ...
    mode: str
    backend: str
    device: str
    points: int
    predicted_bound_px: float
    bound_from_boxes: bool
    point_size: float
    gpu_ms: list[float]
    warnings: list[str]
    @property
    def error_px(self) -> dict[str, float] | None: ...
    @property
    def report(self) -> dict[str, Any] | None: ...
    def png(self) -> bytes: ...
    def save(self, path: PathType) -> None: ...
    def _repr_png_(self) -> bytes: ...

class Renderer:
    def __init__(self, device: str | int = "auto", *, validate: bool = False, max_device_memory: int | str | None = None) -> None: ...
    @property
    def device(self) -> str: ...
    def render(self, points: Points, mode: str = "auto", *, progress: bool = False, **options: Any) -> RenderResult: ...
    def close(self) -> None: ...
    def __enter__(self) -> Renderer: ...
    def __exit__(self, *exc: object) -> None: ...

def read(
    path: PathType,
    *,
    threads: int = 0,
    allow_nonfinite: bool = False,
    colors: str = "auto",
    max_memory: int | str | None = None,
    scene: int = -1,
    all_scenes: bool = False,
    max_points: int = 0,
    columns: str | Sequence[str] | None = None,
    progress: bool = False,
) -> PointSet: ...
def write(
    points: PointSet | npt.ArrayLike | Any,  # Any: a pandas DataFrame
    path: PathType,
    *,
    decimals: int = -1,
    ply_ascii: bool = False,
    ply_colors: str | None = None,
    pcd_encoding: str | None = None,
    las_scale: Optional[float] = None,
    crs: Optional[str] = None,
    order: str = "input",
    no_colors: bool = False,
    color_format: str = "linear",
    unique: bool = False,
    threads: int = 0,
    max_memory: int | str | None = None,
    progress: bool = False,
) -> None: ...
def sample(
    mesh: PointSet | PathType,
    count: int,
    *,
    method: str = "uniform",
    seed: int = 0,
    threads: int = 0,
    max_memory: int | str | None = None,
    progress: bool = False,
) -> PointSet: ...
def generate(kind: str, *, progress: bool = False, **options: Any) -> PointSet: ...
def info(
    points: Points,
    *,
    sample: int = 10000,
    threads: int = 0,
    allow_nonfinite: bool = False,
    stream: str = "auto",
    max_memory: int | str | None = None,
    columns: str | Sequence[str] | None = None,
    progress: bool = False,
    **camera: Any,
) -> dict[str, Any]: ...
def render(points: Points, mode: str = "auto", *, progress: bool = False, **options: Any) -> RenderResult: ...
def bench(suite: str = "ci", out: PathType = "bench-out", *, progress: bool = False, **options: Any) -> dict[str, Any]: ...
