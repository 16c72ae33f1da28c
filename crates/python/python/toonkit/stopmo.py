"""Replacement libraries for 3D-printed stop-motion (StopShop) on :class:`toonkit.Scene`.

Example::

    import toonkit
    face = toonkit.load("assets/face/ict-face-talk.glb", fps=2)
    parts = {"upper": [(0, 10, 13)], "lower": [(0, -14, 10)]}   # seed points (or triangle ids)
    seg = toonkit.stopmo.segment(face, parts=parts)
    lib = toonkit.stopmo.library(seg, pieces={"upper": 4, "lower": 6})
    lib.labels          # int32 (frames, parts): the piece shown at every frame
    lib.save("out/")    # the CLI's layout: pieces/, assembly.csv, report.json, ...
"""

from __future__ import annotations

import json
from typing import Any, Callable, Iterable, Mapping, Optional, Sequence, Union

from . import _native
from ._native import Library, Segmented

__all__ = ["Library", "Segmented", "library", "run", "segment"]

_SEGMENT_KEYS = {
    "auto_parts", "figure", "gamma", "smooth_iterations", "smooth_step", "snap",
    "homogenize", "weld_epsilon",
}

Seeds = Iterable[Union[int, Sequence[float]]]


def _parts(parts: Optional[Mapping[str, Seeds]]) -> list:
    out = []
    for name, seeds in (parts or {}).items():
        specs = []
        for s in seeds:
            if isinstance(s, int):
                specs.append({"Triangle": int(s)})
            else:
                p = [float(x) for x in s]
                if len(p) != 3:
                    raise ValueError(f"part {name!r}: a seed is a triangle id or a point (x, y, z)")
                specs.append({"Point": p})
        out.append({"name": str(name), "seeds": specs})
    return out


def _segment_options(parts, gamma, homogenize, options) -> dict:
    opts = {"parts": _parts(parts), "homogenize": bool(homogenize)}
    if gamma is not None:
        opts["gamma"] = float(gamma)
    opts.update(options)
    return opts


def _library_options(pieces, options) -> dict:
    options = dict(options)
    budget, max_error = options.pop("budget", None), options.pop("max_error_mm", None)
    if budget is not None and max_error is not None:
        raise ValueError("pieces: give budget or max_error_mm, not both")
    if budget is not None:
        count: Any = {"budget": int(budget)}
    elif max_error is not None:
        count = {"max_error_mm": float(max_error)}
    elif isinstance(pieces, Mapping):
        count: Any = {"per_part": {str(k): int(v) for k, v in pieces.items()}}
    else:
        count = {"each": int(pieces)}
    return {"pieces": count, **options}


def segment(
    scene: "_native.Scene",
    parts: Optional[Mapping[str, Seeds]] = None,
    gamma: Optional[float] = None,
    homogenize: bool = True,
    progress: Optional[Callable[[str, float], None]] = None,
    **options: Any,
) -> Segmented:
    """Cuts the animated mesh into parts (StopShop Eqs. 1-3) and homogenizes the seams
    (StopShop Eqs. 4-9), as ``toonkit stopmo segment``.

    ``parts`` maps part names to seeds: triangle ids or points ``(x, y, z)`` in model units.
    ``gamma`` weighs the deformation term of StopShop Eq. 3 (default 1000 after scaling to a
    unit box); other ``options``: ``auto_parts``, ``smooth_iterations``, ``snap``, ...
    Returns a :class:`Segmented` with ``.labels`` (part per input triangle), ``.parts``,
    ``.report`` and ``.save(path.glb)``.
    """
    opts = _segment_options(parts, gamma, homogenize, options)
    return _native.stopmo_segment(scene, json.dumps(opts), progress)


def library(
    segmented: Segmented,
    pieces: Union[int, Mapping[str, int]] = 20,
    progress: Optional[Callable[[str, float], None]] = None,
    **options: Any,
) -> Library:
    """Builds the replacement library of each part and labels every frame (StopShop
    Eqs. 10-16), as ``toonkit stopmo library``.

    ``pieces`` is a count for every part or a dict per part; ``budget=N`` (a total over all
    parts) or ``max_error_mm=E`` (the smallest library within that error) replace it; other
    ``options`` are the stopmo
    crate's ``LibraryJobOptions`` (``restarts``, ``seed``, ``method``, ``print_height_mm``,
    ``plugs``, ...); printing: ``magnets="3x2"`` (a disc magnet, mm: a pocket in every piece
    and the part's mount), ``clearance_mm`` (fits; default 3 x the printer resolution),
    ``print_format="stl"|"3mf"|"stl,3mf"``, ``plate_mm=(w, d)`` (``library.3mf``'s build
    plates), ``min_wall_mm`` and ``min_feature_mm`` (the printer's minimums, default 0.8 and
    0.3: thinner walls and features are warned about), as the CLI's ``--magnets``,
    ``--clearance``, ``--print-format``, ``--plate``, ``--min-wall``, ``--min-feature``.
    Returns a :class:`Library` with ``.labels`` ``(frames, parts)``,
    ``.pieces``, ``.assembly``, ``.report`` and ``.save(dir)`` (the CLI's layout).
    """
    opts = _library_options(pieces, options)
    return _native.stopmo_library(segmented, json.dumps(opts), progress)


def run(
    scene: "_native.Scene",
    parts: Optional[Mapping[str, Seeds]] = None,
    pieces: Union[int, Mapping[str, int]] = 20,
    gamma: Optional[float] = None,
    homogenize: bool = True,
    progress: Optional[Callable[[str, float], None]] = None,
    **options: Any,
) -> Library:
    """Segments, then builds the library: the whole ``toonkit stopmo run`` job. Options go
    to the segmentation or the library by name (see :func:`segment`, :func:`library`)."""
    seg = {k: v for k, v in options.items() if k in _SEGMENT_KEYS}
    lib = {k: v for k, v in options.items() if k not in _SEGMENT_KEYS}
    opts = {
        "segment": _segment_options(parts, gamma, homogenize, seg),
        "library": _library_options(pieces, lib),
    }
    return _native.stopmo_run(scene, json.dumps(opts), progress)
