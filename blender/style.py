"""The panel's settings as a toonkit style (the CLI's `--style` TOML format) and back."""

import json
import math
import tomllib

SIGN_STAGE = {"PAST": [{"op": "past"}], "FUTURE": [{"op": "future"}], "BOTH": []}


def _weight_stage(s):
    return [{"op": "weight"}] if s.weight_group else []


def _offset_stages(s):
    """Warp, then the δ± restriction (SMEAR Fig. 12, Fig. 11d)."""
    warp = [{"op": "warp", "s": s.warp_s, "p": s.warp_p}] if s.warp else []
    return warp + SIGN_STAGE[s.sign]


def elongation(s):
    """S_E of SMEAR Eq. 10 for the preset."""
    stages = _offset_stages(s)
    if s.preset in ("SPEED", "NOISE"):
        stages.append({"op": "speed"})
    if s.preset == "NOISE":
        stages.append({"op": "noise", "kappa": s.kappa})
    return {"stages": stages + _weight_stage(s) + [{"op": "scale", "by": s.beta_max}]}


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
            "length": {"stages": SIGN_STAGE[s.sign] + [{"op": "speed"}] + _weight_stage(s)
                       + [{"op": "scale", "by": s.line_length}]},
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
    return json.loads(json.dumps(a)) == json.loads(json.dumps(b))


def _apply(style, s):
    live, s.live = s.live, False
    try:
        s.smooth = style.get("offsets", {}).get("smooth", 2)
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
            s.past, s.future = m.get("past", 1), m.get("future", 1)
            s.spacing_mode = "SPACING" if "spacing" in m else "OVERLAP"
            s.spacing = m.get("spacing", 0.5)
            s.overlap = m.get("overlap", 1)
            s.on_twos = m.get("step", 1) == 2
        ln = style.get("lines")
        s.lines = ln is not None
        if ln:
            s.line_count, s.seed, s.line_gap = ln["count"], ln.get("seed", 7), ln.get("gap", 0.0)
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


def _value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        if isinstance(v, float) and not math.isfinite(v):
            raise ValueError(f"style value {v} is not a number TOML can hold")
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + " }"
    raise ValueError(f"style value {v!r} cannot be written as TOML")


def dumps(style):
    """TOML text of a style dict: top-level values first, then one table per section."""
    head = [f"{k} = {_value(v)}" for k, v in style.items() if not isinstance(v, dict)
            or k == "weights"]
    out = ["# toonkit style (Blender extension); `toonkit smear IN --style THIS -o OUT`", *head]
    for k, v in style.items():
        if isinstance(v, dict) and k != "weights":
            out += ["", f"[{k}]", *(f"{kk} = {_value(x)}" for kk, x in v.items())]
    return "\n".join(out) + "\n"


def write(path, style):
    """Writes a style file atomically."""
    import os
    import tempfile

    text = dumps(style)
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
