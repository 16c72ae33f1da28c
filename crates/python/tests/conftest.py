"""Shared fixtures: repository assets and the `toonkit` CLI built from the same tree.

The CLI is `$TOONKIT_CLI` if set, else `target/debug/toonkit` (built with
`cargo build -p toonkit-cli` when missing), so module and CLI results are compared on the
same inputs.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import urllib.request
from pathlib import Path

import numpy as np
import pytest

import toonkit

REPO = Path(__file__).resolve().parents[3]
ROBOT = "characters/RobotExpressive.glb"


def asset(rel: str) -> Path:
    """A repository asset (`assets/<rel>`); fails loudly when missing."""
    p = REPO / "assets" / rel
    assert p.exists(), f"missing asset {p}"
    return p


def example(rel: str) -> Path:
    """A file under the repository's `examples/`."""
    p = REPO / "examples" / rel
    assert p.exists(), f"missing example {p}"
    return p


def _cli_path() -> Path:
    env = os.environ.get("TOONKIT_CLI")
    if env:
        return Path(env)
    p = REPO / "target" / "debug" / "toonkit"
    if not p.exists():
        subprocess.run(
            ["cargo", "build", "--quiet", "-p", "toonkit-cli"], cwd=REPO, check=True
        )
    return p


CLI = _cli_path()


def run_cli(*args: object, check: bool = True) -> subprocess.CompletedProcess:
    """Runs `toonkit ARGS` and returns the completed process (text output)."""
    out = subprocess.run(
        [str(CLI), *map(str, args)], capture_output=True, text=True, cwd=REPO
    )
    if check and out.returncode != 0:
        raise AssertionError(f"toonkit {args} failed: {out.stderr}")
    return out


def cli_error(*args: object) -> str:
    """The CLI's one-line error for ARGS, without its `toonkit: error: ` prefix."""
    out = run_cli(*args, check=False)
    assert out.returncode != 0, f"toonkit {args} unexpectedly succeeded"
    line = out.stderr.strip()
    assert "\n" not in line
    return line.removeprefix("toonkit: error: ")


def cli_json(*args: object) -> dict:
    """Runs `toonkit --json ARGS` and parses its summary."""
    return json.loads(run_cli("--json", *args).stdout)


def read_pc2(path: Path) -> np.ndarray:
    """Positions of a PC2 point cache, float32 (frames, points, 3)."""
    data = path.read_bytes()
    assert data[:12] == b"POINTCACHE2\0"
    points = int(np.frombuffer(data, "<i4", 1, 16)[0])
    frames = int(np.frombuffer(data, "<i4", 1, 28)[0])
    return np.frombuffer(data, "<f4", frames * points * 3, 32).reshape(frames, points, 3)


@pytest.fixture(scope="session")
def robot() -> toonkit.Scene:
    """RobotExpressive's Dance clip at 24 fps."""
    return toonkit.load(asset(ROBOT), clip="Dance")


# The files a test studio serves, by index: the two bundled characters the agreement tests use.
STUDIO_FILES = ["characters/CesiumMan.glb", ROBOT]


@pytest.fixture(scope="session")
def studio(tmp_path_factory):
    """`toonkit studio` on `STUDIO_FILES`, on a free port: (url, output folder)."""
    out = tmp_path_factory.mktemp("studio-out")
    files = [asset(rel) for rel in STUDIO_FILES]
    server = subprocess.Popen([str(CLI), "studio", *map(str, files), "--port", "0", "--no-open",
                               "--out", str(out)], stdout=subprocess.PIPE, text=True, cwd=REPO)
    try:
        line = server.stdout.readline()
        match = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
        assert match, f"the studio did not start: {line!r}"
        yield f"http://127.0.0.1:{match.group(1)}", out
    finally:
        server.terminate()
        server.wait(timeout=30)


def studio_post(url: str, route: str, body: dict) -> bytes:
    """POSTs `body` as JSON to the studio's `route`, as the page does; the answer's bytes."""
    request = urllib.request.Request(url + route, data=json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=300) as answer:
        return answer.read()


def studio_unpack(data: bytes):
    """The studio's binary answer (crates/studio/src/pack.rs): JSON header, then buffers."""
    size = int.from_bytes(data[:4], "little")
    header = json.loads(data[4:4 + size])
    start = 4 + size
    return header, {b["name"]: np.frombuffer(data, "<f4" if b["type"] == "f32" else "<u4",
                                             b["count"], start + b["offset"])
                    for b in header["buffers"]}
