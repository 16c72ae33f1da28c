"""toonkit.smear against `toonkit smear ...` on the same inputs."""

import threading
import time

import numpy as np
import pytest

import toonkit
from conftest import ROBOT, asset, example, read_pc2, run_cli

STRETCH = {"elongate": {"function": {"stages": [{"op": "scale", "by": 2}]}}}


def cli_offsets(tmp_path, *flags):
    out = tmp_path / "offsets.npy"
    run_cli("smear", "offsets", asset(ROBOT), "--clip", "Dance", *flags, "-o", out)
    return np.load(out)


def test_offsets_equal_cli_npy(robot, tmp_path):
    delta = toonkit.smear.offsets(robot)
    expected = cli_offsets(tmp_path)
    assert delta.dtype == np.float32
    assert delta.shape == expected.shape == robot.positions.shape[:2]
    assert np.abs(delta - expected).max() <= 1e-6
    assert np.isfinite(delta).all() and np.abs(delta).max() <= 1.0 + 1e-6


@pytest.mark.parametrize(
    "kwargs, flags",
    [
        ({"smooth": 0}, ["--smooth", "0"]),
        ({"whole_body": True}, ["--whole-body"]),
        ({"prune": ["Head", "ShoulderL"]}, ["--prune", "Head,ShoulderL"]),
    ],
)
def test_offset_options_equal_cli_flags(robot, tmp_path, kwargs, flags):
    delta = toonkit.smear.offsets(robot, **kwargs)
    assert np.abs(delta - cli_offsets(tmp_path, *flags)).max() <= 1e-6
    if "prune" not in kwargs:  # the robot's pruned joints carry rigid props: same offsets
        assert np.abs(delta - toonkit.smear.offsets(robot)).max() > 1e-3  # the option acts


def test_from_arrays_with_skin_gives_the_same_offsets(robot):
    scene = toonkit.Scene.from_arrays(
        robot.positions, robot.triangles, fps=robot.fps, skin=robot.skin, objects=robot.objects
    )
    assert scene.objects == robot.objects
    assert scene.joint_names == robot.joint_names
    loaded = toonkit.smear.offsets(robot)
    np.testing.assert_allclose(toonkit.smear.offsets(scene), loaded, atol=1e-6, rtol=0)
    np.testing.assert_allclose(
        toonkit.smear.offsets(scene, whole_body=True), toonkit.smear.offsets(robot, whole_body=True),
        atol=1e-6, rtol=0)
    # One object covering every vertex (a host's single mesh) is the whole scene, named.
    n = robot.positions.shape[1]
    skin = {k: v for k, v in robot.skin.items() if k != "object_parents"}
    one = toonkit.Scene.from_arrays(robot.positions, robot.triangles, fps=robot.fps,
                                    skin=skin, objects=[("all", range(0, n))])
    whole = toonkit.Scene.from_arrays(robot.positions, robot.triangles, fps=robot.fps,
                                      skin=skin)
    assert one.objects == [("all", range(0, n))]
    np.testing.assert_array_equal(toonkit.smear.offsets(one), toonkit.smear.offsets(whole))
    # Without the skin the robot is one simple object (SMEAR Eq. 1): different offsets.
    simple = toonkit.Scene.from_arrays(robot.positions, robot.triangles, fps=robot.fps)
    assert np.abs(toonkit.smear.offsets(simple) - loaded).max() > 0.1


def test_progress_is_called(robot):
    calls = []
    toonkit.smear.offsets(robot, progress=lambda stage, f: calls.append((stage, f)))
    assert calls == [("offsets", 0.0), ("offsets", 1.0)]


def test_progress_exception_aborts(robot):
    def stop(stage, fraction):
        raise KeyboardInterrupt("stop")

    with pytest.raises(KeyboardInterrupt):
        toonkit.smear.offsets(robot, progress=stop)


def count_while(job):
    """Runs `job` in a thread; counts how often the main thread ran meanwhile."""
    done = threading.Event()
    result = {}

    def work():
        result["value"] = job()
        done.set()

    t = threading.Thread(target=work)
    ticks = 0
    start = time.perf_counter()
    t.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    t.join()
    return ticks, time.perf_counter() - start, result["value"]


@pytest.fixture(scope="module")
def prepared(robot):
    return toonkit.smear.prepare(robot)


def test_prepared_offsets_equal_offsets(robot, prepared):
    np.testing.assert_array_equal(prepared.offsets, toonkit.smear.offsets(robot))
    assert [o["name"] for o in prepared.report["objects"]] == [n for n, _ in robot.objects]


