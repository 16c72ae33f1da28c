#!/usr/bin/env bash
# Runs the README's `toonkit stopmo` examples with two toonkit binaries and shows that every
# output file is byte-identical (report/summary JSON compared without timing and memory
# fields). `reconstruction.glb` files whose bytes differ (the pieces as morph targets instead
# of one target per frame) are compared as animations: both are converted to point caches by
# the new binary and every position must agree within the glTF quantization (1e-4 of the
# bounding-box diagonal).
#
#   scripts/stopmo_outputs_identical.sh OLD_TOONKIT NEW_TOONKIT [FACE.glb]
#
# The face is sampled at 2 fps (120 frames) to keep every run short. JSON files are compared
# as data without timing fields (keys ending in "seconds") and with the two output roots
# replaced by one name (reports name their input and output paths).
set -euo pipefail
old=$1
new=$2
here=$(cd "$(dirname "$0")/.." && pwd)
face=${3:-$here/assets/face/ict-face-talk.glb}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
seeds=(--part upper=point:0,10,13 --part lower=point:0,-14,10)

examples() { # $1 = binary, $2 = output root
    local t=$1 o=$2
    mkdir -p "$o"
    "$t" --json stopmo segment "$face" -o "$o/parts.glb" --fps 2 "${seeds[@]}" \
        --report "$o/seg.json" --render "$o/seg.png" >"$o/segment.stdout.json"
    "$t" --json stopmo segment "$face" -o "$o/parts_flip.glb" --fps 2 --auto-parts 3 \
        --gamma 100 --smooth-iters 4 --layout flipbook >"$o/segment_auto.stdout.json"
    "$t" --json stopmo library "$o/parts.glb" -o "$o/lib" --fps 2 --pieces upper=4,lower=6 \
        --restarts 2 --seed 1 --report "$o/lib_report.json" >"$o/library.stdout.json"
    "$t" --json stopmo library "$face" -o "$o/lib_curve" --fps 2 --max-error 0.25 \
        --restarts 2 --seed 3 >"$o/library_curve.stdout.json"
    "$t" --json stopmo library "$face" -o "$o/lib3" --fps 2 --pieces 3 --restarts 2 \
        --method uniform >"$o/library3.stdout.json"
    "$t" --json stopmo library "$face" -o "$o/lib_fixed" --fps 2 --pieces 5 --restarts 2 \
        --fixed "$o/lib3/pieces" --method kmeans --cuts 0,60 >"$o/library_fixed.stdout.json"
    "$t" --json stopmo run "$face" -o "$o/run" --fps 2 "${seeds[@]}" --pieces 3 --restarts 1 \
        --plugs --render --report "$o/run_report.json" >"$o/run.stdout.json"
}

examples "$old" "$work/old"
examples "$new" "$work/new"

strip_timing='
import json, sys
def strip(v, root):
    if isinstance(v, dict):
        return {
            k: strip(x, root)
            for k, x in v.items()
            if not (k.endswith("seconds") or k == "peak_memory_mib")
        }
    if isinstance(v, list):
        return [strip(x, root) for x in v]
    if isinstance(v, str):
        return v.replace(root, "OUT")
    return v
a, b = (strip(json.load(open(p)), r) for p, r in zip(sys.argv[1:3], sys.argv[3:5]))
sys.exit(0 if a == b else 1)
'
same_frames='
import struct, sys
def frames(p):
    b = open(p, "rb").read()
    n = struct.unpack_from("<i", b, 16)[0] * struct.unpack_from("<i", b, 28)[0] * 3
    return struct.unpack_from("<%df" % n, b, 32)
a, b = frames(sys.argv[1]), frames(sys.argv[2])
if len(a) != len(b):
    sys.exit(1)
span = max(max(a[k::3]) - min(a[k::3]) for k in range(3))
worst = max(abs(x - y) for x, y in zip(a, b))
print("  largest position difference %.3g (%.2g of the extent)" % (worst, worst / span))
sys.exit(0 if worst <= 1e-4 * span * 3 else 1)
'
status=0
count=0
while IFS= read -r -d '' f; do
    rel=${f#"$work/old/"}
    g=$work/new/$rel
    count=$((count + 1))
    if [[ ! -e $g ]]; then
        echo "MISSING in new: $rel"; status=1; continue
    fi
    if [[ $rel == *.json ]] && ! cmp -s "$f" "$g"; then
        if python3 -c "$strip_timing" "$f" "$g" "$work/old" "$work/new"; then
            echo "same (timing aside): $rel"
        else
            echo "DIFFERENT: $rel"; status=1
        fi
    elif [[ $rel == *reconstruction.glb ]] && ! cmp -s "$f" "$g"; then
        "$new" convert "$f" "$work/a.pc2" >/dev/null
        "$new" convert "$g" "$work/b.pc2" >/dev/null
        if python3 -c "$same_frames" "$work/a.pc2" "$work/b.pc2"; then
            echo "same frames (encoding differs): $rel"
        else
            echo "DIFFERENT: $rel"; status=1
        fi
        rm -f "$work"/a.pc2 "$work"/a.obj "$work"/b.pc2 "$work"/b.obj
    elif cmp -s "$f" "$g"; then
        echo "identical: $rel"
    else
        echo "DIFFERENT: $rel"; status=1
    fi
done < <(find "$work/old" -type f -print0 | sort -z)
while IFS= read -r -d '' g; do
    rel=${g#"$work/new/"}
    [[ -e $work/old/$rel ]] || echo "new file: $rel"
done < <(find "$work/new" -type f -print0 | sort -z)
echo "$count files compared"
exit $status
