"""Smear frames (SIGGRAPH 2024) on toonkit.Scene (type stubs)."""

from typing import Any, Callable, Iterable, Optional, Union

import numpy as np
import numpy.typing as npt

from ._native import Scene

def offsets(
    scene: Scene,
    smooth: int = 2,
    whole_body: bool = False,
    prune: Iterable[str] = (),
    camera: Optional[Union[str, int]] = None,
    progress: Optional[Callable[[str, float], Any]] = None,
) -> npt.NDArray[np.float32]: ...
