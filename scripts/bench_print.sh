#!/usr/bin/env bash
# Whole-process timing of `toonkit stopmo run` on the bundled talking face, where printing the
# pieces (back surfaces, exact crossing tests, the search that moves points) is nearly all of
# the time: the README cut (8 pieces per part, clip at 2 fps), the same cut printed 25 mm high
# (1 fps), and two automatic parts (2 fps; a cut that leaves crossings, so the search runs
# longest). Prints min/median per cut and the crossing triangles and thinnest wall per part.
#
# usage: scripts/bench_print.sh [RUNS]      (needs hyperfine: apt-get install hyperfine)
set -euo pipefail

runs=${1:-3}
root=$(cd "$(dirname "$0")/.." && pwd)
target=${CARGO_TARGET_DIR:-$root/target}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cd "$root"
cargo build -q --release -p toonkit-cli
bin=$target/release/toonkit
face=assets/face/ict-face-talk.glb
readme="--part upper=point:0,10,13 --part lower=point:0,-14,10 --pieces 8"
declare -A cuts=(
    [readme]="$readme --fps 2"
    [readme-25mm]="$readme --fps 1 --print-height 25"
    [auto-parts-2]="--auto-parts 2 --pieces 8 --fps 2"
)
for name in readme readme-25mm auto-parts-2; do
    hyperfine -N --runs "$runs" --export-json "$work/$name.json" \
        "$bin stopmo run $face -o $work/$name ${cuts[$name]}" >/dev/null
    python3 - "$work/$name.json" "$work/$name/report.json" "$name" <<'PY'
import json, statistics, sys
t = json.load(open(sys.argv[1]))["results"][0]["times"]
parts = json.load(open(sys.argv[2]))["printing"]["parts"]
shells = ", ".join(
    f"{p['shell']['self_intersecting_triangles']} crossing / {p['shell']['min_wall_mm']:.2f} mm"
    for p in parts)
print(f"{sys.argv[3]}: min {min(t):.2f} s, median {statistics.median(t):.2f} s ({len(t)} runs); {shells}")
PY
done
