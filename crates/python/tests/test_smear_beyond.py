"""toonkit.smear beyond the paper (issue #22): causal mode, revolving objects, streaming."""

import numpy as np
import pytest

import toonkit
from conftest import ROBOT, asset, run_cli

LINEAR = {"elongate": {"function": {"stages": [{"op": "scale", "by": 1}]}}}


def hopping_box(frames=20):
    """A box hopping along +X (float32 positions (frames, 8, 3), triangles (12, 3))."""
    corners = np.array(
        [[x, y, z] for y in (0, 1) for z in (-0.5, 0.5) for x in (-0.5, 0.5)], dtype=np.float32
    )
    tris = np.array(
        [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
         [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]],
        dtype=np.int32,
    )
    t = np.arange(frames, dtype=np.float32)
    shift = np.stack([0.3 * t, 2.0 * np.abs(np.sin(t * np.pi / 8)), 0 * t], axis=1)
    return (corners[None] + shift[:, None]).astype(np.float32), tris


def test_causal_offsets_equal_cli(tmp_path):
    robot = toonkit.load(asset(ROBOT), clip="Dance")
    out = tmp_path / "causal.npy"
    run_cli("smear", "offsets", asset(ROBOT), "--clip", "Dance", "--causal", "-o", out)
    causal = toonkit.smear.offsets(robot, causal=True)
    assert np.abs(causal - np.load(out)).max() <= 1e-6
    assert np.abs(causal - toonkit.smear.offsets(robot)).max() > 1e-3  # the option acts


def test_causal_frames_ignore_the_future():
    pos, tris = hopping_box()
    other = pos.copy()
    other[11:] += np.float32([0.0, 3.0, 1.0])
    a = toonkit.smear.stylize(
        toonkit.smear.prepare(toonkit.Scene.from_arrays(pos, tris), causal=True), LINEAR
    ).elongated
    b = toonkit.smear.stylize(
        toonkit.smear.prepare(toonkit.Scene.from_arrays(other, tris), causal=True), LINEAR
    ).elongated
    np.testing.assert_array_equal(a[:11], b[:11])
    assert np.abs(a[11:] - b[11:]).max() > 0.1


def test_stream_matches_causal_stylize():
    pos, tris = hopping_box()
    prepared = toonkit.smear.prepare(toonkit.Scene.from_arrays(pos, tris), causal=True)
    offline = toonkit.smear.stylize(prepared, LINEAR).elongated
    s = toonkit.smear.stream(tris, pos.shape[1])
    for f in range(pos.shape[0]):
        out = s.push(pos[f])
        assert out.shape == (8, 3) and out.dtype == np.float32
        assert np.abs(out - offline[f]).max() <= 1e-4, f
    assert s.frames_pushed == pos.shape[0]
    np.testing.assert_allclose(s.offsets, prepared.offsets[-1], atol=1e-5)
    with pytest.raises(ValueError, match="positions"):
        s.push(pos[0][:3])
    with pytest.raises(ValueError, match="triangles"):
        toonkit.smear.stream(tris + 100, 8)


def test_stream_ground_keeps_points_above():
    pos, tris = hopping_box()
    s = toonkit.smear.stream(tris, 8, elongate={"stages": [{"op": "scale", "by": 3}]}, ground=0.0)
    low = min(s.push(p)[:, 1].min() for p in pos)
    assert low >= 0.0


def test_revolve_names_unknown_objects():
    pos, tris = hopping_box()
    scene = toonkit.Scene.from_arrays(pos, tris)
    with pytest.raises(ValueError, match="wheel"):
        toonkit.smear.prepare(scene, revolve=["wheel"])


def test_colliders_keep_the_smear_out_of_a_slab():
    pos, tris = hopping_box()
    # Drop the box onto y = 0 and stop it there: Catmull-Rom overshoots the stop.
    t = np.arange(pos.shape[0], dtype=np.float32)
    pos = pos - pos[:, :1] + pos[:1, :1]  # the box's own shape, at the origin
    pos = pos + np.stack([0.3 * t, np.maximum(4.0 - 0.5 * t, 0.0), 0 * t], 1)[:, None]
    pos = pos.astype(np.float32)
    # A slab under the hops (top y = 0): the box corners of hopping_box, scaled.
    lo, hi = np.float32([-2.0, -1.0, -1.0]), np.float32([8.0, 0.0, 1.0])
    corners = np.array(
        [[x, y, z] for y in (lo[1], hi[1]) for z in (lo[2], hi[2]) for x in (lo[0], hi[0])],
        dtype=np.float32,
    )
    slab = toonkit.Scene.from_arrays(corners[None], tris)
    scene = toonkit.Scene.from_arrays(pos, tris)

    def inside(points):
        return int(np.all((points > lo + 1e-6) & (points < hi - 1e-6), axis=-1).sum())

    free = toonkit.smear.stylize(toonkit.smear.prepare(scene), LINEAR).elongated
    assert inside(free) > 0  # trajectories overshoot the landings into the slab
    kept = toonkit.smear.stylize(toonkit.smear.prepare(scene, colliders=[slab]), LINEAR)
    assert inside(kept.elongated) == 0
    assert np.abs(kept.elongated - pos).max() > 0.1  # still smeared
    with pytest.raises(toonkit.ToonkitError, match="Ramp"):
        toonkit.smear.prepare(scene, colliders="Ramp")
