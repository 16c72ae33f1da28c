"""A replacement library for the talking face with the toonkit Python module (StopShop).

    pip install ./crates/python
    python examples/python/stopmo_library.py [assets/face/ict-face-talk.glb] [out/stopmo_py]

Cuts the face into an upper and a lower part, builds 4 + 6 printable pieces, prints which
piece each part shows over the first frames, and writes the CLI's folder layout.
"""

import sys
from pathlib import Path

import toonkit

REPO = Path(__file__).resolve().parents[2]
path = Path(sys.argv[1]) if len(sys.argv) > 1 else REPO / "assets/face/ict-face-talk.glb"
out = Path(sys.argv[2]) if len(sys.argv) > 2 else Path("out/stopmo_py")

face = toonkit.load(path, fps=2)
parts = {"upper": [(0, 10, 13)], "lower": [(0, -14, 10)]}  # seed points in model units
seg = toonkit.stopmo.segment(face, parts=parts)
lib = toonkit.stopmo.library(seg, pieces={"upper": 4, "lower": 6})
print(f"{face.positions.shape[0]} frames -> labels {lib.labels.shape}")
for frame in range(min(8, lib.labels.shape[0])):
    print(f"  frame {frame}: pieces {list(lib.labels[frame])}")
lib.save(out)
print(f"wrote {out}/ (pieces/, assembly.csv, report.json, ...)")
