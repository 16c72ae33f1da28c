#!/usr/bin/env bash
# Blender extension CI (issues 16 and 17), called by .ci/run after python.sh and caches.sh:
# builds the extension zip (python blender/build.py, reusing python.sh's release wheel in
# target/pywheels/ when it is there), then on real Blender through `bpy` from PyPI -- 4.2.0
# LTS (reusing caches.sh's target/caches-venv), 4.5.15 LTS and 5.0.1 (own venvs), each with
# numpy<2 --
# installs the zip with bpy.ops.extensions.package_install_files and runs
# blender/tests/test_smear.py, test_stopmo.py, test_loa.py, test_rigs.py, test_usd.py (USD
# import of the debug toonkit's curves and velocities) and test_presets.py (every named smear
# preset against the debug toonkit CLI) (one PASS/FAIL line per test, non-zero exit on a
# failure).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT="$PWD"
PY=python3.11
command -v "$PY" >/dev/null || PY=python3
PIP=(--disable-pip-version-check --quiet)

wheel=$(ls target/pywheels/toonkit-*-cp311-abi3-*.whl 2>/dev/null | head -n 1 || true)
if [ -n "$wheel" ]; then
    zip=$("$PY" blender/build.py --wheel "$wheel" -o target/blender-dist | tail -n 1)
else
    zip=$("$PY" blender/build.py -o target/blender-dist | tail -n 1)
fi
echo "blender: extension $(basename "$zip"), $(stat -c %s "$zip") bytes"

venv() {  # venv DIR BPY_VERSION
    test -x "$1/bin/python" || "$PY" -m venv "$1"
    "$1/bin/pip" install "${PIP[@]}" "bpy==$2" "numpy<2"
}
status=0
# The benchmark tube (docs/blender.md, "Speed"): the smear test prints bake and restyle times
# and Blender's own floor on it (the build phase's `--all-targets` compiled the example; a
# `cargo run -p` here would resolve other features and rebuild much of the workspace).
tube=target/blender-tube.glb
target/debug/examples/write_tube "$tube" 40
export TOONKIT_TUBE="$ROOT/$tube"
# test_rigs.py compares the bake with the CLI of this tree (the build phase's debug toonkit).
export TOONKIT_CLI="$ROOT/target/debug/toonkit"
for spec in "4.2.0:target/caches-venv" "4.5.15:target/blender-venv-4.5" \
    "5.0.1:target/blender-venv-5.0"; do
    version=${spec%%:*}
    dir=${spec#*:}
    venv "$dir" "$version"
    out="target/blender-out-$version"
    rm -rf "$out" "target/blender-user-$version"
    echo "== Blender $version"
    for t in smear stopmo loa rigs usd presets; do
        rm -rf "target/blender-user-$version"
        BLENDER_USER_RESOURCES="$ROOT/target/blender-user-$version" \
            "$dir/bin/python" "blender/tests/test_$t.py" "$zip" "$out/$t" || status=1
    done
done
exit $status
