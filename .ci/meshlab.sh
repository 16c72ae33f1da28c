#!/usr/bin/env bash
# Issue 19: MeshLab's own self-intersection filter (pymeshlab from PyPI, ~12 s to install) on
# every STL of the README's stopmo example (`stopmo run` on the face at 2 fps, 8 pieces per
# part, with the debug build `cargo test --workspace` left behind), and of a cut whose solids
# cross themselves as built and are regularized (the seam through both eyes), and of an untuned
# cut whose magnet pocket stands in a boss (one piece per part, 15 frames): every solid must
# be watertight with 0 self-intersecting faces. The crate's tests check the same with an exact
# integer test; this is the independent check. All runs mount the pieces with magnets (a
# pocket cut by an exact boolean in every piece and mount), and the first writes library.3mf,
# which lib3mf (the 3MF Consortium's reader, PyPI) must load as watertight millimetre meshes,
# one per piece (.ci/threemf_check.py).
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TERM_COLOR=never
PY=${PYTHON:-python3}
VENV=target/meshlab-venv
OUT=target/meshlab-stopmo

[ -x "$VENV/bin/python" ] || "$PY" -m venv "$VENV"
"$VENV/bin/pip" --disable-pip-version-check --quiet install pymeshlab lib3mf
# `cargo test --workspace` builds target/debug/toonkit (CARGO_BIN_EXE of the CLI tests).
[ -x target/debug/toonkit ] || cargo build --workspace --quiet
rm -rf "$OUT"
start=$(date +%s)
target/debug/toonkit stopmo run assets/face/ict-face-talk.glb -o "$OUT" --fps 2 \
    --part upper=point:0,10,13 --part lower=point:0,-14,10 --pieces 8 \
    --magnets 3x2 --print-format stl,3mf
echo "meshlab: stopmo run took $(( $(date +%s) - start )) s"
"$VENV/bin/python" .ci/meshlab_check.py "$OUT/pieces"
"$VENV/bin/python" .ci/threemf_check.py "$OUT"
rm -rf "$OUT"
start=$(date +%s)
target/debug/toonkit stopmo run assets/face/ict-face-talk.glb -o "$OUT" --fps 2 \
    --part upper=point:0,15,8 --part lower=point:0,-8,12 --pieces 8 --magnets 3x2
echo "meshlab: stopmo run (seam through the eyes) took $(( $(date +%s) - start )) s"
# The regularization must have had work to do, or this checks nothing new.
"$VENV/bin/python" -c 'import json, sys
parts = json.load(open(sys.argv[1]))["printing"]["parts"]
sys.exit(0 if any(p["regularized_pieces"] for p in parts) else "meshlab: nothing was regularized")' \
    "$OUT/report.json"
"$VENV/bin/python" .ci/meshlab_check.py "$OUT/pieces"
rm -rf "$OUT"
rm -rf "$OUT"
# A cut none of the printing was tuned on, one piece per part at the default 1.5 mm back: the
# upper part's back is too thin for the pocket, which stands in a boss on every piece (joined
# by an exact union) and in a recess of the mount.
start=$(date +%s)
target/debug/toonkit stopmo run assets/face/ict-face-talk.glb -o "$OUT" --fps 0.5 \
    --part upper=point:0,5,14 --part lower=point:0,-16,6 --pieces 1 --seed 11 --restarts 1 \
    --magnets 3x2
echo "meshlab: stopmo run (an untuned cut, magnets in a boss) took $(( $(date +%s) - start )) s"
"$VENV/bin/python" -c 'import json, sys
parts = json.load(open(sys.argv[1]))["printing"]["parts"]
sys.exit(0 if any(p["magnet_pocket"]["boss"] for p in parts) else "meshlab: no pocket needed a boss")' \
    "$OUT/report.json"
"$VENV/bin/python" .ci/meshlab_check.py "$OUT/pieces"
rm -rf "$OUT"
