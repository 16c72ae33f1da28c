"""Smear frames (Basset, Bénard, Barla, SIGGRAPH 2024) on :class:`toonkit.Scene`.

Example::

    import toonkit
    scene = toonkit.load("assets/characters/RobotExpressive.glb", clip="Dance")
    delta = toonkit.smear.offsets(scene, smooth=2)   # float32 (frames, vertices), in [-1, 1]

    prepared = toonkit.smear.prepare(scene)          # offsets solved once ...
    look = toonkit.smear.stylize(prepared, {"elongate": {"function": {"stages": [{"op": "scale", "by": 2}]}}})
    look = toonkit.smear.stylize(prepared, "examples/smear/fig11c_speed.toml")  # ... reused
    look.elongated                                   # float32 (frames, vertices, 3)
    look.save("smear.glb")
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Iterable, Mapping, Optional, Tuple, Union

import numpy as np

from . import _native
from ._native import Prepared, Preparing, Stream, Stylized

__all__ = [
    "Prepared",
    "Preparing",
    "Stream",
    "Stylized",
    "offsets",
    "parameters",
    "preset_function",
    "presets",
    "prepare",
    "save_style",
    "start_prepare",
    "stream",
    "style_toml",
    "stylize",
]


def presets() -> list:
    """The elongation presets S_E (SMEAR Section 5.2, Fig. 11), defined once in the smear
    crate: a list of ``{"name", "doc", "parameters", "default", "function"}`` (``function``:
    the preset's stage chain with the default parameters, as a style's ``elongate.function``;
    ``default``: the preset front ends start from).

    >>> [p["name"] for p in toonkit.smear.presets()]
    ['linear', 'speed', 'noise']
    """
    return json.loads(_native.smear_presets())


def parameters() -> dict:
    """The style parameters every front end shows: name → ``{"name", "default", "min",
    "max", "integer", "doc"}`` (the CLI's flag defaults, the Blender panel's and the studio's).

    >>> toonkit.smear.parameters()["kappa"]["default"]
    18.0
    """
    return {p["name"]: p for p in json.loads(_native.smear_parameters())}


def preset_function(name: str, beta_max: Optional[float] = None, kappa: Optional[float] = None,
                    signed: bool = True) -> dict:
    """A preset's stage chain with these parameters (defaults: :func:`parameters`), as a
    style's ``elongate.function`` dict. ``signed=False`` leaves out the preset's own δ±
    restriction (for a front end that offers it as a separate choice)."""
    table = parameters()
    b = table["beta_max"]["default"] if beta_max is None else beta_max
    k = table["kappa"]["default"] if kappa is None else kappa
    return json.loads(_native.smear_preset_function(name, float(b), float(k), signed))


def style_toml(style: Mapping[str, Any]) -> str:
    """A style dict, checked, as the TOML text the CLI's ``--style`` reads."""
    return _native.smear_style_toml(json.dumps(style))


def save_style(path: Union[str, "os.PathLike[str]"], style: Mapping[str, Any]) -> str:
    """Writes a style dict, checked, as a TOML style file (atomically). Returns the path."""
    return os.fspath(_native.smear_save_style(os.fspath(path), json.dumps(style)))


def _prune_list(prune: Iterable[str]) -> list:
    if isinstance(prune, str):
        return [p for p in prune.split(",") if p]
    return list(prune)


def offsets(
    scene: "_native.Scene",
    smooth: int = 2,
    whole_body: bool = False,
    prune: Iterable[str] = (),
    camera: Optional[Union[str, int]] = None,
    progress: Optional[Callable[[str, float], None]] = None,
    causal: bool = False,
    revolve: Iterable[str] = (),
) -> np.ndarray:
    """Motion offsets per frame and vertex (SMEAR Eqs. 1-9).

    Returns float32 ``(frames, vertices)`` in ``scene.positions``' vertex order: leading
    parts > 0, trailing parts < 0 -- the array ``toonkit smear offsets IN -o OUT.npy`` writes.

    ``smooth`` is the half-window N of SMEAR Eq. 2 (0 = off); ``whole_body`` treats each
    skinned character as one object (Fig. 14); ``prune`` names joints whose vertices follow
    their nearest kept ancestor; ``camera`` (name or index) measures motion relative to a
    camera. ``causal`` uses past frames only (backward differences, past-half smoothing);
    ``revolve`` names objects (or ``"auto"``) whose offsets follow arcs about their rotation
    axis. The GIL is released while computing. ``progress(stage, fraction)`` is called
    before and after.

    >>> scene = toonkit.load("assets/characters/RobotExpressive.glb", clip="Dance")
    >>> toonkit.smear.offsets(scene, prune=["Head"]).shape == scene.positions.shape[:2]
    True
    """
    return _native.smear_offsets(
        scene,
        int(smooth),
        bool(whole_body),
        _prune_list(prune),
        camera,
        progress,
        bool(causal),
        _prune_list(revolve),
    )


def prepare(
    scene: "_native.Scene",
    smooth: int = 2,
    whole_body: bool = False,
    prune: Iterable[str] = (),
    camera: Optional[Union[str, int]] = None,
    weights: Optional[Mapping[str, Any]] = None,
    merge: Optional[str] = None,
    progress: Optional[Callable[[str, float], None]] = None,
    causal: bool = False,
    revolve: Iterable[str] = (),
    colliders: Iterable[Union[str, "_native.Scene"]] = (),
) -> Prepared:
    """Everything a style does not change, computed once: offsets, camera, weights, velocities.

    Takes the options of :func:`offsets`, plus ``weights`` (painted weights, the ``weights``
    table of a style file, e.g. ``{"group": ["Head"]}``) and ``merge`` (merge all objects
    into one of this name, as ``toonkit smear elongate`` does). Pass the result to
    :func:`stylize` as often as you like: the offsets are never solved again.

    ``colliders`` are meshes the elongated and multiple in-betweens never enter (the CLI's
    ``--collider-object NAME`` / ``--collider FILE``): a name takes that object out of
    ``scene`` (not smeared, not in the results); a :class:`toonkit.Scene` (e.g.
    ``toonkit.load("ramp.obj")``) adds each of its meshes, static or animated.

    >>> prepared = toonkit.smear.prepare(scene, smooth=2)
    >>> prepared.offsets.shape == scene.positions.shape[:2]
    True
    """
    options, scenes = _prepare_options(weights, merge, colliders)
    return _native.smear_prepare(
        scene,
        int(smooth),
        bool(whole_body),
        _prune_list(prune),
        camera,
        options,
        progress,
        bool(causal),
        _prune_list(revolve),
        scenes,
    )


def start_prepare(
    scene: "_native.Scene",
    smooth: int = 2,
    whole_body: bool = False,
    prune: Iterable[str] = (),
    camera: Optional[Union[str, int]] = None,
    weights: Optional[Mapping[str, Any]] = None,
    merge: Optional[str] = None,
    causal: bool = False,
    revolve: Iterable[str] = (),
    colliders: Iterable[Union[str, "_native.Scene"]] = (),
) -> Preparing:
    """:func:`prepare` (the same options but ``progress``) on a thread of its own: returns at
    once, and ``result()`` waits for the :class:`Prepared` :func:`prepare` gives, or raises
    its error. A host does other work meanwhile (Blender builds its result objects).

    >>> preparing = toonkit.smear.start_prepare(scene, smooth=2)
    >>> prepared = preparing.result()
    """
    options, scenes = _prepare_options(weights, merge, colliders)
    return _native.smear_start_prepare(
        scene,
        int(smooth),
        bool(whole_body),
        _prune_list(prune),
        camera,
        options,
        bool(causal),
        _prune_list(revolve),
        scenes,
    )


def _prepare_options(weights, merge, colliders):
    """`prepare`'s `weights`, `merge` and collider names as the native options JSON (None
    when unset), and its collider scenes."""
    extra = {}
    if weights is not None:
        extra["weights"] = dict(weights)
    if merge is not None:
        extra["merge"] = str(merge)
    colliders = [colliders] if isinstance(colliders, (str, _native.Scene)) else list(colliders)
    names = [c for c in colliders if isinstance(c, str)]
    scenes = [c for c in colliders if not isinstance(c, str)]
    if names:
        extra["colliders"] = names
    return (json.dumps(extra) if extra else None), scenes


def stream(
    triangles: Any,
    vertices: int,
    smooth: int = 2,
    elongate: Optional[Mapping[str, Any]] = None,
    history: int = 6,
    ground: Optional[float] = None,
    fps: float = 24.0,
    speed_units: str = "size",
    size_reference: Optional[float] = None,
) -> Stream:
    """A streaming smear (past-only): ``s.push(positions)`` returns that frame's elongated
    in-between at once, from the frames pushed so far -- for games and live previews.

    ``triangles`` is ``(T, 3)`` ints, ``vertices`` the points per frame; ``smooth`` the
    past half-window of SMEAR Eq. 2; ``elongate`` a stylization function as in a style's
    ``[elongate] function`` table (default ``{"stages": [{"op": "scale", "by": 1}]}``);
    ``history`` the past frames kept; ``ground`` a plane y = ground never crossed.

    Units as in a style (docs/smear-units.md): with ``speed_units="size"`` (default) the
    function's speeds are in character sizes per second at ``fps`` and its lengths (``x, y,
    z``, noise, ``ground``) in sizes, one size being ``size_reference`` (scene units) or the
    bounding-box diagonal of the first pushed frame; ``"scene"`` keeps scene units per frame.

    >>> s = toonkit.smear.stream(scene.triangles, scene.positions.shape[1])
    >>> out = s.push(scene.positions[0])
    """
    options: dict = {
        "smooth": int(smooth),
        "history": int(history),
        "fps": float(fps),
        "speed_units": str(speed_units),
    }
    if elongate is not None:
        options["elongate"] = dict(elongate)
    if ground is not None:
        options["ground"] = float(ground)
    if size_reference is not None:
        options["size_reference"] = float(size_reference)
    return _native.Stream(np.asarray(triangles), int(vertices), json.dumps(options))


def stylize(
    prepared: Prepared,
    style: Union[Mapping[str, Any], str, "os.PathLike[str]"],
    progress: Optional[Callable[[str, float], None]] = None,
    frames: Optional[Tuple[int, int]] = None,
) -> Stylized:
    """Applies a style to prepared offsets (SMEAR Section 4 effects, Section 5 functions).

    ``style`` is a dict with the keys of the TOML style files (``elongate``, ``multiples``,
    ``lines``, ``weights``, ``objects``; see ``examples/smear/``) or the path of such a file.
    A style without ``offsets`` uses the prepared ones; different ``offsets`` are an error
    (prepare again to change them). Speeds and lengths are in the character's own size
    (bounding-box diagonals, speeds per second) unless the style says
    ``speed_units = "scene"`` (docs/smear-units.md). Returns a :class:`Stylized` with ``.elongated``
    ``(frames, vertices, 3)``, ``.multiples`` and ``.lines`` (per-frame meshes with
    per-vertex ``alpha``), ``.report`` and ``.save(path)`` (``.glb``, ``.usda``, ``.usdc``,
    ``.usdz`` or ``.abc``, as the CLI writes them). The GIL is released while computing.

    ``frames=(start, end)`` stylizes clip frames ``start..end`` only (an interactive restyle
    draws the frame on screen first): the result holds ``end - start`` frames, each equal to
    that frame of the whole clip's, and ``.first_frame`` is ``start``.

    >>> look = toonkit.smear.stylize(prepared, {"multiples": {"past": 2, "future": 0}})
    >>> len(look.multiples)
    2
    """
    if frames is not None:
        frames = (int(frames[0]), int(frames[1]))
    if isinstance(style, Mapping):
        return _native.smear_stylize(prepared, json.dumps(style), None, progress, frames)
    if isinstance(style, (str, os.PathLike)):
        return _native.smear_stylize(prepared, None, os.fspath(style), progress, frames)
    raise TypeError(f"style must be a dict or a path, got {type(style).__name__}")
