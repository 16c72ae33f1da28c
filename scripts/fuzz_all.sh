#!/usr/bin/env bash
# Runs every fuzz target of fuzz/ one after the other on stable Rust (cargo-fuzz through
# RUSTC_BOOTSTRAP=1, no sanitizer: the code is safe Rust, so a crash is a panic, which debug
# assertions and the targets' own round-trip checks turn into findings).
#
#   scripts/fuzz_all.sh [RUNS] [SECONDS] [TARGET...]
#
# RUNS (default 10000000) and SECONDS (default 1800) stop each target at whichever comes
# first. Inputs are at most MAX_LEN bytes (default 8192: every reader's structure fits, and
# runs stay fast; a corpus grown with 64 KiB inputs made the BVH target 300x slower). Prints one line per target: name, executions, seconds, crashes. Crashers land in
# fuzz/artifacts/<target>/; minimize them (cargo fuzz tmin) into fuzz/regressions/<target>/,
# where `cargo test` replays them (crates/cli/tests/fuzz_regressions.rs).
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
runs=${1:-10000000}
secs=${2:-1800}
shift $(( $# > 2 ? 2 : $# ))
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(abc bvh expr gltf keystrokes mdd npy obj pc2 stl style)
fi
command -v cargo-fuzz >/dev/null || cargo install --locked cargo-fuzz
export RUSTC_BOOTSTRAP=1
cargo fuzz build -s none -O -a
mkdir -p logs
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t"
    start=$(date +%s)
    set +e
    cargo fuzz run -s none -O -a "$t" "corpus/$t" "seeds/$t" -- \
        -runs="$runs" -max_total_time="$secs" -max_len="${MAX_LEN:-8192}" -rss_limit_mb=2048 \
        -print_final_stats=1 >"logs/$t.log" 2>&1
    rc=$?
    set -e
    execs=$(grep -a 'stat::number_of_executed_units' "logs/$t.log" | awk '{print $2}' | tail -1)
    crashes=$(ls "artifacts/$t" 2>/dev/null | wc -l)
    echo "$t: ${execs:-?} executions in $(( $(date +%s) - start )) s, exit $rc, $crashes crash file(s)"
done
