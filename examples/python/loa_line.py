"""A dynamic line of action from two sketched keystrokes, with the toonkit Python module.

    pip install ./crates/python
    python examples/python/loa_line.py [line.json]

Writes the CLI's JSON layout (`toonkit loa line ... -o line.json`) and an onion-skin SVG.
"""

import sys
from pathlib import Path

import numpy as np

import toonkit

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("line.json")
t = np.linspace(0.0, 1.0, 20)
crouch = np.stack([200 + 60 * t, 500 - 120 * t + 40 * np.sin(np.pi * t)], axis=1)
stretch = np.stack([230 + 10 * t, 520 - 260 * t], axis=1)
line = toonkit.loa.line(
    [
        {"frame": 0, "points": crouch, "damping": 0.5},
        {"frame": 12, "points": stretch, "stiffness": 90.0},
        {"frame": 30, "points": crouch},
    ],
    mode="physics",
    fps=24.0,
)
print(line, line.points.shape)
tip = line.points[:, -1]
print("tip travels", float(np.linalg.norm(np.diff(tip, axis=0), axis=1).sum()), "px")
line.save(out)
line.save(out.with_suffix(".svg"))
print(f"wrote {out} and {out.with_suffix('.svg')}")
