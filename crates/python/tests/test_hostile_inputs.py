"""A hostile but realistic user's inputs through the Python module: a clip keyed at
20,000 s, sizes over their budgets, an expression NaN at some vertices, a save over the
input. Each raises an exception with the CLI's one line (the file or option, the limit or
the fix), never a crash, and the input keeps every byte."""

import json
import shutil
import struct

import numpy as np
import pytest

import toonkit
from conftest import ROBOT, asset, cli_error


def one_line(excinfo):
    msg = str(excinfo.value)
    assert msg and "\n" not in msg
    return msg.strip()


def rekeyed_glb(src, times, dst):
    """A copy of the .glb `src` whose every animation sampler has the keys `times`
    (seconds): each keeps its first len(times) output values, so skins and morph weights
    stay valid (the CLI tests' generator, crates/cli/tests/common.rs)."""
    data = src.read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    gltf = json.loads(data[20 : 20 + length])
    binary = bytearray(data[28 + length :])
    gltf["buffers"][0].pop("uri", None)

    def offset(a):
        acc = gltf["accessors"][a]
        view = gltf["bufferViews"][acc["bufferView"]]
        return view.get("byteOffset", 0) + acc.get("byteOffset", 0)

    samplers = [(s["input"], s["output"]) for a in gltf["animations"] for s in a["samplers"]]
    for inp, out in samplers:
        per_key = gltf["accessors"][out]["count"] // gltf["accessors"][inp]["count"]
        struct.pack_into(f"<{len(times)}f", binary, offset(inp), *times)
        gltf["accessors"][inp].update(count=len(times), min=[min(times)], max=[max(times)])
        gltf["accessors"][out]["count"] = per_key * len(times)
        gltf["accessors"][out].pop("min", None)
        gltf["accessors"][out].pop("max", None)
    for a in gltf["animations"]:
        for s in a["samplers"]:
            s["interpolation"] = "LINEAR"
    text = json.dumps(gltf).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    total = 28 + len(text) + len(binary)
    dst.write_bytes(
        struct.pack("<4sII", b"glTF", 2, total)
        + struct.pack("<I4s", len(text), b"JSON")
        + text
        + struct.pack("<I4s", len(binary), b"BIN\0")
        + bytes(binary)
    )
    return dst


def test_a_clip_keyed_at_20000_seconds(tmp_path):
    one = rekeyed_glb(asset(ROBOT), [20000.0], tmp_path / "one.glb")
    scene = toonkit.load(one, clip="Wave")
    assert scene.positions.shape[0] == 1
    assert np.isfinite(scene.positions).all()
    assert np.isfinite(toonkit.smear.offsets(scene)).all()

    two = rekeyed_glb(asset(ROBOT), [0.0, 20000.0], tmp_path / "two.glb")
    before = two.read_bytes()
    with pytest.raises(ValueError) as e:
        toonkit.load(two, clip="Wave")
    msg = one_line(e)
    assert "frames at 24 fps = 480001 is over the limit of 100000" in msg
    assert msg == cli_error("smear", "offsets", two, "--clip", "Wave", "-o", tmp_path / "o.npy")
    assert two.read_bytes() == before


@pytest.fixture(scope="module")
def wave():
    return toonkit.load(asset(ROBOT), clip="Wave")


def test_sizes_over_their_budgets(wave, tmp_path):
    with pytest.raises(toonkit.ToonkitError) as e:
        toonkit.smear.offsets(wave, smooth=10**9)
    assert "--smooth = 1e9 is over the limit of 100000" in one_line(e)
    prepared = toonkit.smear.prepare(wave)
    with pytest.raises(toonkit.ToonkitError) as e:
        toonkit.smear.stylize(prepared, {"lines": {"count": 10_000_000}})
    assert "is over the limit of" in one_line(e)
    keys = [{"frame": k, "points": [[10.0, 10.0], [20.0, 40.0 + k % 7]]} for k in range(10_000)]
    with pytest.raises(ValueError) as e:
        toonkit.loa.line(keys)
    assert "keystrokes = 10000 is over the limit of 1000" in one_line(e)
    # Two keystrokes 500,000 frames apart: every frame between them would be a pose.
    stroke = [[10.0, 10.0], [20.0, 40.0], [30.0, 80.0]]
    far = [{"frame": 0, "points": stroke}, {"frame": 500_000, "points": stroke}]
    with pytest.raises(ValueError) as e:
        toonkit.loa.line(far)
    assert "line frames (first keystroke to last, then the settle frames) = 1000001 is over the limit of 100000" in one_line(e)


def test_an_expression_nan_at_some_vertices_names_the_frame_and_the_vertex(wave, tmp_path):
    prepared = toonkit.smear.prepare(wave)
    style = {"elongate": {"function": {"expr": "sqrt(x)"}}}
    with pytest.raises(toonkit.ToonkitError) as e:
        toonkit.smear.stylize(prepared, style)
    msg = one_line(e)
    assert "expression 'sqrt(x)' is NaN or infinite at frame 0, vertex " in msg
    path = tmp_path / "nan.toml"
    path.write_text('[elongate]\nfunction = { expr = "sqrt(x)" }\n')
    cli = cli_error("smear", asset(ROBOT), "--clip", "Wave", "--style", path, "-o", tmp_path / "o.glb")
    assert msg.split(": ", 1)[1] == cli.split(": ", 1)[1], (msg, cli)
    # The stream reports the frame it was pushed (a ValueError, as its other bad inputs).
    s = toonkit.smear.stream(
        wave.triangles, wave.positions.shape[1], elongate={"expr": "sqrt(x)"}
    )
    with pytest.raises(ValueError) as e:
        s.push(wave.positions[0])
    assert "is NaN or infinite at frame 0, vertex " in one_line(e)
    # Finite everywhere: works.
    ok = toonkit.smear.stylize(prepared, {"elongate": {"function": {"expr": "sqrt(abs(x)) * delta"}}})
    assert np.isfinite(ok.elongated).all()


def test_saving_over_the_input_is_refused(tmp_path):
    robot = tmp_path / "robot.glb"
    shutil.copy(asset(ROBOT), robot)
    before = robot.read_bytes()
    scene = toonkit.load(robot, clip="Wave")
    look = toonkit.smear.stylize(toonkit.smear.prepare(scene), {"elongate": {}})
    with pytest.raises(toonkit.ToonkitError) as e:
        look.save(robot)
    assert "is the input" in one_line(e)
    assert robot.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["robot.glb"]


@pytest.mark.parametrize("uri", ["/etc/hostname", "../x.bin", "file:///dev/zero", "/dev/zero"])
def test_a_gltf_buffer_outside_its_folder_is_refused(tmp_path, uri):
    path = tmp_path / "escape.gltf"
    path.write_text(json.dumps({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": uri, "byteLength": 36}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0,
    }))
    with pytest.raises(toonkit.ToonkitError) as e:
        toonkit.load(path)
    msg = one_line(e)
    assert uri in msg and "escape.gltf" in msg
    assert msg == cli_error("info", path)
