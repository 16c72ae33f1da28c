"""Smear frames (Basset, Bénard, Barla, SIGGRAPH 2024) on :class:`toonkit.Scene`.

Example::

    import toonkit
    scene = toonkit.load("assets/characters/RobotExpressive.glb", clip="Dance")
    delta = toonkit.smear.offsets(scene, smooth=2)   # float32 (frames, vertices), in [-1, 1]
"""

from __future__ import annotations

from typing import Callable, Iterable, Optional, Union

import numpy as np

from . import _native

__all__ = ["offsets"]


def offsets(
    scene: "_native.Scene",
    smooth: int = 2,
    whole_body: bool = False,
    prune: Iterable[str] = (),
    camera: Optional[Union[str, int]] = None,
    progress: Optional[Callable[[str, float], None]] = None,
) -> np.ndarray:
    """Motion offsets per frame and vertex (SMEAR Eqs. 1-9).

    Returns float32 ``(frames, vertices)`` in ``scene.positions``' vertex order: leading
    parts > 0, trailing parts < 0 -- the array ``toonkit smear offsets IN -o OUT.npy`` writes.

    ``smooth`` is the half-window N of SMEAR Eq. 2 (0 = off); ``whole_body`` treats each
    skinned character as one object (Fig. 14); ``prune`` names joints whose vertices follow
    their nearest kept ancestor; ``camera`` (name or index) measures motion relative to a
    camera. The GIL is released while computing. ``progress(stage, fraction)`` is called
    before and after.

    >>> scene = toonkit.load("assets/characters/RobotExpressive.glb", clip="Dance")
    >>> toonkit.smear.offsets(scene, prune=["Head"]).shape == scene.positions.shape[:2]
    True
    """
    if isinstance(prune, str):
        prune = [p for p in prune.split(",") if p]
    return _native.smear_offsets(
        scene, int(smooth), bool(whole_body), list(prune), camera, progress
    )
