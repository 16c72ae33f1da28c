"""Type stubs of the compiled core (import ``toonkit`` instead)."""

import os
from typing import Any, Callable, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class ToonkitError(Exception):
    """A toonkit file or computation failed; the message is the CLI's one-line error."""

class Scene:
    """A clip sampled at a fixed frame rate (objects merged in order)."""

    @staticmethod
    def from_arrays(
        positions: Optional[npt.ArrayLike],
        triangles: npt.ArrayLike,
        fps: float = 24.0,
        skin: Optional[Mapping[str, Any]] = None,
        objects: Optional[Sequence[tuple[str, range]]] = None,
        attributes: Optional[Mapping[str, npt.ArrayLike]] = None,
        rest: Optional[npt.ArrayLike] = None,
        skinning: Optional[
            Union[tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike, npt.ArrayLike], SkinStream]
        ] = None,
    ) -> Scene: ...
    @property
    def positions(self) -> npt.NDArray[np.float32]: ...
    @property
    def triangles(self) -> npt.NDArray[np.int32]: ...
    @property
    def fps(self) -> float: ...
    @property
    def frame_count(self) -> int: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def size(self) -> float: ...
    @property
    def joint_names(self) -> list[str]: ...
    @property
    def cameras(self) -> list[str]: ...
    @property
    def objects(self) -> list[tuple[str, range]]: ...
    @property
    def skin(self) -> Optional[dict[str, Any]]: ...

def load(
    path: Union[str, os.PathLike[str]],
    clip: Optional[Union[str, int]] = None,
    fps: float = 24.0,
) -> Scene: ...
class SkinStream:
    """``toonkit.skin`` fed a few frames at a time, skinning on a worker thread."""

    def __init__(
        self,
        rest: npt.ArrayLike,
        indices: npt.ArrayLike,
        weights: npt.ArrayLike,
        frames: int,
        bones: int,
    ) -> None: ...
    def push(self, matrices: npt.ArrayLike) -> None: ...

def skin(
    rest: npt.ArrayLike,
    indices: npt.ArrayLike,
    weights: npt.ArrayLike,
    matrices: npt.ArrayLike,
) -> npt.NDArray[np.float32]: ...
def smear_offsets(
    scene: Scene,
    smooth: int = 2,
    whole_body: bool = False,
    prune: Sequence[str] = ...,
    camera: Optional[Union[str, int]] = None,
    progress: Optional[Callable[[str, float], Any]] = None,
) -> npt.NDArray[np.float32]: ...

class Line:
    """An animated line of action: one chain of joints per frame."""

    @property
    def points(self) -> npt.NDArray[np.float64]: ...
    @property
    def angles(self) -> npt.NDArray[np.float64]: ...
    @property
    def lengths(self) -> npt.NDArray[np.float64]: ...
    @property
    def frames(self) -> list[int]: ...
    @property
    def keystroke_frames(self) -> list[int]: ...
    @property
    def fps(self) -> float: ...
    @property
    def warnings(self) -> list[str]: ...
    def to_json(self) -> str: ...
    def save(self, path: Union[str, os.PathLike[str]]) -> os.PathLike[str]: ...

def loa_line(
    keystrokes_json: str,
    options_json: str,
    progress: Optional[Callable[[str, float], Any]] = None,
) -> Line: ...

class Prepared:
    """Motion offsets solved once for any number of stylize calls."""

    @property
    def offsets(self) -> npt.NDArray[np.float32]: ...
    @property
    def report(self) -> dict[str, Any]: ...
    def report_json(self) -> str: ...

class Preparing:
    """prepare running on a thread of its own."""

    def result(self) -> Prepared: ...

class Stream:
    def __init__(self, triangles: Any, vertices: int, options_json: Optional[str] = None) -> None: ...
    def push(self, positions: Any) -> npt.NDArray[np.float32]: ...
    @property
    def offsets(self) -> npt.NDArray[np.float32]: ...
    @property
    def frames_pushed(self) -> int: ...

