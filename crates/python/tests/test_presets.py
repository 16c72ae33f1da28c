"""One definition of the smear presets, defaults and ranges for every front end (the smear
crate's `ElongatePreset` and `PARAMETERS`): the CLI's `--preset` flags, the Python module, the
style files the module writes (as the Blender panel saves them) and the studio's API (a
`toonkit studio` server, asked over HTTP as the page asks) give the same bytes, for every named
preset on two characters. All four share the core's sampling of the file, which
test_gltf_spec.py checks against an independent reading of the glTF. Blender's side is
blender/tests/test_presets.py: Blender agrees on the robot only when its glTF importer places the
bone-parented parts as the file does (Bone Dir: Temperance; with the default the parts are
0.57-0.65 units off, docs/blender.md)."""

from __future__ import annotations

import inspect
import re

import numpy as np
import pytest

import toonkit

from conftest import STUDIO_FILES, asset, read_pc2, run_cli, studio_post, studio_unpack

CHARACTERS = {
    "robot": ("characters/RobotExpressive.glb", "Wave"),
    "cesium": ("characters/CesiumMan.glb", None),
}
PRESETS = [p["name"] for p in toonkit.smear.presets()]


def _input(name):
    path, clip = CHARACTERS[name]
    return [asset(path), *(["--clip", clip] if clip else [])]


@pytest.fixture(scope="module", params=sorted(CHARACTERS))
def character(request):
    path, clip = CHARACTERS[request.param]
    scene = toonkit.load(asset(path), clip=clip)
    return request.param, scene, toonkit.smear.prepare(scene)


@pytest.mark.parametrize("preset", PRESETS)
def test_every_preset_gives_the_clis_bytes(character, preset, studio, tmp_path):
    name, scene, prepared = character
    cli = tmp_path / "cli.pc2"
    run_cli("smear", "elongate", *_input(name), "--preset", preset, "--beta-max", "4",
            "--kappa", "12", "-o", cli)
    style = {"elongate": {"function": toonkit.smear.preset_function(preset, 4, 12)}}
    look = toonkit.smear.stylize(prepared, style)
    np.testing.assert_array_equal(look.elongated, read_pc2(cli))  # bit for bit
    # The style file the module writes (the Blender panel's "Save style") through `--style`.
    toonkit.smear.save_style(tmp_path / "style.toml", style)
    styled = tmp_path / "styled.glb"
    run_cli("smear", *_input(name), "--style", tmp_path / "style.toml", "-o", styled)
    assert look.save(tmp_path / "py.glb").read_bytes() == styled.read_bytes()
    # The studio's API: the page's request (stylize) and its export.
    url, out = studio
    request = {"file": STUDIO_FILES.index(CHARACTERS[name][0]), "clip": CHARACTERS[name][1] or "",
               "style": style}
    _, buffers = studio_unpack(studio_post(url, "/api/smear/stylize", request))
    np.testing.assert_array_equal(buffers["body"].reshape(look.elongated.shape), look.elongated)
    studio_post(url, "/api/smear/export", {**request, "name": f"{name}-{preset}.glb"})
    assert (out / f"{name}-{preset}.glb").read_bytes() == styled.read_bytes()
    diag = float(np.linalg.norm(np.ptp(scene.positions[0], axis=0)))
    assert np.abs(look.elongated - scene.positions).max() > 1e-3 * diag  # it did elongate


def test_cli_defaults_are_the_parameter_table(character, tmp_path):
    name, _, prepared = character
    cli = tmp_path / "cli.pc2"
    run_cli("smear", "elongate", *_input(name), "-o", cli)
    default = next(p for p in toonkit.smear.presets() if p["default"])
    look = toonkit.smear.stylize(prepared, {"elongate": {"function": default["function"]}})
    np.testing.assert_array_equal(look.elongated, read_pc2(cli))
    assert default["function"] == toonkit.smear.preset_function(default["name"])


def test_noise_preset_trails_as_in_fig11d():
    stages = toonkit.smear.preset_function("noise", 10, 18)["stages"]
    assert [s["op"] for s in stages] == ["past", "speed", "noise", "scale"]
    unsigned = toonkit.smear.preset_function("noise", 10, 18, signed=False)["stages"]
    assert unsigned == stages[1:]
    with pytest.raises(ValueError, match="not a smear preset"):
        toonkit.smear.preset_function("wobbly")


def test_parameter_table_is_what_the_front_ends_default_to():
    table = toonkit.smear.parameters()
    for p in table.values():
        assert p["min"] <= p["default"] <= p["max"], p
        assert p["doc"], p
    # The module's own keyword defaults.
    for f in (toonkit.smear.offsets, toonkit.smear.prepare):
        assert inspect.signature(f).parameters["smooth"].default == table["smooth"]["default"]
    # The CLI's flag defaults.
    help_lines = run_cli("smear", "elongate", "--help").stdout.splitlines()

    def shown(flag):  # the help of one flag: its line up to the next flag's line (a flag
        # named inside a help text is on an indented continuation line, not a flag's line)
        def is_flag_line(line):
            return re.match(r"^ {1,6}(-\w, )?--[\w-]+", line) is not None
        start = next(i for i, line in enumerate(help_lines)
                     if is_flag_line(line) and re.search(rf"(^|[ ,]){flag}\b", line))
        end = next((i for i in range(start + 1, len(help_lines)) if is_flag_line(help_lines[i])),
                   len(help_lines))
        return " ".join(" ".join(help_lines[start:end]).split())

    for flag, key in (("--beta-max", "beta_max"), ("--kappa", "kappa"), ("--smooth", "smooth")):
        assert f"[default: {table[key]['default']:g}]" in shown(flag), shown(flag)
    default = next(p["name"] for p in toonkit.smear.presets() if p["default"])
    assert f"[default: {default}]" in shown("--preset"), shown("--preset")


def test_style_files_are_written_by_the_core(tmp_path):
    style = {"elongate": {"function": toonkit.smear.preset_function("speed", 2.5)},
             "lines": {"count": 12}}
    text = toonkit.smear.style_toml(style)
    assert "[elongate" in text and "count = 12" in text
    path = toonkit.smear.save_style(tmp_path / "s.toml", style)
    assert open(path, encoding="utf-8").read() == text
    with pytest.raises(ValueError, match="style"):
        toonkit.smear.style_toml({"lines": {"count": -3}})
    with pytest.raises(ValueError):
        toonkit.smear.style_toml({"elongate": {"wobble": 1}})
