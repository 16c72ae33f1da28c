"""toonkit: stylization tools for 3D animation on numpy arrays.

Three tools from three papers, the same code as the ``toonkit`` command line:

* :mod:`toonkit.smear` -- smear frames (Basset et al., SIGGRAPH 2024): motion offsets,
  elongated and multiple in-betweens, motion lines.
* :mod:`toonkit.stopmo` -- replacement libraries for 3D-printed stop-motion (StopShop).
* :mod:`toonkit.loa` -- dynamic lines of action (Guay et al., SBIM 2015).

Example::

    import toonkit
    scene = toonkit.load("assets/characters/RobotExpressive.glb", clip="Dance")
    delta = toonkit.smear.offsets(scene)          # float32 (frames, vertices)

Errors are one line, as the CLI prints them: ``FileNotFoundError`` for a missing file,
``ValueError`` for a bad argument, :class:`ToonkitError` for anything else.
"""

from ._native import Scene, SkinStream, ToonkitError, __version__, load, skin
from . import loa, smear, stopmo

__all__ = ["Scene", "SkinStream", "ToonkitError", "load", "loa", "skin", "smear", "stopmo",
           "__version__"]
