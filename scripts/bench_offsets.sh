#!/usr/bin/env bash
# Whole-process timing of `toonkit smear offsets` on the benchmark tube (15,002 vertices
# skinned to a 10-bone chain, 40 frames; the scene of crates/smear/benches/offsets.rs written
# to .glb). Target (issue 14): ≤ 12.8 ms, 100× the authors' Blender add-on (1.28 s).
#
# usage: scripts/bench_offsets.sh [RUNS]      (needs hyperfine: apt-get install hyperfine)
#
# The VM's speed drifts over minutes: to compare two builds, time them run after run with
# scripts/bench_offsets_interleaved.py TUBE.glb RUNS BUILD_A BUILD_B.
set -euo pipefail

runs=${1:-50}
root=$(cd "$(dirname "$0")/.." && pwd)
target=${CARGO_TARGET_DIR:-$root/target}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cd "$root"
cargo build -q --release -p toonkit-cli
cargo run -q --release -p toonkit-smear --example write_tube -- "$work/tube.glb" 40
bin=$target/release/toonkit
hyperfine -N --warmup 5 --runs "$runs" --export-json "$work/offsets.json" \
    "$bin smear offsets $work/tube.glb -o $work/offsets.npy" \
    "$bin convert $work/tube.glb $work/tube.pc2"
python3 - "$work/offsets.json" <<'PY'
import json, statistics, sys
for r in json.load(open(sys.argv[1]))["results"]:
    t = [x * 1000 for x in r["times"]]
    print(f"{r['command'].split()[1:3]}: min {min(t):.2f} ms, median {statistics.median(t):.2f} ms ({len(t)} runs)")
PY
