"""toonkit: stylization tools for 3D animation on numpy arrays (type stubs)."""

from . import loa as loa, smear as smear, stopmo as stopmo
from ._native import Scene as Scene, SkinStream as SkinStream, ToonkitError as ToonkitError, __version__ as __version__
from ._native import load as load, skin as skin

__all__ = ["Scene", "SkinStream", "ToonkitError", "load", "loa", "skin", "smear", "stopmo",
           "__version__"]
