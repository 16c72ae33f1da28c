"""Replacement libraries for 3D-printed stop-motion (StopShop).

The whole-job calls ``segment``, ``library`` and ``run`` arrive with the stopmo crate's
library API (issue 14).
"""

__all__: list = []
