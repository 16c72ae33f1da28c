#!/usr/bin/env python3
"""Renders docs/loa_parameters.png: one keystroke sequence (default examples/loa/whip.json) at
three dampings × three stiffnesses, as `toonkit loa line`'s own onion-skin SVGs, with each
interval's arrival, overshoot and damping used (its JSON summary) and the progress of the
angles along each key-to-key change (read from its JSON frames).

usage: scripts/loa_parameters.py TOONKIT [KEYS.json] [OUT.png]

Needs chromium on PATH (headless screenshot of the composed page). Only runs the CLI and
composes its outputs: no timing is computed here.
"""

import html
import json
import os
import subprocess
import sys
import tempfile

STIFFNESS = [5, 25, 100]
DAMPING = [0.05, 0.2, 0.5]
SETTLE = 20
COLOURS = ["#d62728", "#2ca02c", "#1f77b4"]


def run(toonkit, keys, k, z, folder):
    data = json.load(open(keys))
    for key in data["keystrokes"]:
        key["stiffness"], key["damping"] = k, z
    src = os.path.join(folder, f"keys_{k}_{z}.json")
    json.dump(data, open(src, "w"))
    out = {}
    for ext in ("svg", "json"):
        dst = os.path.join(folder, f"line_{k}_{z}.{ext}")
        rep = subprocess.run(
            [toonkit, "--json", "loa", "line", src, "-o", dst, "--settle", str(SETTLE)],
            check=True, capture_output=True, text=True)
        out["summary"] = json.loads(rep.stdout)
        out[ext] = open(dst).read()
    return out


def progress(frames_json):
    """Per frame: the key index plus the progress of the angles along the change of the
    interval the frame is in (the settle measured against the last change)."""
    a = json.loads(frames_json)
    keys = a["keystroke_frames"]
    by = {f["frame"]: f["angles"] for f in a["frames"]}
    out = []
    for f in sorted(by):
        i = max(j for j in range(len(keys) - 1) if keys[j] <= f) if f < keys[-1] else len(keys) - 2
        g0, g1, g = by[keys[i]], by[keys[i + 1]], by[f]
        num = sum((x - p) * (q - p) for x, p, q in zip(g, g0, g1))
        den = sum((q - p) ** 2 for p, q in zip(g0, g1)) or 1.0
        out.append((f, i + num / den))
    return out, keys


def plot(title, curves, keys, labels):
    w, h, x0, y0 = 290, 150, 28, 130
    last = max(f for c in curves for f, _ in c)
    top = max(v for c in curves for _, v in c) + 0.2
    sx = (w - x0 - 10) / last
    sy = (y0 - 20) / top
    parts = [f'<text x="{x0}" y="12" font-size="12">{html.escape(title)}</text>']
    for j in range(len(keys)):
        y = y0 - j * sy
        parts.append(f'<line x1="{x0}" x2="{w - 10}" y1="{y}" y2="{y}" stroke="#ddd"/>'
                     f'<text x="0" y="{y + 4}" font-size="9">key {j}</text>')
    for f in keys:
        x = x0 + f * sx
        parts.append(f'<line x1="{x}" x2="{x}" y1="20" y2="{y0}" stroke="#ccc"/>'
                     f'<text x="{x - 4}" y="{y0 + 12}" font-size="9">{f}</text>')
    for c, colour, label, n in zip(curves, COLOURS, labels, range(3)):
        pts = " ".join(f"{x0 + f * sx:.1f},{y0 - v * sy:.1f}" for f, v in c)
        parts.append(f'<polyline points="{pts}" fill="none" stroke="{colour}" stroke-width="1.5"/>')
        parts.append(f'<text x="{w - 90}" y="{80 + 14 * n}" font-size="11" fill="{colour}">'
                     f'{html.escape(label)}</text>')
    return f'<svg width="{w}" height="{h}">{"".join(parts)}</svg>'


def caption(summary):
    r = summary["retargets"]
    arrival = ", ".join(f'{x["arrival"]:.1f}' for x in r)
    over = ", ".join(f'{x["overshoot"]:.2f}' for x in r)
    used = ", ".join(f'{x["damping"]:.2f}' for x in r)
    return f"arrival {arrival} fr · overshoot {over} · ζ used {used}"


def main():
    toonkit = sys.argv[1]
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    keys = sys.argv[2] if len(sys.argv) > 2 else os.path.join(root, "examples/loa/whip.json")
    out = sys.argv[3] if len(sys.argv) > 3 else os.path.join(root, "docs/loa_parameters.png")
    with tempfile.TemporaryDirectory() as folder:
        runs = {(k, z): run(toonkit, keys, k, z, folder) for z in DAMPING for k in STIFFNESS}
        rows = ['<tr><td></td>' + "".join(f"<th>k = {k}</th>" for k in STIFFNESS) + "</tr>"]
        for z in DAMPING:
            cells = "".join(
                f'<td><div class="skin">{runs[(k, z)]["svg"]}</div>'
                f'<div class="cap">{html.escape(caption(runs[(k, z)]["summary"]))}</div></td>'
                for k in STIFFNESS)
            rows.append(f"<tr><th>ζ = {z}</th>{cells}</tr>")
        mid_k, mid_z = STIFFNESS[1], DAMPING[1]
        by_z = [progress(runs[(mid_k, z)]["json"]) for z in DAMPING]
        by_k = [progress(runs[(k, mid_z)]["json"]) for k in STIFFNESS]
        plots = (plot(f"progress along the change, k = {mid_k}", [c for c, _ in by_z], by_z[0][1],
                      [f"ζ = {z}" for z in DAMPING])
                 + plot(f"progress along the change, ζ = {mid_z}", [c for c, _ in by_k],
                        by_k[0][1], [f"k = {k}" for k in STIFFNESS]))
        name = os.path.relpath(keys, root)
        page = f"""<!doctype html><html><head><meta charset="utf-8"><style>
body {{ font-family: sans-serif; margin: 6px; width: 988px; }}
th {{ font-size: 15px; }} td {{ text-align: center; vertical-align: top; }}
.skin svg {{ width: 300px; height: 200px; }}
.cap {{ font-size: 11px; margin-bottom: 8px; }}
</style></head><body>
<div><b>{html.escape(name)}</b> — <code>toonkit loa line</code> onion skins (every frame,
keystrokes bold), {SETTLE} settle frames; per interval: frames to the first arrival, overshoot
(fraction of the change), damping ratio used</div>
<table>{"".join(rows)}</table><div>{plots}</div></body></html>"""
        page_path = os.path.join(folder, "page.html")
        open(page_path, "w").write(page)
        subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu",
                        "--hide-scrollbars", f"--screenshot={out}", "--window-size=1000,900",
                        "file://" + page_path], check=True, capture_output=True)
    print(out)


if __name__ == "__main__":
    main()
