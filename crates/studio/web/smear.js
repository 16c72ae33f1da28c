// The smear panel: presets, β max and multiples/lines fields and a block of every parameter
// generated from the style's JSON (keyframeable on the timeline, smear_keys.js), the
// weight-group picker (smear_weights.js), the TOML editor with inline errors, the offsets
// view, exports. Every change restyles the prepared offsets on the server: the current frame
// first, the whole clip right after its answer.
import { getJSON, getPack, getPackOffThread, postJSON } from './api.js';
import { KEYABLE, keyable, isCurve, paramAt, setKey, deleteKey, drawKeys, styleParams } from './smear_keys.js';
import { WeightPicker } from './smear_weights.js';
import { smearSummary } from './report.js';
import { ClipBody, ClipCopy } from './smear_clip.js';

const $ = (id) => document.getElementById(id);
const EMPTY_LINES = { positions: new Float32Array(0), triangles: new Uint32Array(0) };

/** Motion-line set `i` of a stylize answer, per frame: [{positions, triangles}]. */
function splitLines(buffers, i) {
  const counts = buffers[`lines${i}.counts`], pos = buffers[`lines${i}.positions`];
  // 16-bit indices (a whole-clip answer's) are drawn as they came, as uint16.
  const t16 = buffers[`lines${i}.triangles16`];
  const tri = t16 ? new Uint16Array(t16.buffer, t16.byteOffset, t16.length) : buffers[`lines${i}.triangles`];
  const out = [];
  let v = 0, t = 0;
  for (let f = 0; f < counts.length / 2; f++) {
    const nv = counts[2 * f], nt = counts[2 * f + 1];
    out.push({ positions: pos.subarray(v * 3, (v + nv) * 3), triangles: tri.subarray(t * 3, (t + nt) * 3) });
    v += nv; t += nt;
  }
  return out;
}

/** A row of the "all parameters" block: label, field, and ◇/✕ for a keyable number. */
function paramRow(d) {
  const row = document.createElement('label');
  const name = document.createElement('span');
  name.textContent = d.label;
  name.title = d.id.slice(2);
  const input = document.createElement('input');
  input.id = d.id;
  if (d.kind === 'bool') input.type = 'checkbox';
  else if (d.kind === 'text') { input.readOnly = true; input.title = 'edit in the TOML below'; }
  else { input.type = 'number'; input.step = d.integer ? '1' : 'any'; }
  row.append(name, input);
  if (d.keyed) {
    const key = document.createElement('button'), unkey = document.createElement('button');
    key.className = 'key'; key.dataset.key = d.id; key.textContent = '◇'; key.title = 'set a keyframe at the current frame';
    unkey.className = 'unkey'; unkey.dataset.key = d.id; unkey.textContent = '✕'; unkey.title = 'delete the keyframe at the current frame'; unkey.disabled = true;
    row.append(key, unkey);
  }
  return row;
}

export class SmearPanel {
  constructor(studio) {
    this.studio = studio;
    this.name = 'smear';
    this.active = false;
    this.style = null;
    this.inflight = false;
    this.pending = null;
    this.offsets = null;
    this.loadedKey = null;
    this.weights = new WeightPicker(studio);
    $('beta-max').addEventListener('input', () => this.edit('beta-max'));
    for (const id of ['mult-past', 'mult-future', 'line-count']) $(id).addEventListener('change', () => this.edit(id));
    for (const b of document.querySelectorAll('button.key')) b.addEventListener('click', () => this.key(b.dataset.key));
    for (const b of document.querySelectorAll('button.unkey')) b.addEventListener('click', () => this.unkey(b.dataset.key, this.studio.frame));
    // The generated fields are replaced with the style: their events are caught on the block.
    $('all-params').addEventListener('change', (e) => { if (e.target.id.startsWith('p:')) this.edit(e.target.id); });
    $('all-params').addEventListener('click', (e) => {
      const b = e.target.closest('button');
      if (b && b.classList.contains('key')) this.key(b.dataset.key);
      else if (b && b.classList.contains('unkey')) this.unkey(b.dataset.key, this.studio.frame);
    });
    $('weight-source').addEventListener('change', () => this.pickWeights());
    $('show-weights').addEventListener('change', () => this.weights.showOverlay());
    window.addEventListener('resize', () => { if (this.active) this.drawKeys(); });
    $('preset').addEventListener('change', () => this.usePreset($('preset').value));
    $('apply-toml').addEventListener('click', () => this.request({ toml: $('style-toml').value }, performance.now()));
    $('show-offsets').addEventListener('change', () => this.showOffsets());
    $('smear-export').addEventListener('click', () => this.export($('smear-name').value));
    $('style-export').addEventListener('click', () => this.export($('smear-name').value.replace(/\.[^.]*$/, '') + '.toml'));
  }

