"""toonkit.smear against `toonkit smear ...` on the same inputs."""

import threading
import time

import numpy as np
import pytest

import toonkit
from conftest import ROBOT, asset, run_cli


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
    assert np.abs(delta - toonkit.smear.offsets(robot)).max() > 1e-3  # the option acts


def test_from_arrays_with_skin_gives_the_same_offsets(robot):
    scene = toonkit.Scene.from_arrays(
        robot.positions, robot.triangles, fps=robot.fps, skin=robot.skin
    )
    assert scene.joint_names == robot.joint_names
    loaded = toonkit.smear.offsets(robot)
    np.testing.assert_allclose(toonkit.smear.offsets(scene), loaded, atol=1e-6, rtol=0)
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


def test_offsets_release_the_gil(robot):
    # A 1 ms sleep loop on the main thread keeps running while a worker computes: with the
    # GIL held it would tick once or twice in total.
    ticks, seconds, delta = count_while(lambda: toonkit.smear.offsets(robot))
    assert delta.shape == robot.positions.shape[:2]
    assert seconds > 0.01
    assert ticks >= max(5, int(seconds / 0.001 * 0.2)), (ticks, seconds)
