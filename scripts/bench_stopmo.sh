#!/usr/bin/env bash
# Whole-process stopmo benchmark at feature-film scale (see crates/stopmo/benches/scale.rs):
# builds the release CLI, writes the seeded inputs from the bundled face once, then runs
# each case with every binary given (interleaved, so a shared machine's load hits all alike)
# and prints wall, user and system CPU seconds and peak resident memory.
#
#   scripts/bench_stopmo.sh [--toonkit OTHER_BINARY]... [--repeat K] [--cases face20,table1,print20]
#
# Needs /usr/bin/time (Debian package `time`).
set -euo pipefail
cd "$(dirname "$0")/.."
# --workspace, as CI builds: `-p` resolves other features and rebuilds the dependencies.
cargo build --release --workspace --bins
# The bench runs from the crate's folder: other binaries' paths are made absolute here.
args=()
while [ $# -gt 0 ]; do
    if [ "$1" = --toonkit ] && [ $# -gt 1 ]; then
        args+=(--toonkit "$(realpath -- "$2")")
        shift 2
    else
        args+=("$1")
        shift
    fi
done
exec cargo bench --workspace --bench scale -- \
    --out "$PWD/target/stopmo-scale" --toonkit "$PWD/target/release/toonkit" "${args[@]}"
