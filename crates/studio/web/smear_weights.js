// The smear panel's weight-group picker (SMEAR Fig. 15b): the file's weight sources (a group
// per bone, painted vertex attributes, vertex-colour channels) from the server; picking one
// sets the style's painted weights ω, and the overlay colours the mesh grey (ω = 0) → orange
// (ω = 1).
import { getJSON, getPack } from './api.js';

const $ = (id) => document.getElementById(id);
const GREY = [0.78, 0.78, 0.8], HOT = [1.0, 0.42, 0.08];

export class WeightPicker {
  constructor(studio) {
    this.studio = studio;
    this.sources = [];
    this.key = null;
    this.cache = new Map();
  }

  /** Lists the weight sources of the current file and clip (once per file and clip). */
  async load() {
    const s = this.studio;
    const key = `${s.file}/${s.clip}`;
    if (this.key === key) return;
    this.key = key;
    this.cache.clear();
    const r = await getJSON(`/api/smear/weight-sources?file=${s.file}&clip=${encodeURIComponent(s.clip)}`);
    this.sources = r.sources;
    const sel = $('weight-source');
    sel.replaceChildren(new Option('none (ω = 1)', ''));
    r.sources.forEach((w, i) => sel.add(new Option(w.label, String(i))));
  }

  /** The picked source (the style's `weights` form), or null. */
  picked() {
    const v = $('weight-source').value;
    if (v === '') return null;
    if (v === 'style') return this.fromStyle;
    return this.sources[Number(v)].source;
  }

  /** Shows the style's weight source in the picker. */
  sync(style) {
    const sel = $('weight-source');
    const w = style && style.weights;
    for (const o of [...sel.options]) if (o.value === 'style') o.remove();
    if (!w) { sel.value = ''; return; }
    const text = JSON.stringify(w);
    const i = this.sources.findIndex((x) => JSON.stringify(x.source) === text);
    if (i >= 0) { sel.value = String(i); return; }
    this.fromStyle = w;
    sel.add(new Option(`from the style: ${text}`, 'style'));
    sel.value = 'style';
  }

  /** The overlay on (when the checkbox is ticked and a source is picked) or off. */
  async showOverlay() {
    const s = this.studio;
    const w = this.picked();
    if (!$('show-weights').checked || !w) { s.view.setVertexColors(null); return; }
    const text = JSON.stringify(w);
    try {
      let colors = this.cache.get(text);
      if (!colors) {
        const r = await getPack(`/api/smear/weights?file=${s.file}&clip=${encodeURIComponent(s.clip)}&source=${encodeURIComponent(text)}`);
        const weights = r.buffers.weights;
        colors = new Float32Array(weights.length * 3);
        weights.forEach((x, i) => { for (let c = 0; c < 3; c++) colors[i * 3 + c] = GREY[c] + (HOT[c] - GREY[c]) * x; });
        this.cache.set(text, colors);
      }
      // The picker may have moved on while the weights came.
      if (JSON.stringify(this.picked()) === text && $('show-weights').checked) s.view.setVertexColors(colors);
    } catch (e) { s.showError(e.message); }
  }
}