  async activate() {
    this.active = true;
    this.studio.view.setActionCamera(null);
    this.studio.view.setVertexColors(null);
    if (!this.presets) {
      // The smear crate's presets, default and parameter ranges (one definition for every
      // front end), then the example styles.
      const answer = await getJSON('/api/smear/presets');
      this.presets = answer.presets;
      for (const p of this.presets) $('preset').add(new Option(p.name, p.name));
      $('preset').value = answer.default;
      this.style = structuredClone(this.presets.find((p) => p.name === answer.default).style);
      const beta = answer.parameters.find((p) => p.name === 'beta_max');
      Object.assign($('beta-max'), { min: beta.min, max: beta.max, title: beta.doc });
    }
    await this.reload();
  }

  deactivate() {
    this.active = false;
    if (this.restCtl) { this.restCtl.abort(); this.restCtl = null; }
    this.gen = (this.gen || 0) + 1;
    this.clip = this.copies = this.lines = null;
    this.studio.view.clearEffects();
    this.studio.view.setOffsets(null);
    this.studio.view.setVertexColors(null);
    $('key-track').hidden = true;
  }

  async reload() {
    const s = this.studio;
    const key = `${s.file}/${s.clip}`;
    if (this.loadedKey !== key) {
      this.anim = await s.loadClip(s.file, s.clip);
      this.loadedKey = key;
      this.offsets = null;
      this.clip = this.copies = this.lines = null;
    }
    s.view.setAnimation({ ...this.anim });
    s.setTimeline(this.anim.frames, this.anim.fps);
    s.setFrame(s.frame);
    await this.weights.load();
    this.syncFields();
    this.weights.showOverlay();
    await this.request({ style: this.style }, performance.now());
  }

  onFrame(f) {
    this.studio.view.setFrame(f);
    if (this.style) this.syncFields();
    if (this.restCtl && this.fresh && !this.fresh.has(f)) this.loadFrame(f);
  }

  usePreset(name) {
    this.style = structuredClone(this.presets.find((p) => p.name === name).style);
    this.syncFields();
    this.request({ style: this.style }, performance.now());
  }

  /** The fields show the style's values at the current frame; the keys and the picker too. */
  syncFields() {
    const f = this.studio.frame;
    for (const d of KEYABLE) {
      const p = d.get(this.style);
      if (p === null || p === undefined) continue;
      const v = +Number(paramAt(p, f)).toFixed(3);
      $(d.id).value = v;
      if (d.id === 'beta-max') $('beta-max-value').value = v;
    }
    this.syncParams(f);
    this.weights.sync(this.style);
    this.drawKeys();
  }

