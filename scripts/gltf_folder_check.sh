#!/usr/bin/env bash
# The "N files of an engine's example assets" check of issue 24, on any folder of glTF files:
# `toonkit info` on every .glb/.gltf under DIR, one line each: `ok` with the mesh/clip summary,
# or `refused` with toonkit's one-line reason. Fails (exit 1) if toonkit crashed, printed a
# reason of more than one line, or (with --all) refused any file.
#
# usage: scripts/gltf_folder_check.sh DIR [--all]   (TOONKIT=path/to/toonkit to pick a binary)
set -uo pipefail
dir=${1:?usage: scripts/gltf_folder_check.sh DIR [--all]}
all=${2:-}
root=$(cd "$(dirname "$0")/.." && pwd)
tk=${TOONKIT:-$root/target/debug/toonkit}
[ -x "$tk" ] || (cd "$root" && cargo build --quiet --workspace --bins) || exit 1
ok=0 refused=0 bad=0
while IFS= read -r -d '' f; do
    rel=${f#"$dir"/}
    out=$("$tk" info "$f" 2>&1)
    rc=$?
    if [ $rc -eq 0 ]; then
        ok=$((ok + 1))
        summary=$(echo "$out" | grep -E '^  (meshes|clips):' | sed 's/^  //' | paste -sd ';' -)
        printf 'ok       %s  %s\n' "$rel" "$summary"
    elif [ $rc -eq 2 ] && [ "$(echo "$out" | wc -l)" -eq 1 ]; then
        refused=$((refused + 1))
        printf 'refused  %s  %s\n' "$rel" "${out#toonkit: error: }"
    else
        bad=$((bad + 1))
        printf 'FAILED   %s  exit %s:\n%s\n' "$rel" "$rc" "$out"
    fi
done < <(find "$dir" -type f \( -name '*.glb' -o -name '*.gltf' \) -print0 | sort -z)
echo "$ok loaded, $refused refused in one line, $bad failed"
[ $bad -eq 0 ] && { [ "$all" != --all ] || [ $refused -eq 0 ]; }
