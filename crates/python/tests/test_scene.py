"""toonkit.load and toonkit.Scene against the CLI's reading of the same files."""

import numpy as np
import pytest

import toonkit
from conftest import ROBOT, asset, cli_json, read_pc2, run_cli


def test_load_matches_convert_to_pc2(robot, tmp_path):
    # `toonkit convert IN OUT.pc2` writes the merged vertex order SPEC names.
    out = tmp_path / "robot.pc2"
    run_cli("convert", asset(ROBOT), "--clip", "Dance", out)
    cached = read_pc2(out)
    assert robot.positions.dtype == np.float32
    assert robot.positions.shape == cached.shape
    np.testing.assert_allclose(robot.positions, cached, atol=1e-6, rtol=0)


def test_scene_metadata_matches_info(robot):
    info = cli_json("info", asset(ROBOT))
    frames, vertices, _ = robot.positions.shape
    dance = [c for c in info["clips"] if c["name"] == "Dance"][0]
    assert frames == dance["frames"] == robot.frame_count
    assert vertices == sum(m["vertices"] for m in info["meshes"]) == robot.vertex_count
    assert robot.triangles.dtype == np.int32
    assert robot.triangles.shape == (sum(m["triangles"] for m in info["meshes"]), 3)
    assert robot.triangles.min() >= 0 and robot.triangles.max() < vertices
    assert len(robot.joint_names) == info["joints"]
    assert robot.fps == 24.0
    # Objects tile the vertex range in order.
    stops = [r.start for _, r in robot.objects] + [vertices]
    assert stops[0] == 0
    assert all(r.stop == stops[i + 1] for i, (_, r) in enumerate(robot.objects))
    assert "Dance" in repr(robot) or "RobotExpressive" in repr(robot)


def test_arrays_are_read_only_views(robot):
    assert not robot.positions.flags.writeable
    assert robot.positions is robot.positions or np.shares_memory(
        robot.positions, robot.positions
    )


def test_clip_by_index_and_fps(robot):
    info = cli_json("info", asset(ROBOT))
    index = [c["name"] for c in info["clips"]].index("Dance")
    by_index = toonkit.load(str(asset(ROBOT)), clip=index)
    np.testing.assert_array_equal(by_index.positions, robot.positions)
    half = toonkit.load(asset(ROBOT), clip="Dance", fps=12.0)
    assert half.fps == 12.0
    assert half.frame_count < robot.frame_count


def test_skin_round_trip(robot):
    skin = robot.skin
    joints = len(robot.joint_names)
    assert skin["matrices"].shape == (robot.frame_count, joints, 4, 4)
    assert skin["weights"].shape == (robot.vertex_count, joints)
    assert skin["parents"].shape == (joints,)
    # Rows are normalized weights on skinned objects, zero on the rigid props (most of the
    # robot's objects are props parented to joints: object_parents names their joints).
    sums = skin["weights"].sum(axis=1)
    assert np.all((np.abs(sums - 1.0) < 1e-5) | (sums == 0.0))
    assert len(skin["object_parents"]) == len(robot.objects)
    for (name, r), parent in zip(robot.objects, skin["object_parents"]):
        assert parent >= 0 or sums[r.start] == 1.0, name
    # Matrices are row-major with the translation in column 3.
    np.testing.assert_allclose(skin["matrices"][:, :, 3, :], [[[0, 0, 0, 1]] * joints] * robot.frame_count, atol=1e-6)


def test_from_arrays_without_skin(robot):
    s = toonkit.Scene.from_arrays(robot.positions.astype(np.float64), robot.triangles, fps=30.0)
    np.testing.assert_array_equal(s.positions, robot.positions)
    np.testing.assert_array_equal(s.triangles, robot.triangles)
    assert s.fps == 30.0 and s.skin is None and s.joint_names == []
    assert [r for _, r in s.objects] == [range(0, robot.vertex_count)]


def test_from_arrays_attributes_are_painted_weights(robot):
    # A painted attribute (e.g. a Blender vertex group) drives `weights = { attribute }`:
    # weight 0 everywhere leaves the input untouched, weight 1 equals no weights at all.
    scene = lambda w: toonkit.Scene.from_arrays(  # noqa: E731
        robot.positions, robot.triangles, fps=robot.fps, skin=robot.skin,
        objects=robot.objects, attributes={"paint": w},
    )
    n = robot.vertex_count
    style = {"elongate": {"function": {"stages": [{"op": "weight"}, {"op": "scale", "by": 3}]}},
             "weights": {"attribute": "paint"}}
    zero = toonkit.smear.stylize(toonkit.smear.prepare(scene(np.zeros(n, np.float32))), style)
    np.testing.assert_array_equal(zero.elongated, robot.positions)
    one = toonkit.smear.stylize(toonkit.smear.prepare(scene(np.ones(n, np.float32))), style)
    plain = toonkit.smear.stylize(toonkit.smear.prepare(robot), {
        "elongate": {"function": {"stages": [{"op": "scale", "by": 3}]}}})
    np.testing.assert_allclose(one.elongated, plain.elongated, atol=1e-5)
    assert np.abs(one.elongated - robot.positions).max() > 1e-3
    with pytest.raises(ValueError, match="attributes"):
        scene(np.ones(n + 1, np.float32))
