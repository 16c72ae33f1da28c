"""Builds the Blender extension zip: `python blender/build.py [--wheel WHEEL] [-o DIR]`.

Builds the toonkit cp311-abi3 wheel with pip (maturin, `wheel` profile) unless `--wheel` names one,
then writes `dist/toonkit-<version>-<platform>.zip` with the extension's Python files, the
manifest (its `wheels` and `platforms` set to that wheel) and the wheel under `wheels/`.
Install it with Edit ▸ Preferences ▸ Get Extensions ▸ Install from Disk, or headless with
`bpy.ops.extensions.package_install_files(filepath=ZIP, repo="user_default")`.
No pip at run time: Blender installs the bundled wheel; numpy is Blender's own.
"""

import argparse
import pathlib
import re
import subprocess
import sys
import tempfile
import tomllib
import zipfile

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
SKIP = {"build.py"}  # the extension is every other .py file beside the manifest


def platform_of(wheel: pathlib.Path) -> str:
    """Blender's platform name of a wheel's platform tag (`linux_x86_64` -> `linux-x64`)."""
    tag = wheel.stem.rsplit("-", 1)[-1]
    system = next((name for key, name in (("linux", "linux"), ("win", "windows"),
                                           ("macosx", "macos")) if key in tag), None)
    arch = ("x64" if "x86_64" in tag or "amd64" in tag
            else "arm64" if "arm64" in tag or "aarch64" in tag else None)
    if system is None or arch is None:
        sys.exit(f"build.py: {wheel.name}: unknown platform tag {tag!r}")
    return f"{system}-{arch}"


def build_wheel(out: pathlib.Path) -> pathlib.Path:
    out.mkdir(parents=True, exist_ok=True)
    for old in out.glob("toonkit-*.whl"):
        old.unlink()
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--wheel-dir", str(out),
                    str(ROOT / "crates" / "python")], check=True)
    return only_wheel(out)


def only_wheel(folder: pathlib.Path) -> pathlib.Path:
    wheels = sorted(folder.glob("toonkit-*-cp311-abi3-*.whl"))
    if len(wheels) != 1:
        sys.exit(f"build.py: expected one toonkit cp311-abi3 wheel in {folder}, found {len(wheels)}")
    return wheels[0]


def manifest_text(wheel: pathlib.Path, platform: str) -> str:
    text = (HERE / "blender_manifest.toml").read_text(encoding="utf-8")
    text = re.sub(r'(?m)^platforms = .*$', f'platforms = ["{platform}"]', text)
    text = re.sub(r'(?m)^wheels = .*$', f'wheels = ["./wheels/{wheel.name}"]', text)
    tomllib.loads(text)  # still valid
    return text


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wheel", type=pathlib.Path, help="use this toonkit wheel (else build one)")
    ap.add_argument("-o", "--out", type=pathlib.Path, default=ROOT / "dist")
    args = ap.parse_args()
    wheel = args.wheel.resolve() if args.wheel else build_wheel(ROOT / "target" / "blender-wheel")
    if not wheel.is_file():
        sys.exit(f"build.py: {wheel}: no such wheel")
    if "-cp311-abi3-" not in wheel.name:
        sys.exit(f"build.py: {wheel.name}: Blender needs the cp311-abi3 wheel")
    version = tomllib.loads((HERE / "blender_manifest.toml").read_text())["version"]
    platform = platform_of(wheel)
    args.out.mkdir(parents=True, exist_ok=True)
    target = args.out / f"toonkit-{version}-{platform}.zip"
    with tempfile.NamedTemporaryFile(dir=args.out, suffix=".zip", delete=False) as tmp:
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("blender_manifest.toml", manifest_text(wheel, platform))
            for path in sorted(HERE.glob("*.py")):
                if path.name not in SKIP:
                    z.write(path, path.name)
            z.write(wheel, f"wheels/{wheel.name}")
    pathlib.Path(tmp.name).replace(target)
    print(target)


if __name__ == "__main__":
    main()
