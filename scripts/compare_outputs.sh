#!/usr/bin/env bash
# Byte-for-byte comparison of smear outputs between a base revision and the working tree.
#
# usage: scripts/compare_outputs.sh BASE_REV [CHARACTER.glb]
#
# Builds `toonkit` at BASE_REV (in a temporary git worktree) and at the working tree (dev
# profile, sharing this repository's target directory so dependencies are not rebuilt), runs
# every examples/smear/*.toml style (.glb, .usda, and a GIF preview for one) and
# `smear offsets | elongate | multiples | lines` in several formats on the character
# (default: assets/characters/RobotExpressive.glb), and `cmp`s every output.
# Exit status 0 when every output is identical.
set -euo pipefail

base=${1:?usage: scripts/compare_outputs.sh BASE_REV [CHARACTER.glb]}
root=$(cd "$(dirname "$0")/.." && pwd)
input=${2:-$root/assets/characters/RobotExpressive.glb}
input=$(cd "$(dirname "$input")" && pwd)/$(basename "$input")
target=${CARGO_TARGET_DIR:-$root/target}
work=$(mktemp -d)
trap 'git -C "$root" worktree remove --force "$work/src" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT

build() { # SOURCE_DIR DEST_BINARY
    (cd "$1" && CARGO_TARGET_DIR=$target cargo build -q -p toonkit-cli)
    cp "$target/debug/toonkit" "$2"
}

git -C "$root" worktree add -q --detach "$work/src" "$base"
echo "building $base ..."
build "$work/src" "$work/toonkit-base"
echo "building the working tree ..."
build "$root" "$work/toonkit-head"

run_all() { # BINARY OUT_DIR
    local bin=$1 out=$2
    mkdir -p "$out"
    for style in "$root"/examples/smear/*.toml; do
        local name
        name=$(basename "$style" .toml)
        "$bin" smear "$input" --style "$style" -o "$out/style_$name.glb"
        "$bin" smear "$input" --style "$style" -o "$out/style_$name.usda"
    done
    "$bin" smear "$input" --style "$root/examples/smear/fig16_combined.toml" \
        -o "$out/preview.glb" --gif "$out/preview.gif"
    "$bin" smear offsets "$input" -o "$out/offsets.npy"
    "$bin" smear offsets "$input" -o "$out/offsets.glb"
    "$bin" smear offsets "$input" --whole-body --smooth 0 -o "$out/offsets_whole.npy"
    "$bin" smear elongate "$input" -o "$out/elongate.glb"
    "$bin" smear elongate "$input" --preset speed --beta-max 4 -o "$out/elongate_speed.usda"
    "$bin" smear elongate "$input" --preset noise --step 2 -o "$out/elongate_noise.pc2"
    "$bin" smear elongate "$input" --layout morph --weight-expr "clamp01(y)" -o "$out/elongate_morph.glb"
    "$bin" smear multiples "$input" --past 2 --future 1 -o "$out/multiples.glb"
    "$bin" smear multiples "$input" --past 2 --future 0 --overlap 1 -o "$out/multiples.usda"
    "$bin" smear lines "$input" --count 30 --length-max 6 -o "$out/lines.glb"
    "$bin" smear lines "$input" --count 0:10,20:40 --seed 3 --opacity-expr "1 - t" -o "$out/lines.usda"
}

echo "running $base ..."
run_all "$work/toonkit-base" "$work/base" >/dev/null
echo "running the working tree ..."
run_all "$work/toonkit-head" "$work/head" >/dev/null

same=0
differ=0
for f in $(cd "$work/base" && find . -type f | sort); do
    if cmp -s "$work/base/$f" "$work/head/$f"; then
        same=$((same + 1))
    else
        echo "DIFFERS: ${f#./}"
        differ=$((differ + 1))
    fi
done
missing=$(cd "$work/head" && find . -type f | wc -l)
echo "$same identical, $differ different ($(cd "$work/base" && find . -type f | wc -l) files at $base, $missing in the working tree)"
[ "$differ" -eq 0 ]
