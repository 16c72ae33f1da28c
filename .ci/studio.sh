#!/usr/bin/env bash
# Browser tests of `toonkit studio` (issue #18): Debian's chromium headless driven by
# playwright-core (npm) against the studio on the bundled robot and face. Installs what it
# needs; screenshots go to target/studio-shots/, latency figures to the output.
set -euo pipefail
cd "$(dirname "$0")/.."

command -v chromium >/dev/null || { apt-get update -qq && apt-get install -y -qq chromium; }
command -v node >/dev/null || { apt-get update -qq && apt-get install -y -qq nodejs npm; }
npm ci --prefix .ci/studio --no-audit --no-fund --loglevel=error

# The binaries `cargo test --workspace` built (`cargo build` would resolve other features
# without the dev-dependencies and rebuild much of the workspace).
cargo test --quiet --workspace --no-run
# The binary alone, as `cargo install` leaves it: copied into an empty folder and run from
# there (the page and three.js are embedded; nothing of the checkout is reachable by cwd).
ALONE=$(mktemp -d)
cp target/debug/toonkit "$ALONE/"
PORT=${STUDIO_PORT:-18765}
OUT=$PWD/target/studio-out
rm -rf "$OUT"
ROOT=$PWD
(cd "$ALONE" && exec ./toonkit studio "$ROOT/assets/characters/RobotExpressive.glb" \
    "$ROOT/assets/face/ict-face-talk.glb" --no-open --port "$PORT" --out "$OUT") \
    >target/studio-server.log 2>&1 &
SERVER=$!
trap 'kill $SERVER 2>/dev/null || true; rm -rf "$ALONE"' EXIT
for _ in $(seq 1 100); do
    curl -sf "http://127.0.0.1:$PORT/api/info" >/dev/null && break
    sleep 0.2
done
STUDIO_PID=$SERVER node .ci/studio/test.mjs "http://127.0.0.1:$PORT/" target/studio-shots
