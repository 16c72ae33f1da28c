#!/usr/bin/env bash
# CI for scene caches and farm batches (issue 21), called by .ci/run after the Rust tests:
# 1. a 3-shot manifest (RobotExpressive Punch, a smear elongate of it, CesiumMan) through
#    `toonkit batch`: run, then re-run (every shot skipped); the kill-and-resume and
#    failing-shot cases are Rust tests (crates/cli/tests/batch.rs);
# 2. the same manifest as an Open Job Description template: `openjd check`, `openjd run` of
#    every step, and the files equal those of `toonkit batch` byte for byte;
# 3. Blender 4.2 (bpy, headless) imports every .abc and .usdc of the batch: one object, the
#    frame range, vertex positions = the shot's .pc2 at 3 frames, velocities of the moving
#    .usdc = the motion; motion lines (.usda BasisCurves) import as curves
#    (.ci/blender_caches.py);
# 4. Pixar's usd-core opens every .usdc/.usdz of the batch and its compliance checks pass
#    (.ci/validate_usd.py; .ci/run checks those the Rust tests left in $TOONKIT_VALIDATE_DIR).
# Python tools live in a venv under target/ (bpy 4.2 wants CPython 3.11).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT="$PWD"
VENV="$ROOT/target/caches-venv"
PY=python3.11
command -v "$PY" >/dev/null || PY=python3
test -x "$VENV/bin/python" || "$PY" -m venv "$VENV"
"$VENV/bin/pip" install --quiet --disable-pip-version-check \
    "bpy==4.2.0" "numpy<2" "openjd-cli" "usd-core==26.11"

# The binaries `cargo test --workspace` built (`cargo build` would resolve other features
# without the dev-dependencies and rebuild much of the workspace).
cargo test --quiet --workspace --no-run
TK="$ROOT/target/debug/toonkit"
WORK="$ROOT/target/caches"
rm -rf "$WORK"
mkdir -p "$WORK"
ASSETS="$ROOT/assets/characters"
cat > "$WORK/shots.toml" <<TOML
[[shot]]
name = "robot_punch"
tool = "convert"
input = "$ASSETS/RobotExpressive.glb"
clip = "Punch"
outputs = ["robot_punch.abc", "robot_punch.usdc", "robot_punch.pc2", "robot_punch.usdz"]

[[shot]]
name = "robot_punch_elongate"
tool = "smear elongate"
input = "$ASSETS/RobotExpressive.glb"
clip = "Punch"
outputs = ["elongate/robot_punch.abc", "elongate/robot_punch.usdc", "elongate/robot_punch.pc2"]

[[shot]]
name = "cesium_walk"
tool = "convert"
input = "$ASSETS/CesiumMan.glb"
outputs = ["cesium_walk.abc", "cesium_walk.usdc", "cesium_walk.pc2"]
TOML

echo "== toonkit batch"
"$TK" batch "$WORK/shots.toml" -o "$WORK/batch" --jobs 2
"$TK" --json batch "$WORK/shots.toml" -o "$WORK/batch" > "$WORK/rerun.json"
"$VENV/bin/python" - "$WORK/rerun.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["skipped"] == 3 and r["done"] == 0 and r["failed"] == 0, r
print("re-run: every shot skipped")
PY

echo "== Open Job Description"
"$TK" batch "$WORK/shots.toml" -o "$WORK/openjd" --openjd "$WORK/job.yaml"
"$VENV/bin/openjd" check "$WORK/job.yaml"
for step in convert smear; do
    "$VENV/bin/openjd" run "$WORK/job.yaml" --step "$step" --job-param Toonkit="$TK"
done
(cd "$WORK/batch" && find . -type f ! -path './.toonkit-batch/*' | sort) > "$WORK/batch.files"
(cd "$WORK/openjd" && find . -type f ! -path './.toonkit-batch/*' | sort) > "$WORK/openjd.files"
diff "$WORK/batch.files" "$WORK/openjd.files"
while read -r f; do cmp "$WORK/batch/$f" "$WORK/openjd/$f"; done < "$WORK/batch.files"
echo "openjd run: the same $(wc -l < "$WORK/batch.files") files as toonkit batch"

# Motion lines as USD BasisCurves, for the Blender import check (curves) and Pixar's checks.
mkdir -p "$WORK/batch/lines"
"$TK" smear lines "$ASSETS/RobotExpressive.glb" --clip Punch --fps 12 --count 0:0,4:40 \
    --length-max 4 -o "$WORK/batch/lines/robot_lines.usda"

echo "== Blender 4.2 imports"
"$VENV/bin/python" .ci/blender_caches.py "$WORK/batch"

echo "== Pixar USD"
"$VENV/bin/python" .ci/validate_usd.py "$WORK/batch"
