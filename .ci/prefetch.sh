#!/usr/bin/env bash
# Started in the background by .ci/run before the Rust builds: installs the outside tools the
# later phases use — Debian's chromium (studio) and assimp-utils (io), the Python venvs with
# bpy 4.2 / 4.5.15 / 5.0.1, openjd-cli, usd-core and pymeshlab, the npm packages — while cargo
# compiles, so ~2 GB of downloads overlap the build instead of following it. The requirement lists are
# the phases' own (each phase still runs its install, a no-op when this got there first), so a
# failure here costs time, never correctness; .ci/run prints this log before the first phase
# that needs any of it.
set -uo pipefail
cd "$(dirname "$0")/.."
PY=python3.11
command -v "$PY" >/dev/null || PY=python3
status=0

step() {  # step NAME COMMAND...: runs it, says how long it took, remembers a failure
    local name=$1 start=$SECONDS
    shift
    if "$@"; then
        echo "prefetch: $name ($((SECONDS - start)) s)"
    else
        echo "prefetch: $name FAILED after $((SECONDS - start)) s (the phase installs it again)"
        status=1
    fi
}
venv() {  # venv DIR REQUIREMENT...
    local dir=$1
    shift
    { test -x "$dir/bin/python" || "$PY" -m venv "$dir"; } &&
        "$dir/bin/pip" install --quiet --disable-pip-version-check "$@"
}
apt_tools() {
    local missing=()
    command -v chromium >/dev/null || missing+=(chromium)
    command -v assimp >/dev/null || missing+=(assimp-utils)
    [ ${#missing[@]} -eq 0 ] || { apt-get update -qq && apt-get install -y -qq "${missing[@]}"; }
}

mkdir -p target
step "apt chromium assimp-utils" apt_tools
# The same lists as .ci/caches.sh, .ci/blender.sh and .ci/meshlab.sh.
step "bpy 4.2.0 venv" venv target/caches-venv "bpy==4.2.0" "numpy<2" "openjd-cli" "usd-core==26.11"
step "bpy 4.5.15 venv" venv target/blender-venv-4.5 "bpy==4.5.15" "numpy<2"
step "bpy 5.0.1 venv" venv target/blender-venv-5.0 "bpy==5.0.1" "numpy<2"
step "pymeshlab venv" venv target/meshlab-venv pymeshlab
step "npm studio tests" npm ci --prefix .ci/studio --no-audit --no-fund --loglevel=error
mkdir -p target/io-npm && cp .ci/io/package.json .ci/io/package-lock.json target/io-npm/
step "npm io" npm ci --prefix target/io-npm --no-audit --no-fund --loglevel=error
exit $status
