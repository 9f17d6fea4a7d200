"""MorphFX for Python: scenes, images as numpy arrays, and renders through the
MorphFX nodes, pixel for pixel as the `morphfx` command line renders them."""

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union, final

import numpy as np
import numpy.typing as npt

__version__: str
__all__ = [
    "__version__",
    "Error",
    "SceneError",
    "ImageError",
    "ParamError",
    "RenderError",
    "Scene",
    "read_image",
    "write_image",
    "morph",
    "warp",
    "stmap",
    "params",
    "last_render_seconds",
    "build",
    "track",
    "snap",
    "suggest",
]
_Path = Union[str, "os.PathLike[str]"]
#: A picture: a float32 ``(H, W, C)`` array (any array-like is converted), row 0 the top row.
_Picture = npt.ArrayLike
#: A plate: a picture, or an image file's path (``#``-numbered for a sequence).
_Plate = Union[_Path, npt.ArrayLike]
#: A node param's value: a number, bool, option name or pair, or ``{frame: value}`` keys.
_ParamValue = Union[float, int, bool, str, Sequence[float], Dict[float, Any]]
_Params = Dict[str, _ParamValue]
_Image = npt.NDArray[np.float32]

class Error(Exception): ...
class SceneError(Error): ...
class ImageError(Error): ...
class ParamError(Error): ...
class RenderError(Error): ...

@final
class Scene:
    @staticmethod
    def load(path: _Path) -> Scene: ...
    @staticmethod
    def from_json(text: str) -> Scene: ...
    def to_json(self) -> str: ...
    def save(self, path: _Path) -> None: ...
    @property
    def features(self) -> List[Dict[str, Any]]: ...
    @property
    def keyframes(self) -> List[Dict[str, Any]]: ...
    @property
    def method(self) -> str: ...
    def with_(self, key: str, value: Any) -> Scene: ...

_SceneLike = Union[Scene, _Path]

def read_image(path: _Path, *, raw: bool = False) -> _Image: ...
def write_image(
    path: _Path,
    image: _Picture,
    *,
    half: bool = False,
    compression: Optional[str] = None,
    raw: bool = False,
) -> None: ...
def morph(
    scene: Optional[_SceneLike],
    a: _Picture,
    b: _Picture,
    t: Optional[float] = None,
    frame: Optional[float] = None,
    view: str = "morph",
    params: Optional[_Params] = None,
    *,
    mask: Optional[_Picture] = None,
    timing: Optional[_Picture] = None,
) -> _Image: ...
def warp(
    scene: Optional[_SceneLike],
    a: _Picture,
    t: Optional[float] = None,
    frame: Optional[float] = None,
    view: str = "morph",
    params: Optional[_Params] = None,
    *,
    mask: Optional[_Picture] = None,
) -> _Image: ...
def stmap(
    scene: Optional[_SceneLike],
    side: str,
    t: float,
    width: int,
    height: int,
    *,
    frame: Optional[float] = None,
    params: Optional[_Params] = None,
    a: Optional[_Picture] = None,
    b: Optional[_Picture] = None,
) -> _Image: ...
def params(node: str = "morph") -> List[str]: ...
def last_render_seconds() -> float: ...
def build() -> str: ...
def track(
    scene: _SceneLike,
    a: Union[_Path, Sequence[_Picture]],
    b: Optional[Union[_Path, Sequence[_Picture]]] = None,
    *,
    frames: Union[str, Tuple[int, int]],
    radius: int = 12,
    min_correlation: float = 0.75,
) -> Scene: ...
def snap(
    scene: _SceneLike,
    a: _Plate,
    b: _Plate,
    *,
    frame: Optional[float] = None,
    sigma: float = 3.0,
    iterations: int = 200,
    clamp_controls: bool = False,
) -> Scene: ...
def suggest(
    a: Union[_Plate, Sequence[_Picture]],
    b: Union[_Plate, Sequence[_Picture]],
    *,
    frames: Optional[Union[str, Tuple[int, int]]] = None,
    at: Optional[int] = None,
    scene: Optional[_SceneLike] = None,
    count: int = 40,
    min_confidence: float = 0.5,
    method: Optional[str] = None,
) -> Scene: ...
