"""toonkit.stopmo against `toonkit stopmo run` on the face (2 fps keeps it cheap)."""

import json

import numpy as np
import pytest

import toonkit
from conftest import asset, run_cli

FACE = "face/ict-face-talk.glb"
PARTS = {"upper": [(0, 10, 13)], "lower": [(0, -14, 10)]}
PIECES = {"upper": 4, "lower": 6}


@pytest.fixture(scope="module")
def face():
    return toonkit.load(asset(FACE), fps=2.0)


def test_run_writes_the_cli_layout(face, tmp_path):
    cli = tmp_path / "cli"
    run_cli("stopmo", "run", asset(FACE), "-o", cli, "--fps", "2",
            "--part", "upper=point:0,10,13", "--part", "lower=point:0,-14,10",
            "--pieces", "upper=4,lower=6", "--restarts", "2")
    lib = toonkit.stopmo.run(face, parts=PARTS, pieces=PIECES, restarts=2)
    assert lib.part_names == ["upper", "lower"]
    assert len(lib.pieces) == 10
    labels = lib.labels
    assert labels.shape == (face.frame_count, 2) and labels.dtype == np.int32
    written = lib.save(tmp_path / "py")
    assert "assembly.csv" in written and "report.json" in written
    py = tmp_path / "py"
    for name in ("assembly.csv", "shooting_order.csv"):
        assert (py / name).read_text() == (cli / name).read_text(), name
    ours, theirs = json.loads((py / "report.json").read_text()), json.loads((cli / "report.json").read_text())
    for key in ("energy", "pieces"):
        assert ours[key] == theirs[key]
    assert sorted(p.name for p in (py / "pieces").iterdir()) == sorted(
        p.name for p in (cli / "pieces").iterdir())


def test_no_print_is_the_cli_without_solids(face, tmp_path):
    """``print=False`` is ``--no-print``: the same library and files, no STL solids."""
    cli = tmp_path / "cli"
    run_cli("stopmo", "run", asset(FACE), "-o", cli, "--fps", "2",
            "--part", "upper=point:0,10,13", "--part", "lower=point:0,-14,10",
            "--pieces", "3", "--restarts", "1", "--no-print")
    lib = toonkit.stopmo.run(face, parts=PARTS, pieces=3, restarts=1, print=False)
    py = tmp_path / "py"
    lib.save(py)
    assert (py / "assembly.csv").read_text() == (cli / "assembly.csv").read_text()
    pieces = sorted(p.name for p in (py / "pieces").iterdir())
    assert pieces == sorted(p.name for p in (cli / "pieces").iterdir())
    assert pieces == [f"{part}_{k:02}.obj" for part in ("lower", "upper") for k in range(3)]
    assert lib.report["printing"] is None
    assert json.loads((cli / "report.json").read_text())["printing"] is None
    # The reconstruction in memory is what the files hold (read here by hand, independently).
    rec = lib.reconstruction
    data = (py / "reconstruction.pc2").read_bytes()
    assert data[:12] == b"POINTCACHE2\0"
    points, frames = np.frombuffer(data[16:20], "<i4")[0], np.frombuffer(data[28:32], "<i4")[0]
    pc2 = np.frombuffer(data, "<f4", offset=32).reshape(frames, points, 3)
    assert rec["positions"].shape == pc2.shape == (face.frame_count, len(rec["rest"]), 3)
    assert np.array_equal(rec["positions"], pc2)
    obj = (py / "rest.obj").read_text().splitlines()
    rest = np.array([[float(x) for x in ln.split()[1:4]] for ln in obj if ln.startswith("v ")])
    tris = np.array([[int(x.split("/")[0]) - 1 for x in ln.split()[1:4]]
                     for ln in obj if ln.startswith("f ")])
    assert np.allclose(rec["rest"], rest, atol=1e-5) and np.array_equal(rec["triangles"], tris)


def test_segment_then_library(face, tmp_path):
    seg = toonkit.stopmo.segment(face, parts=PARTS)
    assert seg.part_names == ["upper", "lower"]
    assert set(np.unique(seg.labels)) == {0, 1}
    assert seg.report["parts"] == ["upper", "lower"]
    seg.save(tmp_path / "parts.glb")
    lib = toonkit.stopmo.library(seg, pieces=3, restarts=1, print=False)
    assert [len([p for p in lib.pieces if p["part"] == i]) for i in range(2)] == [3, 3]
    assert len(lib.assembly) == face.frame_count


