"""Dynamic lines of action (SBIM 2015) (type stubs)."""

from typing import Any, Callable, Iterable, Mapping, Optional, Tuple, Union

import os

from ._native import Line as Line, Motion as Motion, Scene

STIFFNESS_RANGE: tuple[float, float]
DAMPING_RANGE: tuple[float, float]
BONE_SETS: list[tuple[str, str, str]]

def line(
    keystrokes: Iterable[Mapping[str, Any]],
    mode: str = "physics",
    fps: float = 24.0,
    progress: Optional[Callable[[str, float], Any]] = None,
    **options: Any,
) -> Line: ...
def animate(
    character: Union[Scene, str, os.PathLike[str]],
    line: Line,
    bones: Union[str, Iterable[str], None] = None,
    contacts: Union[str, Iterable[str], None] = None,
    twists: Union[str, Iterable[str], None] = None,
    pose: str = "rest",
    progress: Optional[Callable[[str, float], Any]] = None,
    canvas: Optional[Tuple[float, float]] = None,
    **options: Any,
) -> Motion: ...
def bone_chain(
    character: Union[str, os.PathLike[str]], bones: str, pose: str = "rest"
) -> list[str]: ...
def save_pose(
    path: Union[str, os.PathLike[str]],
    names: Iterable[str],
    parents: Iterable[int],
    heads: Any,
) -> str: ...