class Stylized:
    """A style's result: elongated positions, multiple in-betweens, motion lines."""

    @property
    def elongated(self) -> npt.NDArray[np.float32]: ...
    @property
    def multiples(self) -> list[dict[str, Any]]: ...
    @property
    def lines(self) -> list[dict[str, Any]]: ...
    @property
    def first_frame(self) -> int: ...
    @property
    def report(self) -> dict[str, Any]: ...
    def report_json(self) -> str: ...
    def save(self, path: Union[str, os.PathLike[str]]) -> os.PathLike[str]: ...

def smear_prepare(
    scene: Scene,
    smooth: int = 2,
    whole_body: bool = False,
    prune: Sequence[str] = ...,
    camera: Optional[Union[str, int]] = None,
    options_json: Optional[str] = None,
    progress: Optional[Callable[[str, float], Any]] = None,
    causal: bool = False,
    revolve: Sequence[str] = ...,
    collider_scenes: Sequence[Scene] = ...,
) -> Prepared: ...
def smear_start_prepare(
    scene: Scene,
    smooth: int = 2,
    whole_body: bool = False,
    prune: Sequence[str] = ...,
    camera: Optional[Union[str, int]] = None,
    options_json: Optional[str] = None,
    causal: bool = False,
    revolve: Sequence[str] = ...,
    collider_scenes: Sequence[Scene] = ...,
) -> Preparing: ...
def smear_stylize(
    prepared: Prepared,
    style_json: Optional[str] = None,
    style_path: Optional[str] = None,
    progress: Optional[Callable[[str, float], Any]] = None,
    frames: Optional[tuple[int, int]] = None,
) -> Stylized: ...
def loa_save_pose(
    path: str, names: Sequence[str], parents: Sequence[int], heads: npt.NDArray[np.float64]
) -> str: ...
def loa_bone_chain(path: str, bones: str, pose: str) -> list[str]: ...
def smear_presets() -> str: ...
def smear_parameters() -> str: ...
def smear_preset_function(name: str, beta_max: float, kappa: float, signed: bool = True) -> str: ...
def smear_save_style(path: str, style_json: str) -> str: ...
def smear_style_toml(style_json: str) -> str: ...

class Motion:
    """Joint motion synthesized from a line of action."""

    @property
    def rotations(self) -> npt.NDArray[np.float64]: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]: ...
    @property
    def joint_names(self) -> list[str]: ...
    @property
    def fps(self) -> float: ...
    @property
    def first_frame(self) -> int: ...
    @property
    def report(self) -> dict[str, Any]: ...
    def save(self, path: Union[str, os.PathLike[str]]) -> os.PathLike[str]: ...

def loa_animate(
    character: Union[Scene, str],
    line: Line,
    bones: Sequence[str],
    contacts: Sequence[str],
    twists: Sequence[str],
    pose: str,
    options_json: str,
    progress: Optional[Callable[[str, float], Any]] = None,
    canvas: Optional[Tuple[float, float]] = None,
) -> Motion: ...

class Segmented:
    """Parts of a segmented animation."""

    @property
    def part_names(self) -> list[str]: ...
    @property
    def labels(self) -> npt.NDArray[np.int32]: ...
    @property
    def parts(self) -> list[dict[str, Any]]: ...
    @property
    def report(self) -> dict[str, Any]: ...
    def save(self, path: Union[str, os.PathLike[str]]) -> os.PathLike[str]: ...

class Library:
    """A replacement library: pieces, per-frame labels, assembly, report."""

    @property
    def part_names(self) -> list[str]: ...
    @property
    def labels(self) -> npt.NDArray[np.int32]: ...
    @property
    def pieces(self) -> list[dict[str, Any]]: ...
    @property
    def assembly(self) -> list[list[str]]: ...
    @property
    def report(self) -> dict[str, Any]: ...
    def save(self, dir: Union[str, os.PathLike[str]]) -> list[str]: ...

def stopmo_segment(
    scene: Scene, options_json: str, progress: Optional[Callable[[str, float], Any]] = None
) -> Segmented: ...
def stopmo_library(
    segmented: Segmented, options_json: str, progress: Optional[Callable[[str, float], Any]] = None
) -> Library: ...
def stopmo_run(
    scene: Scene, options_json: str, progress: Optional[Callable[[str, float], Any]] = None
) -> Library: ...

LOA_STIFFNESS_RANGE: tuple[float, float]
LOA_DAMPING_RANGE: tuple[float, float]
LOA_BONE_SETS: list[tuple[str, str, str]]
