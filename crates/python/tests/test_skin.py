"""`toonkit.skin`: linear blend skinning of a whole clip from per-frame bone matrices (the
Blender extension's pose-only sampling, docs/blender.md)."""

import numpy as np
import pytest

import toonkit


def rotation_z(a, t):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0, t[0]], [s, c, 0, t[1]], [0, 0, 1, t[2]], [0, 0, 0, 1]])


def test_skin_is_the_normalized_weighted_blend_per_frame():
    rng = np.random.default_rng(7)
    rest = rng.normal(size=(50, 3)).astype(np.float32)
    indices = rng.integers(0, 4, size=(50, 3))
    indices[::5, 2] = -1  # padding: no influence
    weights = rng.uniform(0.1, 2.0, size=(50, 3)).astype(np.float32)  # unnormalized
    mats = np.stack([[rotation_z(0.3 * f + b, (f, b, 0.5)) for b in range(4)]
                     for f in range(6)]).astype(np.float32)
    got = toonkit.skin(rest, indices, weights, mats)
    assert got.shape == (6, 50, 3) and got.dtype == np.float32
    w = np.where(indices >= 0, weights, 0.0).astype(np.float64)
    w /= w.sum(axis=1, keepdims=True)
    home = np.concatenate([rest, np.ones((50, 1), np.float32)], axis=1).astype(np.float64)
    moved = np.einsum("fbij,vj->fvbi", mats.astype(np.float64), home)[..., :3]
    want = np.einsum("fvki,vk->fvi", moved[:, np.arange(50)[:, None], np.maximum(indices, 0)], w)
    np.testing.assert_allclose(got, want, atol=1e-5)


def test_a_vertex_without_weights_stays_at_rest():
    rest = np.array([[1.0, 2.0, 3.0], [0.0, 0.0, 0.0]], np.float32)
    mats = np.tile(rotation_z(1.0, (5, 0, 0)), (3, 1, 1, 1)).astype(np.float32)
    got = toonkit.skin(rest, [[-1], [0]], [[1.0], [0.0]], mats)
    np.testing.assert_array_equal(got[:, 0], np.repeat(rest[:1], 3, axis=0))
    np.testing.assert_array_equal(got[:, 1], np.repeat(rest[1:], 3, axis=0))


def test_bad_inputs_are_one_line_value_errors():
    rest = np.zeros((2, 3), np.float32)
    mats = np.tile(np.eye(4, dtype=np.float32), (2, 2, 1, 1))
    with pytest.raises(ValueError, match=r"indices\[1, 0\] = 2"):
        toonkit.skin(rest, [[0], [2]], [[1.0], [1.0]], mats)
    with pytest.raises(ValueError, match="weights must have shape"):
        toonkit.skin(rest, [[0], [1]], [[1.0, 2.0], [1.0, 1.0]], mats)
    with pytest.raises(ValueError, match="matrices must have shape"):
        toonkit.skin(rest, [[0], [1]], [[1.0], [1.0]], mats[..., :3])


def test_a_scene_skinned_in_place_equals_one_from_the_skinned_array():
    """`Scene.from_arrays(None, ..., skinning=...)` skins the clip straight into the scene
    (the Blender bake's transfer without a copy, docs/blender.md "Speed"): the same clip,
    size and offsets, bit for bit, as the array `toonkit.skin` returns handed over."""
    rng = np.random.default_rng(3)
    rest = rng.normal(size=(60, 3)).astype(np.float32)
    indices = np.broadcast_to(np.arange(3), (60, 3))
    weights = rng.uniform(0.0, 1.0, size=(60, 3)).astype(np.float32)
    weights[::4, 1] = 0.0  # a zero weight is no influence
    mats = np.stack([[rotation_z(0.2 * f * (b + 1), (0.3 * f, b, 0.0)) for b in range(3)]
                     for f in range(12)]).astype(np.float32)
    triangles = rng.integers(0, 60, size=(40, 3))
    at_rest = rest + 1.0
    copied = toonkit.Scene.from_arrays(toonkit.skin(rest, indices, weights, mats), triangles,
                                       fps=30.0, objects=[("body", range(60))], rest=at_rest)
    skinned = toonkit.Scene.from_arrays(None, triangles, fps=30.0,
                                        objects=[("body", range(60))], rest=at_rest,
                                        skinning=(rest, indices, weights, mats))
    np.testing.assert_array_equal(skinned.positions, copied.positions)
    assert skinned.size == copied.size and skinned.objects == copied.objects
    a = np.asarray(toonkit.smear.prepare(copied).offsets)
    b = np.asarray(toonkit.smear.prepare(skinned).offsets)
    np.testing.assert_array_equal(a, b)


