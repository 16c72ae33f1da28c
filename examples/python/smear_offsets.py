"""Motion offsets of the robot's Dance clip with the toonkit Python module.

    pip install ./crates/python
    python examples/python/smear_offsets.py [assets/characters/RobotExpressive.glb] [out.npy]

Prints which vertices lead and trail on the fastest frame and saves the offsets as the CLI's
`toonkit smear offsets IN -o out.npy` would.
"""

import sys
from pathlib import Path

import numpy as np

import toonkit

REPO = Path(__file__).resolve().parents[2]
path = Path(sys.argv[1]) if len(sys.argv) > 1 else REPO / "assets/characters/RobotExpressive.glb"
out = Path(sys.argv[2]) if len(sys.argv) > 2 else Path("offsets.npy")

scene = toonkit.load(path, clip="Dance")
print(scene)
delta = toonkit.smear.offsets(
    scene, smooth=2, progress=lambda stage, f: print(f"  {stage}: {f:.0%}")
)
speed = np.linalg.norm(np.gradient(scene.positions, axis=0), axis=2)  # units per frame
f = int(speed.mean(axis=1).argmax())
print(f"fastest frame {f}: {np.sum(delta[f] > 0.5)} vertices lead, {np.sum(delta[f] < -0.5)} trail")
for name, vertices in scene.objects:
    print(f"  {name:<20} offsets in [{delta[:, vertices].min():+.2f}, {delta[:, vertices].max():+.2f}]")
np.save(out, delta)
print(f"wrote {out} {delta.shape} {delta.dtype}")