  /**
   * The "all parameters" block: rebuilt when the style's set of parameters changes (preset,
   * TOML, a section switched on), otherwise only its values are set (a field being edited
   * keeps its focus).
   */
  syncParams(f) {
    const params = styleParams(this.style);
    const sig = params.map((d) => `${d.id}:${d.kind}`).join('|');
    if (sig !== this.paramSig) {
      this.paramSig = sig;
      $('all-params').replaceChildren(...params.map((d) => paramRow(d)));
      $('all-params-count').textContent = params.length;
    }
    for (const d of params) {
      const el = document.getElementById(d.id), p = d.get(this.style);
      if (d.kind === 'bool') el.checked = p;
      else if (d.kind === 'text') el.value = Array.isArray(p) ? p.join(', ') : p;
      else el.value = +Number(paramAt(p, f)).toFixed(4);
    }
  }

  drawKeys() {
    const s = this.studio;
    drawKeys(this.style, s.frame, s.timeline.frames, { jump: (f) => s.setFrame(f), remove: (id, f) => this.unkey(id, f) });
  }

  /** A field changed: a keyed parameter gets a key at the current frame, others a constant. */
  edit(id) {
    const t0 = performance.now();
    const d = keyable(id, this.style);
    if (!d) return;
    if (d.kind === 'bool') { d.set(this.style, $(id).checked); this.request({ style: this.style }, t0); return; }
    if ($(id).value === '' || !Number.isFinite(Number($(id).value))) return;
    const v = Number($(id).value);
    if (id === 'beta-max') $('beta-max-value').value = v;
    const p = d.get(this.style);
    d.set(this.style, isCurve(p) ? setKey(p, this.studio.frame, v) : v);
    this.request({ style: this.style }, t0);
  }

  /** The field's key button: a key at the current frame with the field's value. */
  key(id) {
    const d = keyable(id, this.style);
    d.set(this.style, setKey(d.get(this.style), this.studio.frame, Number($(id).value)));
    this.drawKeys();
    this.request({ style: this.style }, performance.now());
  }

  /** Deletes field `id`'s key at `frame` (the last key's value stays as a constant). */
  unkey(id, frame) {
    const d = keyable(id, this.style);
    d.set(this.style, deleteKey(d.get(this.style), frame));
    this.drawKeys();
    this.request({ style: this.style }, performance.now());
  }

  /**
   * The weight-group picker changed: the server sets the source on the style
   * (`smear::Style::set_weights`, the effects then read ω) and the overlay shows it.
   */
  pickWeights() {
    const w = this.weights.picked();
    if (w) {
      this.style.weights = w;
      $('show-weights').checked = true;
      this.request({ style: this.style, weights: w }, performance.now());
    } else {
      delete this.style.weights;
      this.request({ style: this.style }, performance.now());
    }
    this.weights.showOverlay();
  }

