"""The panel's settings as a toonkit style (the CLI's `--style` TOML format) and back.

The presets' stage chains come from the smear crate (`toonkit.smear.preset_function`) and style
files are written by it (`toonkit.smear.save_style`): the panel only picks presets and values.
"""

import json
import tomllib

from toonkit import smear as _core

from .settings import PARAMS

SIGN_STAGE = {"PAST": [{"op": "past"}], "FUTURE": [{"op": "future"}], "BOTH": [], "PRESET": []}


def _weight_stage(s):
    return [{"op": "weight"}] if s.weight_group else []


def elongation(s):
    """S_E of SMEAR Eq. 10: the crate's preset chain, after the warp (SMEAR Fig. 12), with the
    panel's δ± restriction in place of the preset's own unless "Preset" is chosen, times ω
    last (as the CLI's `--weight-group` appends it)."""
    warp = [{"op": "warp", "s": s.warp_s, "p": s.warp_p}] if s.warp else []
    own = s.sign == "PRESET"
    chain = _core.preset_function(s.preset.lower(), s.beta_max, s.kappa, signed=own)["stages"]
    return {"stages": warp + SIGN_STAGE[s.sign] + chain + _weight_stage(s)}


def weights(s, bones):
    """A bone name → its skin weights (and its children's); else a painted vertex group."""
    if not s.weight_group:
        return None
    if s.weight_group in bones:
        return {"group": [s.weight_group]}
    return {"attribute": s.weight_group}


def from_settings(s, bones=()):
    """The style dict of `scene.toonkit_smear` (`bones`: the baked skeleton's joint names)."""
    if s.preset == "CUSTOM":
        return json.loads(s.custom_style or "{}")
    step = 2 if s.on_twos else 1
    style = {"offsets": {"smooth": s.smooth}}
    w = weights(s, bones)
    if w:
        style["weights"] = w
    if s.elongate:
        style["elongate"] = {"step": step, "function": elongation(s)}
    if s.multiples:
        m = {"past": s.past, "future": s.future, "step": step}
        if s.spacing_mode == "SPACING":
            m["spacing"] = s.spacing
        else:
            m["overlap"] = s.overlap
        if s.weight_group:
            m["opacity"] = {"stages": [{"op": "weight"},
                                       {"op": "multiples", "m_max": max(s.past, s.future, 1)}]}
        style["multiples"] = m
    if s.lines:
        lines = {
            "count": s.line_count, "seed": s.seed, "gap": s.line_gap, "step": step,
            "past_only": s.sign == "PAST",
            # S_L(δ; τ_max) = τ_max·δ (SMEAR Eq. 13), as the CLI's `smear lines` builds it.
            "length": {"stages": SIGN_STAGE[s.sign] + [{"op": "scale", "by": s.line_length}]
                       + _weight_stage(s)},
        }
        if s.line_thickness > 0:
            lines["thickness"] = {"stages": [{"op": "set", "value": s.line_thickness}]}
        style["lines"] = lines
    return style


def to_settings(style, s):
    """Sets the panel from a style; returns False (and selects the "From file" preset, the
    style kept as written) when the style has more than the panel shows."""
    try:
        _apply(style, s)
        if _same(from_settings(s, ()), style, s):
            return True
    except (KeyError, TypeError, ValueError, IndexError):
        pass
    s.custom_style = json.dumps(style)
    s.preset = "CUSTOM"
    return False


def _same(a, b, s):
    # A bone weight group reads back as an attribute without the skeleton: compare loosely.
    if s.weight_group and "weights" in b:
        a = dict(a, weights=b["weights"])
    # Compared as the crate writes them: a file the crate wrote spells out its defaults.
    return _core.style_toml(a) == _core.style_toml(b)


def _whole(v):
    """A count read from a style; a keyframed or fractional one does not fit the panel."""
    if isinstance(v, bool) or not isinstance(v, (int, float)) or v != int(v):
        raise ValueError(f"{v!r} is not a whole number")
    return int(v)


def _apply(style, s):
    live, s.live = s.live, False
    try:
        s.smooth = style.get("offsets", {}).get("smooth", PARAMS["smooth"]["default"])
        w = style.get("weights")
        s.weight_group = (w.get("group") or [w.get("attribute")])[0] if w else ""
        e = style.get("elongate")
        s.elongate = e is not None
        if e:
            s.on_twos = e.get("step", 1) == 2
            ops = [st["op"] for st in e["function"]["stages"]]
            for st in e["function"]["stages"]:
                if st["op"] == "scale":
                    s.beta_max = st["by"]
                elif st["op"] == "noise":
                    s.kappa = st["kappa"]
                elif st["op"] == "warp":
                    s.warp_s, s.warp_p = st["s"], st["p"]
            s.warp = "warp" in ops
            s.sign = "PAST" if "past" in ops else "FUTURE" if "future" in ops else "BOTH"
            s.preset = "NOISE" if "noise" in ops else "SPEED" if "speed" in ops else "LINEAR"
        m = style.get("multiples")
        s.multiples = m is not None
        if m:
            # Counts are numbers in a style (the crate writes 2.0): whole ones fit the panel.
            s.past = _whole(m.get("past", PARAMS["past"]["default"]))
            s.future = _whole(m.get("future", PARAMS["future"]["default"]))
            s.spacing_mode = "SPACING" if "spacing" in m else "OVERLAP"
            s.spacing = m.get("spacing", PARAMS["spacing"]["default"])
            s.overlap = _whole(m.get("overlap", 1))
            s.on_twos = m.get("step", 1) == 2
        ln = style.get("lines")
        s.lines = ln is not None
        if ln:
            s.line_count = _whole(ln.get("count", PARAMS["count"]["default"]))
            s.line_gap = ln.get("gap", 0.0)
            s.seed = ln.get("seed", PARAMS["seed"]["default"])
            s.on_twos = ln.get("step", 1) == 2
            s.line_length = [st for st in ln["length"]["stages"] if st["op"] == "scale"][0]["by"]
            th = ln.get("thickness")
            s.line_thickness = th["stages"][0]["value"] if th else 0.0
    finally:
        s.live = live


def read(path):
    """A style file as a dict (the TOML the CLI reads)."""
    with open(path, "rb") as f:
        return tomllib.load(f)


def write(path, style):
    """Writes a style file (checked, atomically) through the smear crate."""
    import toonkit

    try:
        _core.save_style(path, style)
    except toonkit.ToonkitError as e:  # a file error: the operator reports it as one line
        raise OSError(str(e)) from e