def test_started_prepare_gives_what_prepare_gives_and_its_errors(robot, prepared):
    preparing = toonkit.smear.start_prepare(robot)
    ticks = 0
    started = toonkit.smear.start_prepare(robot, whole_body=True, merge="all")
    while ticks < 3:  # the caller goes on meanwhile
        ticks += 1
        time.sleep(0.001)
    ready = preparing.result()
    np.testing.assert_array_equal(ready.offsets, prepared.offsets)
    look = toonkit.smear.stylize(ready, STRETCH)
    np.testing.assert_array_equal(look.elongated, toonkit.smear.stylize(prepared, STRETCH).elongated)
    whole = toonkit.smear.prepare(robot, whole_body=True, merge="all")
    np.testing.assert_array_equal(started.result().offsets, whole.offsets)
    with pytest.raises(ValueError, match="already taken"):
        preparing.result()
    # The solve's errors are raised by result(), with prepare's message.
    with pytest.raises(ValueError) as expected:
        toonkit.smear.prepare(robot, prune=["Tail"])
    failing = toonkit.smear.start_prepare(robot, prune=["Tail"])
    with pytest.raises(ValueError) as e:
        failing.result()
    assert str(e.value) == str(expected.value)


def test_style_file_saves_what_the_cli_writes(robot, prepared, tmp_path):
    style = example("smear/fig11b_linear.toml")
    cli = tmp_path / "cli.glb"
    run_cli("smear", asset(ROBOT), "--clip", "Dance", "--style", style, "-o", cli)
    ours = toonkit.smear.stylize(prepared, style).save(tmp_path / "py.glb")
    assert ours.read_bytes() == cli.read_bytes()


def test_elongated_equals_cli_elongate(robot, prepared, tmp_path):
    out = tmp_path / "elongated.pc2"
    run_cli("smear", "elongate", asset(ROBOT), "--clip", "Dance", "--preset", "linear",
            "--beta-max", "2", "-o", out)
    expected = read_pc2(out)
    elongated = toonkit.smear.stylize(prepared, STRETCH).elongated
    assert elongated.dtype == np.float32 and elongated.shape == expected.shape
    assert np.abs(elongated - expected).max() <= 1e-5
    assert np.abs(elongated - robot.positions).max() > 1e-3  # it did elongate


def test_restyling_reuses_the_offsets(prepared):
    first = toonkit.smear.stylize(prepared, STRETCH)
    second = toonkit.smear.stylize(prepared, {"multiples": {"past": 2, "future": 0}})
    assert second.report["offset_solves"] == first.report["offset_solves"]
    copies = second.multiples
    assert len(copies) == 2 * len(prepared.report["objects"])  # two past copies per object
    for c in copies:
        f, v, _ = c["positions"].shape
        assert c["alpha"].shape == (f, v) and c["triangles"].shape[1] == 3
        assert 0.0 <= c["alpha"].min() and c["alpha"].max() <= 1.0
        # "object" indexes scene.objects: the copy has that object's vertices.
        name, r = prepared_objects(prepared)[c["object"]]
        assert v == len(r) and c["name"].startswith(name)


def test_stylize_frames_equal_those_frames_of_the_clip(prepared):
    style = {**STRETCH, "multiples": {"past": 1, "future": 1}}
    whole = toonkit.smear.stylize(prepared, style)
    frames = whole.elongated.shape[0]
    assert whole.first_frame == 0
    for start, end in ((0, 1), (7, 8), (3, 12), (frames - 1, frames)):
        part = toonkit.smear.stylize(prepared, style, frames=(start, end))
        assert part.first_frame == start
        np.testing.assert_array_equal(part.elongated, whole.elongated[start:end])
        assert len(part.multiples) == len(whole.multiples)
        for a, b in zip(part.multiples, whole.multiples):
            np.testing.assert_array_equal(a["positions"], b["positions"][start:end])
            np.testing.assert_array_equal(a["alpha"], b["alpha"][start:end])
    for bad in ((5, 5), (6, 2), (0, frames + 1)):
        with pytest.raises(ValueError, match="frames"):
            toonkit.smear.stylize(prepared, style, frames=bad)


def prepared_objects(prepared):
    """`(name, range)` per object of a prepared scene, from its report."""
    out, start = [], 0
    for o in prepared.report["objects"]:
        out.append((o["name"], range(start, start + o["vertices"])))
        start += o["vertices"]
    return out


def test_multiples_only_style_keeps_the_body(robot, prepared):
    look = toonkit.smear.stylize(prepared, {"multiples": {"past": 1, "future": 1}})
    np.testing.assert_array_equal(look.elongated, robot.positions)


def test_motion_lines(robot, prepared):
    look = toonkit.smear.stylize(prepared, {"lines": {"count": 30}})
    assert look.lines, "the robot dances: some lines show"
    shown = []
    for obj in look.lines:
        assert len(obj["frames"]) == robot.frame_count
        assert obj["name"] == robot.objects[obj["object"]][0] + "_lines"
        shown += [m for m in obj["frames"] if len(m["triangles"])]
    assert shown
    for m in shown:
        assert m["positions"].shape[1] == 3 and m["alpha"].shape == (len(m["positions"]),)
        assert m["triangles"].max() < len(m["positions"])


