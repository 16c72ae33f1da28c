#!/usr/bin/env bash
# CI for issue 24 (reading the files animators have), called by .ci/run after the Rust tests:
# 1. Blender 4.2 (bpy, headless; the venv .ci/caches.sh makes) exports the bundled characters
#    (RobotExpressive, CesiumMan, AnimatedMorphSphere) as plain glTF, glTF with a light
#    (KHR_lights_punctual) and binary FBX with baked animation and shape keys (.ci/io_export.py);
#    Assimp (Debian's assimp-utils) writes ASCII FBX 7.5 of two of them and reads it back as OBJ;
# 2. glTF-Transform (npm @gltf-transform/cli) compresses each plain glTF with Draco (the bpy
#    wheel has no Draco library), gltfpack (npm) with meshopt + quantization;
# 3. the Rust test crates/io/tests/exporters.rs reads every file with tkio::load and compares
#    clips (frame counts) and positions with the plain glTF (Draco ≤ 1e-3 of the diagonal,
#    gltfpack ≤ 1e-2, lights and FBX ≤ 1e-5);
# 4. the Khronos validator checks the (default, quantized) flipbook `toonkit smear --style`
#    writes of the robot's Dance clip (Fig. 16 style); its size is printed next to the float
#    one (`--no-quantize`).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT="$PWD"
VENV="$ROOT/target/caches-venv"
PY=python3.11
command -v "$PY" >/dev/null || PY=python3
test -x "$VENV/bin/python" || "$PY" -m venv "$VENV"
"$VENV/bin/pip" install --quiet --disable-pip-version-check "bpy==4.2.0" "numpy<2"

OUT="$ROOT/target/io-exports"
rm -rf "$OUT"
mkdir -p "$OUT"
echo "== Blender exports"
"$VENV/bin/python" .ci/io_export.py "$OUT" assets/characters/RobotExpressive.glb \
    assets/characters/CesiumMan.glb assets/morph/AnimatedMorphSphere/AnimatedMorphSphere.gltf \
    > "$OUT/blender.log" 2>&1 || { tail -20 "$OUT/blender.log"; exit 1; }
grep '^exported' "$OUT/blender.log"

echo "== glTF-Transform (Draco), gltfpack (meshopt + quantization)"
NPM="$ROOT/target/io-npm"
mkdir -p "$NPM"
cp .ci/io/package.json .ci/io/package-lock.json "$NPM/"
(cd "$NPM" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
BIN="$NPM/node_modules/.bin"
for name in RobotExpressive CesiumMan AnimatedMorphSphere; do
    "$BIN/gltf-transform" draco "$OUT/$name.glb" "$OUT/${name}_draco.glb" | tail -1
    "$BIN/gltfpack" -i "$OUT/$name.glb" -o "$OUT/${name}_gltfpack.glb" -c -kn -km | tail -1
done

echo "== Assimp (Debian's assimp-utils): ASCII FBX 7.5, and Assimp's own reading of it as OBJ"
command -v assimp >/dev/null || { apt-get update -qq && apt-get install -y -qq assimp-utils; }
for src in assets/characters/CesiumMan.glb assets/morph/AnimatedMorphSphere/AnimatedMorphSphere.gltf; do
    name=$(basename "${src%.*}")
    assimp export "$src" "$OUT/${name}_ascii.fbx" -ffbxa >/dev/null
    assimp export "$OUT/${name}_ascii.fbx" "$OUT/${name}_ascii.obj" >/dev/null
    echo "exported ${name}_ascii.fbx ($(head -c 24 "$OUT/${name}_ascii.fbx" | head -1))"
done

echo "== toonkit reads them like the plain glTF"
TOONKIT_IO_EXPORTS="$OUT" cargo test --quiet --workspace --test exporters -- --nocapture

echo "== the Fig. 16 style on the robot's Dance clip: quantized (default) and float"
cargo test --quiet --workspace --no-run
TK="$ROOT/target/debug/toonkit"
"$TK" smear assets/characters/RobotExpressive.glb --clip Dance \
    --style examples/smear/fig16_combined.toml -o "$OUT/dance_fig16.glb"
"$TK" --no-quantize smear assets/characters/RobotExpressive.glb --clip Dance \
    --style examples/smear/fig16_combined.toml -o "$OUT/dance_fig16_float.glb"
ls -l "$OUT/dance_fig16.glb" "$OUT/dance_fig16_float.glb" | awk '{print $5, $9}'
"$TK" info "$OUT/dance_fig16.glb" | tail -3
node .ci/validator/validate.mjs "$OUT/dance_fig16.glb"
