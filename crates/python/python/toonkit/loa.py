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
from typing import Any, Callable, Iterable, Mapping, Optional, Tuple, Union

import numpy as np

import os

from . import _native
from ._native import Line, Motion

#: The documented stiffness range (1/s², inclusive); a keystroke outside it raises ValueError.
STIFFNESS_RANGE: tuple = _native.LOA_STIFFNESS_RANGE
#: The documented damping-ratio range (inclusive); a keystroke outside it raises ValueError.
DAMPING_RANGE: tuple = _native.LOA_DAMPING_RANGE
#: Every bone-set preset as ``(name, label, description)``, defined once in the core: found
#: from joint names (``right-leg-spine-head``, ``right-leg-spine-arm`` for a raised arm, …) or
#: from the hierarchy (``foot-head``, ``spine-head``, for any joint names).
BONE_SETS: list = [tuple(p) for p in _native.LOA_BONE_SETS]


__all__ = [
    "BONE_SETS",
    "DAMPING_RANGE",
    "Line",
    "Motion",
    "STIFFNESS_RANGE",
    "animate",
    "bone_chain",
    "line",
    "save_pose",
]


def save_pose(
    path: Union[str, "os.PathLike[str]"],
    names: Iterable[str],
    parents: Iterable[int],
    heads: Any,
) -> str:
    """Writes a posed skeleton as a character :func:`animate` reads (``.bvh``, by the core).

    ``names`` and ``parents`` list the joints parents first (-1 for a root); ``heads`` is
    ``(joints, 3)``: each joint's world position in the pose, which the character's rest pose
    becomes (no rest rotation). A leaf named ``<parent>_end`` is its parent bone's tip (BVH
    ``End Site``). Returns the path.
    """
    heads = np.ascontiguousarray(heads, dtype=np.float64)
    return os.fspath(
        _native.loa_save_pose(os.fspath(path), list(names), [int(p) for p in parents], heads)
    )


def bone_chain(
    character: Union[str, "os.PathLike[str]"], bones: str, pose: str = "rest"
) -> list:
    """The joint names, in chain order, that the bone set ``bones`` (a preset of
    :data:`BONE_SETS` or a comma-separated joint list, without ``@FRAME``) resolves to on the
    character file (glTF/GLB or BVH) in ``pose`` (``"rest"`` or ``"CLIP@FRAME"``): the chain
    :func:`animate` maps onto the line, first joint at the stroke's start.

    >>> toonkit.loa.bone_chain("assets/characters/RobotExpressive.glb", "foot-head")[-1]
    'Head'
    """
    return list(_native.loa_bone_chain(os.fspath(character), str(bones), str(pose)))


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


_PHYSICS = {"fps", "substeps", "simulated_frames", "blend", "settle"}


def line(
    keystrokes: Iterable[Mapping[str, Any]],
    mode: str = "physics",
    fps: float = 24.0,
    progress: Optional[Callable[[str, float], None]] = None,
    **options: Any,
) -> "Line":
    """A dynamic line of action through sketched keystrokes (LoA Eqs. 1-2).

    ``keystrokes`` is a list of ``{"frame": f, "points": (n, 2) array}`` dicts (optionally
    ``"stiffness"`` and ``"damping"`` per keystroke), frames strictly increasing. ``mode`` is
    ``"physics"`` (elastic chain re-targeted onto every keystroke) or ``"hermite"``.
    ``options`` are the fields of the loa crate's ``LineOptions`` (``elements``,
    ``smoothing``, ``orient``, ``wobbles``) and of its ``physics`` options (``substeps``,
    ``simulated_frames`` -- a count or ``"gap"`` --, ``settle`` -- a count or ``"key"``, the
    default, for one key interval --, ``blend``), as the CLI's
    ``toonkit loa line`` flags set them. Returns a :class:`Line` with ``.points``
    ``(frames, joints, 2)``, ``.angles``, ``.lengths`` and ``.save(path)``.

    >>> l = toonkit.loa.line([{"frame": 0, "points": [[0, 0], [1, 2]]},
    ...                       {"frame": 12, "points": [[0, 0], [-1, 2]]}])
    >>> l.points.shape[2]
    2
    """
    physics = {"fps": float(fps)}
    rest = {}
    for k, v in options.items():
        if k in _PHYSICS:
            if k == "simulated_frames":
                v = {"fixed": int(v)} if isinstance(v, int) else ("frame_gap" if v == "gap" else v)
            if k == "settle":
                v = {"frames": int(v)} if isinstance(v, int) else ("key_interval" if v == "key" else v)
            physics[k] = v
        else:
            rest[k] = v
    opts = {"mode": mode, "physics": physics, **rest}
    return _native.loa_line(_keystrokes_json(keystrokes, None), json.dumps(opts), progress)


def _strings(x: Union[str, Iterable[str], None]) -> list:
    if x is None:
        return []
    if isinstance(x, str):
        return [x]
    return [str(v) for v in x]


def animate(
    character: Union["_native.Scene", str, "os.PathLike[str]"],
    line: Line,
    bones: Union[str, Iterable[str], None] = None,
    contacts: Union[str, Iterable[str], None] = None,
    twists: Union[str, Iterable[str], None] = None,
    pose: str = "rest",
    progress: Optional[Callable[[str, float], None]] = None,
    canvas: Optional[Tuple[float, float]] = None,
    **options: Any,
) -> Motion:
    """3D character motion that follows a line of action (LoA Section 4 and 4.1).

    ``character`` is a skinned glTF/GLB or BVH file (path, or a :class:`toonkit.Scene` loaded
    from one). ``bones``, ``contacts`` and ``twists`` are written as the CLI's ``--bones``,
    ``--contact`` and ``--twist`` values (``"right-leg-spine-head@0"``, ``"FootL@0..3"``,
    ``"Torso_1@22:20"``); ``pose`` is ``"rest"`` or ``"CLIP@FRAME"``. ``canvas`` is the
    ``(width, height)`` in pixels of a canvas the keystrokes were drawn on through the default
    front camera (y down), as the studio's page draws them. Other ``options`` are
    fields of the loa crate's ``AnimateOptions`` (``plane_normal``, ``weights``,
    ``max_iterations``). Returns a :class:`Motion` with per-frame joint ``.rotations``
    ``(frames, joints, 4)``, ``.positions``, ``.report`` and ``.save(path)`` (``.glb``/``.bvh``).

    >>> line = toonkit.loa.line(keys)
    >>> motion = toonkit.loa.animate("assets/characters/RobotExpressive.glb", line,
    ...                              bones=["right-leg-spine-head@0"])
    >>> motion.rotations.shape[2]
    4
    """
    if not isinstance(character, _native.Scene):
        character = os.fspath(character)
    return _native.loa_animate(
        character,
        line,
        _strings(bones),
        _strings(contacts),
        _strings(twists),
        str(pose),
        json.dumps(options),
        progress,
        None if canvas is None else (float(canvas[0]), float(canvas[1])),
    )
