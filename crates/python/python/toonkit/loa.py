"""Dynamic lines of action (Guay, Ronfard, Gleicher, Cani, SBIM 2015).

Example::

    import toonkit
    line = toonkit.loa.line([
        {"frame": 0, "points": [[0, 0], [50, 100]]},
        {"frame": 24, "points": [[0, 0], [-50, 100]], "stiffness": 80, "damping": 0.2},
    ])
    line.points   # float64 (frames, joints, 2)
"""

from __future__ import annotations

import json
from typing import Any, Callable, Iterable, Mapping, Optional, Union

import numpy as np

from . import _native
from ._native import Line

__all__ = ["Line", "line"]


def _keystrokes_json(keystrokes: Iterable[Mapping[str, Any]], fps: Optional[float]) -> str:
    keys = []
    for i, k in enumerate(keystrokes):
        if not isinstance(k, Mapping) or "frame" not in k or "points" not in k:
            raise ValueError(
                f"keystroke {i} must be a dict with \"frame\" and \"points\" ((n, 2) array)"
            )
        points = np.asarray(k["points"], dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 2:
            raise ValueError(f"keystroke {i}: points must have shape (n, 2), got {points.shape}")
        entry = {"frame": float(k["frame"]), "points": points.tolist()}
        for opt in ("stiffness", "damping"):
            if k.get(opt) is not None:
                entry[opt] = float(k[opt])
        unknown = set(k) - {"frame", "points", "stiffness", "damping"}
        if unknown:
            raise ValueError(f"keystroke {i}: unknown key(s) {sorted(unknown)}")
        keys.append(entry)
    doc: dict = {"keystrokes": keys}
    if fps is not None:
        doc["fps"] = float(fps)
    return json.dumps(doc, allow_nan=True)


def line(
    keystrokes: Iterable[Mapping[str, Any]],
    mode: str = "physics",
    fps: float = 24.0,
    elements: int = 10,
    substeps: int = 8,
    simulated_frames: Union[int, str] = 40,
    progress: Optional[Callable[[str, float], None]] = None,
) -> "Line":
    """A dynamic line of action through sketched keystrokes (LoA Eqs. 1-2).

    ``keystrokes`` is a list of ``{"frame": f, "points": (n, 2) array}`` dicts (optionally
    ``"stiffness"`` and ``"damping"`` per keystroke), frames strictly increasing. ``mode`` is
    ``"physics"`` (elastic chain re-targeted onto every keystroke) or ``"hermite"``.
    ``elements`` rigid elements per chain, ``substeps`` integration steps per frame,
    ``simulated_frames`` frames simulated per interval (or ``"gap"``) -- the CLI's
    ``toonkit loa line`` options. Returns a :class:`Line` with ``.points``
    ``(frames, joints, 2)``, ``.angles``, ``.lengths`` and ``.save(path)``.

    >>> l = toonkit.loa.line([{"frame": 0, "points": [[0, 0], [1, 2]]},
    ...                       {"frame": 12, "points": [[0, 0], [-1, 2]]}])
    >>> l.points.shape[0]
    13
    """
    return _native.loa_line(
        _keystrokes_json(keystrokes, None),
        mode,
        float(fps),
        int(elements),
        int(substeps),
        simulated_frames,
        progress,
    )