  /**
   * Restyles: the current frame (a one-frame answer, drawn at once), then every frame (asked
   * for as soon as the current frame is answered, laid in when it arrives, cancelled by the
   * next change); frames scrubbed to meanwhile are asked for one by one. While a first-frame
   * request is in flight only the newest change waits.
   */
  async request(body, t0) {
    this.gen = (this.gen || 0) + 1;
    if (this.restCtl) { this.restCtl.abort(); this.restCtl = null; }
    if (this.inflight) {
      // Only the newest change waits; a weight source picked meanwhile still gets set.
      const weights = this.pending && this.pending.body.weights;
      this.pending = { body: weights && !body.weights && !body.toml ? { ...body, weights } : body, t0 };
      return;
    }
    this.inflight = true;
    const s = this.studio;
    const f = s.frame;
    const gen = this.gen;
    this.fresh = null;
    try {
      const r = await getPack('/api/smear/stylize', { file: s.file, clip: s.clip, ...body, frames: [f, f + 1] });
      const fetched = performance.now();
      if (!this.pending) {
        // The whole clip is asked for now, after the current frame's answer and before it is
        // drawn: the small request does not wait behind the clip's tasks on the server's
        // cores (docs/studio.md, "Figures"), and the server restyles the clip while the page
        // draws the frame.
        const ctl = new AbortController();
        const rest = getPackOffThread('/api/smear/stylize', { file: s.file, clip: s.clip, ...body, changes: true }, ctl.signal);
        rest.catch(() => {});
        this.restCtl = ctl;
        $('style-error').textContent = '';
        s.showError('');
        this.style = r.header.style;
        $('style-toml').value = r.header.toml;
        this.syncFields();
        // A preset or TOML may bring or drop weights: the overlay follows the style.
        const weights = JSON.stringify(this.style.weights);
        if (weights !== this.shownWeights) { this.shownWeights = weights; this.weights.showOverlay(); }
        this.lastBody = { style: this.style };
        this.fresh = new Set([f]);
        this.apply(r);
        const applied = performance.now();
        await s.view.rendered();
        const ms = performance.now() - t0;
        s.stats.smear.push({ ms, server_ms: r.header.seconds * 1000, bytes: r.bytes, fetch_ms: fetched - t0, apply_ms: applied - fetched, draw_ms: performance.now() - applied, render_ms: s.view.renderMs, scale: s.view.scale });
        $('smear-report').textContent = `frame ${f} restyled in ${ms.toFixed(0)} ms (server ${(r.header.seconds * 1000).toFixed(0)} ms, ${(r.bytes / 1024).toFixed(0)} KiB)`;
        this.loadRest(gen, t0, rest, ctl);
      }
    } catch (e) {
      $('style-error').textContent = e.message;
      s.showError(e.message);
    } finally {
      this.inflight = false;
      if (this.pending) { const p = this.pending; this.pending = null; this.request(p.body, p.t0); }
    }
  }

  /**
   * Every frame of the current style (the `rest` answer of `ctl`); a newer change aborts it.
   * Called once the current frame's answer is drawn: the frames restyled exactly so far
   * (`fresh`) are kept, and when the frame on screen is one of them nothing is drawn again
   * (it already shows the new style); the clock stops when every frame is in the buffers.
   */
  async loadRest(gen, t0, rest, ctl) {
    const s = this.studio;
    try {
      const r = await rest;
      if (gen !== this.gen) return;
      const fetched = performance.now();
      this.restCtl = null;
      const redrawn = this.apply(r, this.fresh);
      const applied = performance.now();
      if (redrawn) await s.view.rendered();
      // When the request left, its answer's headers and its last byte arrived (from t0).
      const at = (t) => t - t0;
      s.stats.smearAll.push({ ms: performance.now() - t0, server_ms: r.header.seconds * 1000, bytes: r.bytes, frames: r.header.frames, fetch_ms: fetched - t0, apply_ms: applied - fetched, draw_ms: performance.now() - applied, redrawn, sent_ms: at(r.times.sent), headers_ms: at(r.times.headers), body_ms: at(r.times.body) });
      $('smear-report').textContent += `\nall ${r.header.frames} frames in ${(performance.now() - t0).toFixed(0)} ms (server ${(r.header.seconds * 1000).toFixed(0)} ms, ${(r.bytes / 1048576).toFixed(1)} MiB)\n` + smearSummary(r.header.report, r.header.frames, this.anim.height);
    } catch (e) {
      if (e.name !== 'AbortError' && gen === this.gen) s.showError(e.message);
    } finally {
      if (this.restCtl === ctl) this.restCtl = null;
    }
  }

  /** While the background load runs, a frame not restyled yet is asked for alone. */
  async loadFrame(f) {
    if (this.frameInflight) { this.frameWant = f; return; }
    this.frameInflight = true;
    const s = this.studio, gen = this.gen;
    try {
      const r = await getPack('/api/smear/stylize', { file: s.file, clip: s.clip, ...this.lastBody, frames: [f, f + 1] });
      if (gen === this.gen && this.restCtl) { this.fresh.add(f); this.apply(r); }
    } catch (e) {
      if (gen === this.gen) s.showError(e.message);
    } finally {
      this.frameInflight = false;
      const w = this.frameWant; this.frameWant = null;
      if (w !== null && w !== undefined && this.restCtl && this.fresh && !this.fresh.has(w)) this.loadFrame(w);
    }
  }

