"""toonkit.loa against `toonkit loa line` / `loa animate` and the studio's loa panel on the
examples' keystrokes: all of them call the loa crate's one scene-level job."""

import json
import re

import numpy as np
import pytest

import toonkit
from conftest import example, run_cli


def keystrokes(name):
    doc = json.loads(example(f"loa/{name}").read_text())
    keys = []
    for k in doc["keystrokes"]:
        entry = {"frame": k["frame"], "points": np.array(k["points"])}
        for opt in ("stiffness", "damping"):
            if opt in k or opt in doc:
                entry[opt] = k.get(opt, doc.get(opt))
        keys.append(entry)
    return keys, doc.get("fps", 24.0)


@pytest.mark.parametrize("name, mode", [("jump.json", "physics"), ("whip.json", "hermite")])
def test_line_equals_cli_json(tmp_path, name, mode):
    out = tmp_path / "line.json"
    run_cli("loa", "line", example(f"loa/{name}"), "--mode", mode, "-o", out)
    expected = json.loads(out.read_text())
    keys, fps = keystrokes(name)
    line = toonkit.loa.line(keys, mode=mode, fps=fps)
    assert line.keystroke_frames == expected["keystroke_frames"]
    assert line.frames == [f["frame"] for f in expected["frames"]]
    points = np.array([f["points"] for f in expected["frames"]])
    assert line.points.shape == points.shape and line.points.shape[2] == 2
    np.testing.assert_allclose(line.points, points, atol=1e-9, rtol=0)
    np.testing.assert_allclose(line.angles, [f["angles"] for f in expected["frames"]], atol=1e-12)
    assert json.loads(line.to_json()) == expected
    saved = line.save(tmp_path / "again.json")
    assert json.loads(saved.read_text()) == expected


def test_bad_keystrokes_raise():
    with pytest.raises(ValueError, match="frame"):
        toonkit.loa.line([{"frame": 5, "points": [[0, 0], [1, 1]]},
                          {"frame": 2, "points": [[0, 0], [1, 2]]}])
    with pytest.raises(ValueError, match="shape"):
        toonkit.loa.line([{"frame": 0, "points": [0, 1, 2]}])
    with pytest.raises(ValueError, match="bouncy"):
        toonkit.loa.line([{"frame": 0, "points": [[0, 0], [1, 1]]}], mode="bouncy")
    with pytest.raises(ValueError):
        toonkit.loa.line([])
    line = toonkit.loa.line([{"frame": 0, "points": [[0, 0], [1, 1]]},
                             {"frame": 4, "points": [[0, 0], [1, 2]]}])
    with pytest.raises(ValueError, match=r"\.json or \.svg"):
        line.save("line.png")


JUMP_FLAGS = ["--bones", "right-leg-spine-head@0", "--bones", "left-leg-spine-head@22",
              "--contact", "FootL@0..3", "--twist", "Torso_1@22:20"]


def test_animate_equals_cli_bvh(robot, tmp_path):
    from conftest import ROBOT, asset

    out = tmp_path / "cli.bvh"
    run_cli("loa", "animate", asset(ROBOT), example("loa/jump.json"), "-o", out, *JUMP_FLAGS)
    keys, fps = keystrokes("jump.json")
    line = toonkit.loa.line(keys, fps=fps)
    motion = toonkit.loa.animate(
        asset(ROBOT), line,
        bones=["right-leg-spine-head@0", "left-leg-spine-head@22"],
        contacts="FootL@0..3", twists=["Torso_1@22:20"],
    )
    frames = len(line.frames)
    assert motion.rotations.shape == (frames, len(motion.joint_names), 4)
    np.testing.assert_allclose(np.linalg.norm(motion.rotations, axis=2), 1.0, atol=1e-6)
    assert motion.report["line_distance_mean"] < 0.5
    saved = motion.save(tmp_path / "py.bvh")
    assert saved.read_text() == out.read_text()
    # A loaded scene works as the character too.
    again = toonkit.loa.animate(toonkit.load(asset(ROBOT)), line,
                                bones=["right-leg-spine-head@0", "left-leg-spine-head@22"],
                                contacts="FootL@0..3", twists=["Torso_1@22:20"])
    np.testing.assert_array_equal(again.rotations, motion.rotations)


# Two bundled characters and a bone set each finds (the robot's names, CesiumMan's hierarchy).
LOA_CHARACTERS = {
    "robot": ("characters/RobotExpressive.glb", "right-leg-spine-head"),
    "cesium": ("characters/CesiumMan.glb", "foot-head"),
}