def test_bad_parts_raise(face):
    with pytest.raises(ValueError):
        toonkit.stopmo.segment(face, parts={"a": [(0, 0)]})
    with pytest.raises(ValueError, match="options"):
        toonkit.stopmo.library(toonkit.stopmo.segment(face, parts=PARTS), pieces=-1)
    # Ten million restarts: refused by the core's range, as the CLI refuses them.
    with pytest.raises(ValueError, match="between 1 and 1024"):
        toonkit.stopmo.library(toonkit.stopmo.segment(face, parts=PARTS), pieces=2,
                               restarts=10**7, print=False)


def test_budget_replaces_the_piece_count(face):
    lib = toonkit.stopmo.run(face, parts=PARTS, budget=5, restarts=1, print=False)
    assert len(lib.pieces) == 5
    with pytest.raises(ValueError, match="budget"):
        toonkit.stopmo.library(toonkit.stopmo.segment(face, parts=PARTS), budget=4,
                               max_error_mm=1.0)


def test_solids_that_cross_as_built_are_regularized(face, tmp_path):
    """A seam through both eyes folds the fronts over the walls where it meets the eye
    openings: the module writes those solids regularized, as the CLI does, and says so."""
    lib = toonkit.stopmo.run(face, parts={"upper": [(0, 15, 8)], "lower": [(0, -8, 12)]},
                             pieces=3, restarts=1)
    parts = lib.report["printing"]["parts"]
    assert any(p["regularized_pieces"] for p in parts), parts
    for p in parts:
        assert p["shell"]["self_intersecting_triangles"] == 0, p
        assert (p["built_self_intersecting_triangles"] > 0) == bool(p["regularized_pieces"])
    assert any("regularized to the material it encloses" in w for w in lib.report["warnings"])
    written = lib.save(tmp_path / "py")
    assert any(name.endswith(".stl") for name in written)


def test_magnets_clearance_and_3mf_are_the_cli_flags(face, tmp_path):
    """``magnets``, ``clearance_mm``, ``print_format``, ``plate_mm``, ``min_wall_mm`` and
    ``min_feature_mm`` are ``--magnets``, ``--clearance``, ``--print-format``, ``--plate``,
    ``--min-wall`` and ``--min-feature``: the same pieces, pockets, plates and printability
    (a printer that forms nothing under 0.5 mm warns about the IDs' 0.4 mm relief)."""
    cli = tmp_path / "cli"
    run_cli("stopmo", "run", asset(FACE), "-o", cli, "--fps", "2",
            "--part", "upper=point:0,10,13", "--part", "lower=point:0,-14,10",
            "--pieces", "2", "--restarts", "1", "--magnets", "3x2", "--clearance", "0.2",
            "--print-format", "stl,3mf", "--plate", "80x60", "--min-wall", "0.9",
            "--min-feature", "0.5")
    lib = toonkit.stopmo.run(face, parts=PARTS, pieces=2, restarts=1, magnets="3x2",
                             clearance_mm=0.2, print_format="stl,3mf", plate_mm=(80, 60),
                             min_wall_mm=0.9, min_feature_mm=0.5)
    py = tmp_path / "py"
    lib.save(py)
    ours = json.loads((py / "report.json").read_text())["printing"]
    theirs = json.loads((cli / "report.json").read_text())["printing"]
    assert ours["magnet"] == {"diameter_mm": 3.0, "height_mm": 2.0}
    assert ours["clearance_mm"] == 0.2
    for key in ("magnet", "clearance_mm", "plates", "pieces", "print_format", "printability"):
        assert ours[key] == theirs[key], key
    assert ours["printability"]["min_wall_mm"] == 0.9
    assert ours["printability"]["min_feature_mm"] == 0.5
    relief = [w for w in lib.report["warnings"] if "embossed ID relief" in w and "--no-ids" in w]
    assert len(relief) == 2, lib.report["warnings"]
    assert [p["magnet_pocket"] for p in ours["parts"]] == [
        p["magnet_pocket"] for p in theirs["parts"]]
    assert all(p["magnet_pocket"]["cover_mm"] >= 1.0 for p in ours["parts"])
    for name in ("library.3mf", "pieces/upper_back.stl", "pieces/lower_back.stl"):
        assert (py / name).is_file() and (cli / name).is_file(), name
    with pytest.raises(ValueError, match="magnet"):
        toonkit.stopmo.run(face, parts=PARTS, pieces=2, restarts=1, magnets="3 by 2")