  /**
   * Lays a stylize answer holding clip frames `first_frame ..+ frames` into the panel's
   * whole-clip buffers (frames not answered yet keep the previous style; copies there are
   * transparent until they arrive). `keep`: clip frames that already hold this style exactly
   * (a one-frame answer's), left as they are. Returns whether the viewport was given the
   * result to draw again (false when the frame it shows is kept and the meshes stay).
   */
  apply({ header, buffers }, keep = null) {
    const s = this.studio;
    const total = header.clip_frames, k = header.first_frame, nf = header.frames;
    if (!this.clip || this.clip.input !== this.anim) this.clip = new ClipBody(this.anim);
    if (buffers['body.changed']) this.clip.setChanges(k, nf, buffers, keep);
    else this.clip.setFrames(k, nf, buffers.body);
    // The multiples: kept per copy (ClipCopy) while the style's copies stay the same.
    const same = this.copies && this.copies.length === header.copies.length && this.copies.every((c, i) => c.vertices === header.copies[i].vertices && c.triangles.length === buffers[`copy${i}.triangles`].length);
    if (!same) {
      this.copies = header.copies.map((c, i) => {
        const clip = new ClipCopy(this.anim, c.first_vertex, c.vertices);
        return { vertices: c.vertices, frames: total, triangles: buffers[`copy${i}.triangles`], clip, frameAt: (f) => clip.frame(f) };
      });
    }
    header.copies.forEach((c, i) => {
      const shown = buffers[`copy${i}.shown`], clip = this.copies[i].clip;
      if (shown) clip.setShown(k, nf, shown, buffers[`copy${i}.shown_positions`], buffers[`copy${i}.shown_alpha`], keep);
      else clip.setFrames(k, nf, buffers[`copy${i}.positions`], buffers[`copy${i}.alpha`]);
    });
    // The motion lines: per set, one entry per clip frame, replaced in place (the viewport
    // reads the same arrays) while the sets stay the same.
    const sets = header.lines.map((_, i) => splitLines(buffers, i));
    const sameLines = this.lines && this.lines.length === sets.length && this.lines.every((l) => l.length === total);
    if (!sameLines) this.lines = sets.map(() => Array.from({ length: total }, () => EMPTY_LINES));
    sets.forEach((fr, i) => fr.forEach((x, j) => { if (!keep || !keep.has(k + j)) this.lines[i][k + j] = x; }));
    const clip = this.clip, view = s.view;
    if (same && sameLines && keep && keep.has(view.frame) && view.anim && view.anim.clip === clip) return false;
    view.setAnimation({ ...this.anim, positions: clip.positions, frameAt: (f) => clip.frame(f), clip });
    if (!same) view.setCopies(this.copies);
    if (!sameLines) view.setLines(this.lines.map((frames) => ({ frames })));
    return true;
  }

  /** Every frame's body (frames × vertices × 3) of the styles answered so far, or null. */
  get body() { return this.clip ? this.clip.all() : null; }

  async showOffsets() {
    const s = this.studio;
    if (!$('show-offsets').checked) { s.view.setOffsets(null); return; }
    try {
      if (!this.offsets) this.offsets = (await getPack(`/api/smear/offsets?file=${s.file}&clip=${encodeURIComponent(s.clip)}`)).buffers.offsets;
      s.view.setOffsets(this.offsets);
    } catch (e) { s.showError(e.message); }
  }

  async export(name) {
    const s = this.studio;
    try {
      const r = await postJSON('/api/smear/export', { file: s.file, clip: s.clip, style: this.style, name });
      s.status(`wrote ${r.written}`);
    } catch (e) { s.showError(e.message); }
  }
}
