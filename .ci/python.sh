#!/usr/bin/env bash
# Python module CI (issue 15): builds the toonkit wheel with maturin as the PEP 517 backend,
# checks it is one cp311-abi3 wheel under 15 MB, installs `./crates/python` into a fresh venv
# (target/pyvenv) with pytest and numpy<2 (Blender's numpy), and runs crates/python/tests
# against the CLI built from the same tree. Needs only Rust, Python >= 3.11 and PyPI.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TERM_COLOR=never
PY=${PYTHON:-python3}
VENV=target/pyvenv
WHEELS=target/pywheels
MAX_BYTES=$((15 * 1024 * 1024))

rm -rf "$VENV" "$WHEELS"
"$PY" -m venv "$VENV"
PIP=("$VENV/bin/pip" --disable-pip-version-check --quiet)

# The wheel, built as `pip install` builds it (maturin as the PEP 517 backend, stripped) but in
# the dev profile, whose dependencies the test build already compiled: users' `pip install`
# builds the release-like `wheel` profile, a second full compile of every dependency (~9 of a
# cold CI's minutes) that would test the same code. TOONKIT_WHEEL_PROFILE=wheel checks the users' build.
export MATURIN_PEP517_ARGS="--profile ${TOONKIT_WHEEL_PROFILE:-dev}"
"${PIP[@]}" wheel --no-deps --wheel-dir "$WHEELS" ./crates/python
wheel=$(ls "$WHEELS"/toonkit-*.whl)
name=$(basename "$wheel")
size=$(stat -c %s "$wheel")
echo "python: wheel $name, $size bytes"
case "$name" in
    *-cp311-abi3-*) ;;
    *) echo "python: expected one cp311-abi3 wheel, got $name" >&2; exit 1 ;;
esac
if [ "$size" -ge "$MAX_BYTES" ]; then
    echo "python: wheel is $size bytes, limit $MAX_BYTES" >&2
    exit 1
fi

# The README's install command (cargo reuses the build above).
"${PIP[@]}" install ./crates/python pytest "numpy<2"
(cd /tmp && "$OLDPWD/$VENV/bin/python" -c "import toonkit; print('python: toonkit', toonkit.__version__, 'from', toonkit.__file__)")

# The CLI the tests compare against, from the same tree.
# The binaries `cargo test --workspace` built (`cargo build` would resolve other features
# without the dev-dependencies and rebuild much of the workspace).
cargo test --quiet --workspace --no-run
TOONKIT_CLI="$PWD/target/debug/toonkit" "$VENV/bin/python" -m pytest -q -p no:cacheprovider crates/python/tests
