#!/usr/bin/env python3
"""MeshLab's self-intersection test on every STL of a folder (issue 19 acceptance).

Usage: python3 .ci/meshlab_check.py DIR [DIR ...]

Needs `pip install pymeshlab`. For every `*.stl` under each DIR (recursively) it runs
MeshLab's "Select Self Intersecting Faces" filter and prints the number of selected faces and
whether the mesh is watertight (no boundary or non-manifold edge); exits 1 when any file has a
self-intersecting face or is not watertight, 2 when no STL was found.
"""

import pathlib
import sys

import pymeshlab


def check(path: pathlib.Path) -> tuple[int, int, bool]:
    """(faces, self-intersecting faces, watertight) of one STL."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    # STL stores unshared vertices: merge them so adjacent faces are recognised as adjacent.
    ms.meshing_merge_close_vertices(threshold=pymeshlab.PercentageValue(0.0001))
    mesh = ms.current_mesh()
    faces = mesh.face_number()
    ms.compute_selection_by_self_intersections_per_face()
    hits = ms.current_mesh().selected_face_number()
    topo = ms.get_topological_measures()
    watertight = (
        topo.get("boundary_edges", 1) == 0
        and topo.get("non_two_manifold_edges", 1) == 0
    )
    return faces, hits, watertight


def main(argv: list[str]) -> int:
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    files = sorted(
        p for d in argv[1:] for p in pathlib.Path(d).rglob("*.stl") if p.is_file()
    )
    if not files:
        print(f"no .stl under {' '.join(argv[1:])}", file=sys.stderr)
        return 2
    failed = 0
    for f in files:
        faces, hits, watertight = check(f)
        ok = hits == 0 and watertight
        failed += not ok
        print(
            f"{'ok  ' if ok else 'FAIL'} {f}: {hits} of {faces} faces self-intersect, "
            f"{'watertight' if watertight else 'NOT watertight'}"
        )
    print(f"{len(files) - failed} of {len(files)} STL files clean")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