def test_a_scene_takes_positions_or_skinning_not_both():
    rest = np.zeros((3, 3), np.float32)
    mats = np.tile(np.eye(4, dtype=np.float32), (2, 1, 1, 1))
    skinning = (rest, [[0], [0], [0]], [[1.0], [1.0], [1.0]], mats)
    with pytest.raises(ValueError, match="positions or as skinning"):
        toonkit.Scene.from_arrays(np.zeros((2, 3, 3), np.float32), [[0, 1, 2]],
                                  skinning=skinning)
    with pytest.raises(ValueError, match="positions or as skinning"):
        toonkit.Scene.from_arrays(None, [[0, 1, 2]])
    with pytest.raises(ValueError, match=r"indices\[0, 0\] = 1"):
        toonkit.Scene.from_arrays(None, [[0, 1, 2]],
                                  skinning=(rest, [[1], [0], [0]], [[1.0]] * 3, mats))


def test_a_clip_over_the_memory_budget_is_an_error_not_an_abort():
    # 100,000 frames × 100,000 vertices (120 GB of positions) from inputs of a few MB.
    n = 100_000
    rest = np.zeros((n, 3), np.float32)
    idx, w = np.zeros((n, 1), np.int64), np.ones((n, 1), np.float32)
    mats = np.tile(np.eye(4, dtype=np.float32), (n, 1, 1, 1))
    with pytest.raises(ValueError, match="skinned clip.*over the limit"):
        toonkit.skin(rest, idx, w, mats)
    with pytest.raises(ValueError, match="skinned clip.*over the limit"):
        toonkit.Scene.from_arrays(None, [[0, 1, 2]], skinning=(rest, idx, w, mats))


def test_a_skin_stream_fed_in_chunks_gives_the_clip_of_skin_bit_for_bit():
    """`toonkit.SkinStream` (the Blender bake skins each chunk of frames while Blender reads
    the next ones, docs/blender.md "Speed"): pushed in uneven chunks, the scene it makes holds
    the clip `toonkit.skin` returns, bit for bit, and the same offsets."""
    rng = np.random.default_rng(5)
    rest = rng.normal(size=(70, 3)).astype(np.float32)
    indices = np.broadcast_to(np.arange(3), (70, 3))
    weights = rng.uniform(0.0, 1.0, size=(70, 3)).astype(np.float32)
    weights[::5] = 0.0  # no influence: the vertex stays at rest
    mats = np.stack([[rotation_z(0.15 * f * (b + 1), (0.2 * f, b, 0.1)) for b in range(3)]
                     for f in range(13)]).astype(np.float32)
    triangles = rng.integers(0, 70, size=(50, 3))
    stream = toonkit.SkinStream(rest, indices, weights, frames=13, bones=3)
    for a, b in ((0, 8), (8, 12), (12, 13)):
        stream.push(mats[a:b])
    streamed = toonkit.Scene.from_arrays(None, triangles, fps=24.0, skinning=stream)
    at_once = toonkit.Scene.from_arrays(None, triangles, fps=24.0,
                                        skinning=(rest, indices, weights, mats))
    np.testing.assert_array_equal(streamed.positions, toonkit.skin(rest, indices, weights, mats))
    np.testing.assert_array_equal(np.asarray(toonkit.smear.prepare(streamed).offsets),
                                  np.asarray(toonkit.smear.prepare(at_once).offsets))


def test_a_skin_stream_takes_exactly_its_frames_once():
    rest = np.zeros((3, 3), np.float32)
    idx, w = [[0], [0], [0]], [[1.0]] * 3
    mats = np.tile(np.eye(4, dtype=np.float32), (2, 1, 1, 1))
    stream = toonkit.SkinStream(rest, idx, w, frames=2, bones=1)
    stream.push(mats[:1])
    with pytest.raises(ValueError, match="got 1 of its 2 frames"):
        toonkit.Scene.from_arrays(None, [[0, 1, 2]], skinning=stream)
    stream = toonkit.SkinStream(rest, idx, w, frames=2, bones=1)
    with pytest.raises(ValueError, match="takes 2 frames; 0 were pushed, 3 more"):
        stream.push(np.tile(np.eye(4, dtype=np.float32), (3, 1, 1, 1)))
    with pytest.raises(ValueError, match="matrices must have shape"):
        stream.push(np.tile(np.eye(4, dtype=np.float32), (1, 2, 1, 1)))
    stream.push(mats)
    toonkit.Scene.from_arrays(None, [[0, 1, 2]], skinning=stream)
    with pytest.raises(ValueError, match="already used"):
        toonkit.Scene.from_arrays(None, [[0, 1, 2]], skinning=stream)
    with pytest.raises(ValueError, match=r"indices\[0, 0\] = 1"):
        toonkit.SkinStream(rest, [[1], [0], [0]], w, frames=2, bones=1)
    n = 100_000  # 120 GB of positions: refused before anything is held
    with pytest.raises(ValueError, match="skinned clip.*over the limit"):
        toonkit.SkinStream(np.zeros((n, 3), np.float32), np.zeros((n, 1), np.int64),
                           np.ones((n, 1), np.float32), frames=n, bones=1)
