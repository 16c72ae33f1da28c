// The smear panel: presets, β max and multiples/lines fields, the TOML editor with inline
// errors, the offsets view, exports. Every change restyles the prepared offsets on the server.
import { getJSON, getPack, postJSON } from './api.js';

const $ = (id) => document.getElementById(id);

/** The elongation function's `scale` stage (SMEAR Section 5: β max). */
function scaleStage(style) {
  const f = style.elongate && style.elongate.function;
  const stages = f && f.stages;
  return stages ? stages.find((s) => s.op === 'scale') : null;
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
    $('beta-max').addEventListener('input', () => this.edit('beta'));
    $('mult-past').addEventListener('change', () => this.edit('multiples'));
    $('mult-future').addEventListener('change', () => this.edit('multiples'));
    $('line-count').addEventListener('change', () => this.edit('lines'));
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
      this.presets = (await getJSON('/api/smear/presets')).presets;
      for (const p of this.presets) $('preset').add(new Option(p.name, p.name));
      $('preset').value = 'fig11c_speed';
      this.style = structuredClone(this.presets.find((p) => p.name === 'fig11c_speed').style);
    }
    await this.reload();
  }

  deactivate() { this.active = false; this.studio.view.clearEffects(); this.studio.view.setOffsets(null); }

  async reload() {
    const s = this.studio;
    const key = `${s.file}/${s.clip}`;
    if (this.loadedKey !== key) {
      this.anim = await s.loadClip(s.file, s.clip);
      this.loadedKey = key;
      this.offsets = null;
    }
    s.view.setAnimation({ ...this.anim });
    s.setTimeline(this.anim.frames, this.anim.fps);
    s.setFrame(s.frame);
    this.syncFields();
    await this.request({ style: this.style }, performance.now());
  }

  onFrame(f) { this.studio.view.setFrame(f); }

  usePreset(name) {
    this.style = structuredClone(this.presets.find((p) => p.name === name).style);
    this.syncFields();
    this.request({ style: this.style }, performance.now());
  }

  syncFields() {
    const st = scaleStage(this.style);
    if (st && typeof st.by === 'number') { $('beta-max').value = st.by; $('beta-max-value').value = st.by; }
    const m = this.style.multiples;
    $('mult-past').value = m && m.enabled !== false ? (typeof m.past === 'number' ? m.past : 0) : 0;
    $('mult-future').value = m && m.enabled !== false ? (typeof m.future === 'number' ? m.future : 0) : 0;
    const l = this.style.lines;
    $('line-count').value = l && l.enabled !== false && typeof l.count === 'number' ? l.count : 0;
  }

  edit(what) {
    const t0 = performance.now();
    const s = this.style;
    if (what === 'beta') {
      const beta = Number($('beta-max').value);
      $('beta-max-value').value = beta;
      let st = scaleStage(s);
      if (!st) {
        s.elongate = { function: { stages: [{ op: 'speed' }, { op: 'scale', by: beta }] } };
      } else st.by = beta;
    } else if (what === 'multiples') {
      const past = Number($('mult-past').value), future = Number($('mult-future').value);
      if (past + future === 0) delete s.multiples;
      else s.multiples = { ...(s.multiples || {}), enabled: true, past, future };
    } else if (what === 'lines') {
      const count = Number($('line-count').value);
      if (count === 0) delete s.lines;
      else s.lines = { ...(s.lines || {}), enabled: true, count };
    }
    this.request({ style: s }, t0);
  }

  /** Sends a style; while one is in flight only the newest change waits. */
  async request(body, t0) {
    if (this.inflight) { this.pending = { body, t0 }; return; }
    this.inflight = true;
    const s = this.studio;
    try {
      const { header, buffers } = await getPack('/api/smear/stylize', { file: s.file, clip: s.clip, ...body });
      $('style-error').textContent = '';
      s.showError('');
      this.style = header.style;
      $('style-toml').value = header.toml;
      this.syncFields();
      s.view.setAnimation({ ...this.anim, positions: buffers.body });
      s.view.setCopies(header.copies.map((c, i) => ({ vertices: c.vertices, positions: buffers[`copy${i}.positions`], alpha: buffers[`copy${i}.alpha`], triangles: buffers[`copy${i}.triangles`] })));
      s.view.setLines(header.lines.map((l, i) => ({ counts: buffers[`lines${i}.counts`], positions: buffers[`lines${i}.positions`], triangles: buffers[`lines${i}.triangles`], alpha: buffers[`lines${i}.alpha`] })));
      await s.view.rendered();
      const ms = performance.now() - t0;
      s.stats.smear.push({ ms, server_ms: header.seconds * 1000 });
      $('smear-report').textContent = `restyled in ${ms.toFixed(0)} ms (server ${(header.seconds * 1000).toFixed(0)} ms, offset solves so far: ${header.report.offset_solves})\n` + JSON.stringify(header.report.objects.map((o) => ({ name: o.name, elongation_max: o.elongation_max, multiples: o.multiples, lines_max: o.lines_max })), null, 1);
    } catch (e) {
      $('style-error').textContent = e.message;
      s.showError(e.message);
    } finally {
      this.inflight = false;
      if (this.pending) { const p = this.pending; this.pending = null; this.request(p.body, p.t0); }
    }
  }

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