def test_style_errors(prepared, tmp_path):
    with pytest.raises(ValueError, match="style"):
        toonkit.smear.stylize(prepared, {"elongate": {"bogus": 1}})
    with pytest.raises(FileNotFoundError):
        toonkit.smear.stylize(prepared, tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[elongate\n")
    with pytest.raises(ValueError, match="bad.toml"):
        toonkit.smear.stylize(prepared, bad)
    with pytest.raises(ValueError, match=r"\.glb, \.usda, \.usdc, \.usdz or \.abc"):
        toonkit.smear.stylize(prepared, STRETCH).save(tmp_path / "x.obj")
    with pytest.raises(TypeError):
        toonkit.smear.stylize(prepared, 3)


def test_stylize_releases_the_gil(prepared):
    ticks, seconds, look = count_while(
        lambda: toonkit.smear.stylize(prepared, {"lines": {"count": 200}, **STRETCH})
    )
    assert look.elongated.ndim == 3
    assert ticks >= max(3, int(seconds / 0.001 * 0.2)), (ticks, seconds)


def test_offsets_release_the_gil(robot):
    # A 1 ms sleep loop on the main thread keeps running while a worker computes: with the
    # GIL held it would tick once or twice in total. Ten calls, so the worker runs long enough
    # to count ticks on a fast machine too (one call takes ~9 ms in release).
    ticks, seconds, delta = count_while(
        lambda: [toonkit.smear.offsets(robot) for _ in range(10)][-1]
    )
    assert delta.shape == robot.positions.shape[:2]
    assert seconds > 0.01
    assert ticks >= max(5, int(seconds / 0.001 * 0.2)), (ticks, seconds)


def scaled_glb(tmp_path, rel, scale):
    """The bundled GLB `rel` with its one root node scaled by `scale` (its `scale`, or its
    `matrix` multiplied), the binary chunk kept: the character exported in other units."""
    import json
    import struct

    data = asset(rel).read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    doc = json.loads(data[20:20 + length])
    (root,) = doc["scenes"][0]["nodes"]
    node = doc["nodes"][root]
    if "matrix" in node:
        node["matrix"] = [v * scale if k % 4 != 3 else v for k, v in enumerate(node["matrix"])]
    else:
        node["scale"] = [scale] * 3
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    rest = data[20 + length:]
    out = tmp_path / f"{asset(rel).stem}_{scale}.glb"
    out.write_bytes(b"glTF" + struct.pack("<II", 2, 20 + len(text) + len(rest))
                    + struct.pack("<I", len(text)) + b"JSON" + text + rest)
    return out


@pytest.mark.parametrize("rel,clip", [(ROBOT, "Wave"), ("characters/CesiumMan.glb", 0)])
def test_a_style_means_the_same_in_centimetres_and_metres(tmp_path, rel, clip):
    # docs/smear-units.md: speeds in sizes per second, the size the rest pose's diagonal.
    style = example("smear/fig16_combined.toml")
    runs = []
    for scale in (1.0, 0.01, 100.0):
        scene = toonkit.load(scaled_glb(tmp_path, rel, scale), clip=clip, fps=12)
        look = toonkit.smear.stylize(toonkit.smear.prepare(scene), style)
        size = look.report["size"]
        assert size == pytest.approx(scene.size, rel=1e-6)
        objects = look.report["objects"]
        e = np.mean([o["elongation_mean"] for o in objects]) / size
        lines = [o["lines_length_mean"] for o in objects if o.get("lines_length_mean")]
        runs.append((scale, size, e, np.mean(lines) / size))
    _, size, e, length = runs[0]
    assert e > 1e-4 and length > 1e-4, runs
    for scale, size_k, e_k, length_k in runs[1:]:
        assert size_k == pytest.approx(size * scale, rel=1e-4)
        assert e_k == pytest.approx(e, rel=0.01), f"x{scale}: elongation"
        assert length_k == pytest.approx(length, rel=0.01), f"x{scale}: line length"


def test_from_arrays_takes_the_rest_pose_for_the_size():
    # Arrays' size is their `rest` pose's when given, else their first frame's.
    robot = toonkit.load(asset(ROBOT), clip="Wave")
    rest_size = robot.size
    first = robot.positions[0]
    assert toonkit.Scene.from_arrays(robot.positions, robot.triangles).size == pytest.approx(
        float(np.linalg.norm(np.ptp(first, axis=0))), rel=1e-6)
    stretched = first * np.float32(2.0)
    given = toonkit.Scene.from_arrays(robot.positions, robot.triangles, rest=stretched)
    assert given.size == pytest.approx(2 * float(np.linalg.norm(np.ptp(first, axis=0))), rel=1e-6)
    assert rest_size > 0
    with pytest.raises(ValueError, match="rest"):
        toonkit.Scene.from_arrays(robot.positions, robot.triangles, rest=first[:10])