@pytest.mark.parametrize("name", sorted(LOA_CHARACTERS))
def test_the_loa_job_gives_the_same_files_through_the_cli_python_and_the_studio(
        name, studio, tmp_path):
    from conftest import STUDIO_FILES, asset, studio_post, studio_unpack

    rel, preset = LOA_CHARACTERS[name]
    keys, fps = keystrokes("jump.json")
    line = toonkit.loa.line(keys, fps=fps)
    bones = f"{preset}@{keys[0]['frame']}"
    run_cli("loa", "animate", asset(rel), example("loa/jump.json"), "-o", tmp_path / "cli.glb",
            "--bvh", tmp_path / "cli.bvh", "--bones", bones)
    motion = toonkit.loa.animate(asset(rel), line, bones=[bones])
    assert motion.save(tmp_path / "py.bvh").read_text() == (tmp_path / "cli.bvh").read_text()
    assert motion.save(tmp_path / "py.glb").read_bytes() == (tmp_path / "cli.glb").read_bytes()
    # The studio's page: the same keystrokes drawn on a canvas, then its export.
    url, out = studio
    width, height = 800.0, 600.0
    page = [{"frame": k["frame"], "points": np.asarray(k["points"]).tolist(),
             **{o: k[o] for o in ("stiffness", "damping") if o in k}} for k in keys]
    page[0]["bones"] = preset
    header, _ = studio_unpack(studio_post(url, "/api/loa/animate", {
        "file": STUDIO_FILES.index(rel), "keystrokes": page, "width": width, "height": height,
        "fps": fps, "frame": 0}))
    studio_post(url, "/api/loa/export", {"name": f"{name}.bvh"})
    drawn = toonkit.loa.animate(asset(rel), line, bones=[bones], canvas=(width, height))
    assert header["motion"]["frames"] == len(line.frames)
    assert drawn.save(tmp_path / "drawn.bvh").read_text() == (out / f"{name}.bvh").read_text()
    # The canvas is a different screen map from the CLI's fitted one: a different motion.
    assert not np.array_equal(drawn.rotations, motion.rotations)


def test_animate_bad_input(robot):
    keys, fps = keystrokes("jump.json")
    line = toonkit.loa.line(keys, fps=fps)
    with pytest.raises(ValueError, match="no joint named 'no-such-preset'"):
        toonkit.loa.animate(robot, line, bones=["no-such-preset@0"])
    arrays = toonkit.Scene.from_arrays(robot.positions, robot.triangles)
    with pytest.raises(ValueError, match="not a character"):
        toonkit.loa.animate(arrays, line)


def test_values_outside_the_documented_ranges_raise_naming_the_range():
    assert toonkit.loa.STIFFNESS_RANGE == (5.0, 100.0)
    assert toonkit.loa.DAMPING_RANGE == (0.05, 0.5)
    stroke = np.array([[0.0, 0.0], [50.0, -30.0], [100.0, 0.0]])
    for opt, value, text in [("stiffness", 540, "[5, 100]"), ("damping", 0.9, "[0.05, 0.5]")]:
        keys = [{"frame": 0, "points": stroke}, {"frame": 12, "points": stroke, opt: value}]
        with pytest.raises(ValueError, match=re.escape(text)):
            toonkit.loa.line(keys)
    lo, hi = toonkit.loa.STIFFNESS_RANGE
    ok = [{"frame": 0, "points": stroke, "stiffness": lo},
          {"frame": 12, "points": stroke, "stiffness": hi}]
    assert toonkit.loa.line(ok).points.shape[0] > 12


def test_bone_set_presets_come_from_the_core_and_resolve_like_the_cli(tmp_path):
    """`BONE_SETS` lists the core's presets (the CLI's `--bones` names, the raised-arm and the
    hierarchy ones); `bone_chain` gives the chain `animate` maps onto the line, and the CLI
    measures the same joints for it."""
    from conftest import ROBOT, asset

    names = [p[0] for p in toonkit.loa.BONE_SETS]
    for name in ("right-leg-spine-head", "full-body", "right-leg-spine-arm", "foot-head",
                 "spine-head"):
        assert name in names
    assert all(len(p) == 3 and all(p) for p in toonkit.loa.BONE_SETS)
    chain = toonkit.loa.bone_chain(asset(ROBOT), "foot-head", pose="Dance@1")
    assert chain[0] == "FootR" and chain[1] == "LowerLegR" and chain[-1] == "Head"
    assert toonkit.loa.bone_chain(asset(ROBOT), "FootL,Head")[:2] == ["FootL", "LowerLegL"]
    out = tmp_path / "cli.bvh"
    report = json.loads(run_cli("--json", "loa", "animate", asset(ROBOT),
                                example("loa/jump.json"), "-o", out,
                                "--bones", "foot-head@0").stdout)
    measured = {j.replace(" (tip)", "") for j in report["line_distance_joints"]}
    chain = toonkit.loa.bone_chain(asset(ROBOT), "foot-head")
    assert measured <= set(chain) and {chain[0], chain[-1]} <= measured
    with pytest.raises(ValueError, match="NoSuchBone"):
        toonkit.loa.bone_chain(asset(ROBOT), "FootL,NoSuchBone")
