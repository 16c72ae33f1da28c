"""Calling overhead of toonkit.smear.offsets vs the CLI (issue 15: <= 1.2x).

Times `toonkit.smear.offsets` on RobotExpressive's Dance clip (scene loaded once, as a host
application holds it) and the CLI's `toonkit --json smear offsets` on the same input, whose
JSON reports its own timings. Prints min/median of each and the ratio of the medians.

    python crates/python/bench/offsets.py [--runs 7] [--cli target/release/toonkit]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import toonkit

REPO = Path(__file__).resolve().parents[3]
ROBOT = REPO / "assets" / "characters" / "RobotExpressive.glb"


def cli_seconds(cli: Path, out: Path) -> tuple[float, float, dict]:
    """(compute seconds the CLI reports, whole-process seconds, summary) of one CLI run."""
    start = time.perf_counter()
    res = subprocess.run(
        [str(cli), "--json", "smear", "offsets", str(ROBOT), "--clip", "Dance", "-o", str(out)],
        capture_output=True, text=True, check=True,
    )
    wall = time.perf_counter() - start
    summary = json.loads(res.stdout)
    timings = summary.get("timings") or {}
    compute = timings.get("offsets", summary["seconds"])
    return compute, wall, summary


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--cli", type=Path, default=Path(
        os.environ.get("TOONKIT_CLI", REPO / "target" / "release" / "toonkit")))
    args = ap.parse_args()
    if not args.cli.exists():
        subprocess.run(["cargo", "build", "--release", "-p", "toonkit-cli"], cwd=REPO, check=True)

    scene = toonkit.load(ROBOT, clip="Dance")
    toonkit.smear.offsets(scene)  # warm-up (thread pool, page cache)
    module = []
    for _ in range(args.runs):
        t = time.perf_counter()
        toonkit.smear.offsets(scene)
        module.append(time.perf_counter() - t)
    load_and_offsets = []
    for _ in range(args.runs):
        t = time.perf_counter()
        toonkit.smear.offsets(toonkit.load(ROBOT, clip="Dance"))
        load_and_offsets.append(time.perf_counter() - t)

    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "offsets.npy"
        cli_seconds(args.cli, out)
        runs = [cli_seconds(args.cli, out) for _ in range(args.runs)]
    compute = [r[0] for r in runs]
    wall = [r[1] for r in runs]
    what = "offsets timing" if runs[0][2].get("timings") else "'seconds' (load+offsets+write)"

    def row(label: str, xs: list[float]) -> None:
        print(f"{label:<44} min {min(xs) * 1e3:8.2f} ms   median {statistics.median(xs) * 1e3:8.2f} ms")

    f, v, _ = scene.positions.shape
    print(f"RobotExpressive Dance: {f} frames x {v} vertices, {args.runs} runs each")
    row("toonkit.smear.offsets(scene)", module)
    row("toonkit.smear.offsets(toonkit.load(...))", load_and_offsets)
    row(f"CLI compute ({what})", compute)
    row("CLI whole process", wall)
    ratio = statistics.median(module) / statistics.median(compute)
    print(f"module / CLI compute (medians): {ratio:.2f}x  (target <= 1.2x)")


if __name__ == "__main__":
    main()
