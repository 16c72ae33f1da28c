"""Smear frames (SIGGRAPH 2024) on toonkit.Scene (type stubs)."""

import os
from typing import Any, Callable, Iterable, Mapping, Optional, Union

import numpy as np
import numpy.typing as npt

from ._native import Prepared as Prepared, Preparing as Preparing, Scene, Stream as Stream, Stylized as Stylized

def offsets(
    scene: Scene,
    smooth: int = 2,
    whole_body: bool = False,
    prune: Iterable[str] = (),
    camera: Optional[Union[str, int]] = None,
    progress: Optional[Callable[[str, float], Any]] = None,
    causal: bool = False,
    revolve: Iterable[str] = (),
) -> npt.NDArray[np.float32]: ...
def prepare(
    scene: Scene,
    smooth: int = 2,
    whole_body: bool = False,
    prune: Iterable[str] = (),
    camera: Optional[Union[str, int]] = None,
    weights: Optional[Mapping[str, Any]] = None,
    merge: Optional[str] = None,
    progress: Optional[Callable[[str, float], Any]] = None,
    causal: bool = False,
    revolve: Iterable[str] = (),
    colliders: Iterable[Union[str, Scene]] = (),
) -> Prepared: ...
def start_prepare(
    scene: Scene,
    smooth: int = 2,
    whole_body: bool = False,
    prune: Iterable[str] = (),
    camera: Optional[Union[str, int]] = None,
    weights: Optional[Mapping[str, Any]] = None,
    merge: Optional[str] = None,
    causal: bool = False,
    revolve: Iterable[str] = (),
    colliders: Iterable[Union[str, Scene]] = (),
) -> Preparing: ...
def stream(
    triangles: Any,
    vertices: int,
    smooth: int = 2,
    elongate: Optional[Mapping[str, Any]] = None,
    history: int = 6,
    ground: Optional[float] = None,
) -> Stream: ...
def stylize(
    prepared: Prepared,
    style: Union[Mapping[str, Any], str, os.PathLike[str]],
    progress: Optional[Callable[[str, float], Any]] = None,
    frames: Optional[tuple[int, int]] = None,
) -> Stylized: ...
def presets() -> list[dict[str, Any]]: ...
def parameters() -> dict[str, dict[str, Any]]: ...
def preset_function(
    name: str,
    beta_max: Optional[float] = None,
    kappa: Optional[float] = None,
    signed: bool = True,
) -> dict[str, Any]: ...
def style_toml(style: Mapping[str, Any]) -> str: ...
def save_style(path: Union[str, os.PathLike[str]], style: Mapping[str, Any]) -> str: ...
