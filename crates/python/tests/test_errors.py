"""Bad inputs raise FileNotFoundError / ValueError / toonkit.ToonkitError with the CLI's
one-line message; never a crash, never a silent NaN."""

import numpy as np
import pytest

import toonkit
from conftest import ROBOT, asset, cli_error


def one_line(excinfo):
    msg = str(excinfo.value)
    assert msg and "\n" not in msg
    return msg.strip()


def test_toonkit_error_is_an_exception():
    assert issubclass(toonkit.ToonkitError, Exception)


def test_missing_file(tmp_path):
    path = tmp_path / "nope.glb"
    with pytest.raises(FileNotFoundError) as e:
        toonkit.load(path)
    # The CLI prints the OS error's source chain once more after the same text.
    assert cli_error("info", path).startswith(one_line(e))
    assert one_line(e).startswith(str(path))


def test_malformed_file(tmp_path):
    path = tmp_path / "broken.glb"
    path.write_bytes(b"glTF\x02\x00\x00\x00garbage")
    with pytest.raises(toonkit.ToonkitError) as e:
        toonkit.load(path)
    assert one_line(e) == cli_error("info", path)


def test_unknown_clip_and_bad_fps():
    with pytest.raises(ValueError) as e:
        toonkit.load(asset(ROBOT), clip="Moonwalk")
    assert one_line(e) == cli_error(
        "smear", "offsets", asset(ROBOT), "--clip", "Moonwalk", "-o", "x.npy"
    )
    with pytest.raises(ValueError) as e:
        toonkit.load(asset(ROBOT), fps=0.0)
    assert "fps must be a positive number" in one_line(e)


def test_unknown_prune_joint_and_camera(robot, tmp_path):
    out = tmp_path / "o.npy"
    with pytest.raises(ValueError) as e:
        toonkit.smear.offsets(robot, prune=["Tail"])
    assert one_line(e) == cli_error(
        "smear", "offsets", asset(ROBOT), "--clip", "Dance", "--prune", "Tail", "-o", out
    )
    with pytest.raises(ValueError) as e:
        toonkit.smear.offsets(robot, camera="Cam")
    assert one_line(e) == cli_error(
        "smear", "offsets", asset(ROBOT), "--clip", "Dance", "--camera", "Cam", "-o", out
    )
    assert not out.exists()


@pytest.mark.parametrize(
    "positions, triangles, match",
    [
        (np.zeros((2, 4)), [[0, 1, 2]], "positions must have shape"),
        (np.zeros((2, 4, 3)), [[0, 1, 4]], "refers to vertex 4"),
        (np.zeros((2, 4, 3)), [[0, 1, -1]], "refers to vertex -1"),
        (np.zeros((2, 4, 3)), [[0, 1]], "triangles must have shape"),
        (np.full((2, 4, 3), np.nan), [[0, 1, 2]], "<arrays>"),
        (np.zeros((0, 4, 3)), [[0, 1, 2]], "at least one frame"),
    ],
)
def test_from_arrays_rejects_bad_arrays(positions, triangles, match):
    with pytest.raises(ValueError, match=match) as e:
        toonkit.Scene.from_arrays(positions, triangles)
    one_line(e)


def test_from_arrays_rejects_bad_skin(robot):
    p, t, skin = robot.positions, robot.triangles, dict(robot.skin)
    with pytest.raises(ValueError, match="skin has no \"weights\""):
        toonkit.Scene.from_arrays(p, t, skin={k: v for k, v in skin.items() if k != "weights"})
    with pytest.raises(ValueError, match="matrices"):
        toonkit.Scene.from_arrays(p, t, skin={**skin, "matrices": skin["matrices"][:1]})
    parents = np.array(skin["parents"])
    parents[0] = 5
    with pytest.raises(ValueError, match="earlier joint"):
        toonkit.Scene.from_arrays(p, t, skin={**skin, "parents": parents})
    with pytest.raises(ValueError, match="fps"):
        toonkit.Scene.from_arrays(p, t, fps=-1.0)
