"""Replacement libraries for 3D-printed stop-motion (type stubs)."""

from typing import Any, Callable, Iterable, Mapping, Optional, Sequence, Union

from ._native import Library as Library, Scene, Segmented as Segmented

Seeds = Iterable[Union[int, Sequence[float]]]

def segment(
    scene: Scene,
    parts: Optional[Mapping[str, Seeds]] = None,
    gamma: Optional[float] = None,
    homogenize: bool = True,
    progress: Optional[Callable[[str, float], Any]] = None,
    **options: Any,
) -> Segmented: ...
def library(
    segmented: Segmented,
    pieces: Union[int, Mapping[str, int]] = 20,
    progress: Optional[Callable[[str, float], Any]] = None,
    **options: Any,
) -> Library: ...
def run(
    scene: Scene,
    parts: Optional[Mapping[str, Seeds]] = None,
    pieces: Union[int, Mapping[str, int]] = 20,
    gamma: Optional[float] = None,
    homogenize: bool = True,
    progress: Optional[Callable[[str, float], Any]] = None,
    **options: Any,
) -> Library: ...
