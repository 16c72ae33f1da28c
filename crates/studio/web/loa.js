// The loa panel: strokes drawn over the character at the current frame become keystrokes
// (LoA Section 3); the server returns the dynamic line and the character motion that
// follows it (LoA Section 4). Shift-drag on the line wobbles it.
import { getJSON, getPack, postJSON } from './api.js';
import { loaSummary } from './report.js';

const $ = (id) => document.getElementById(id);
const TIMELINE = 48;

export class LoaPanel {
  constructor(studio) {
    this.studio = studio;
    this.name = 'loa';
    this.active = false;
    this.keys = [];
    this.wobbles = [];
    this.result = null;
    this.stroke = null;
    this.overlay = $('overlay');
    this.ctx = this.overlay.getContext('2d');
    this.overlay.addEventListener('pointerdown', (e) => this.down(e));
    this.overlay.addEventListener('pointermove', (e) => this.move(e));
    this.overlay.addEventListener('pointerup', (e) => this.up(e));
    $('loa-clear').addEventListener('click', () => { this.keys = []; this.wobbles = []; this.result = null; this.table(); this.showRest(); });
    $('loa-export-keys').addEventListener('click', () => this.export($('loa-name').value.replace(/\.[^.]*$/, '') + '.keys.json', 'keystrokes'));
    $('loa-export-line').addEventListener('click', () => this.export($('loa-name').value.replace(/\.[^.]*$/, '') + '.line.json', 'line'));
    $('loa-export-motion').addEventListener('click', () => this.export($('loa-name').value, 'motion'));
  }

  async activate() {
    this.active = true;
    this.overlay.classList.add('drawing');
    await this.reload();
  }

  deactivate() {
    this.active = false;
    this.overlay.classList.remove('drawing');
    this.ctx.clearRect(0, 0, this.overlay.width, this.overlay.height);
    this.dirty = true;
    this.studio.view.setActionCamera(null);
  }

  async reload() {
    const s = this.studio;
    this.view = await getJSON(`/api/loa/view?file=${s.file}`);
    if (!$('loa-bones').options.length) {
      $('loa-bones').add(new Option('(default)', ''));
      for (const p of this.view.presets) $('loa-bones').add(new Option(p, p));
    }
    s.view.clearEffects();
    s.view.setOffsets(null);
    s.view.setVertexColors(null);
    s.view.setActionCamera(this.view.camera);
    this.rest = await s.loadClip(s.file, s.clip);
    this.keys = []; this.wobbles = []; this.result = null;
    this.table();
    this.showRest();
  }

  showRest() {
    this.dirty = true;
    const s = this.studio;
    s.view.setAnimation({ ...this.rest, frames: 1 }, { frame: false });
    s.setTimeline(TIMELINE, 24);
  }

  onFrame(f) {
    this.dirty = true;
    const r = this.result;
    if (!r) return;
    this.studio.view.setFrame(f - r.header.motion.first_frame);
  }

  point(e) {
    const r = this.overlay.getBoundingClientRect();
    return [e.clientX - r.left, e.clientY - r.top];
  }

  /** The line's joints at timeline frame f (canvas pixels), or null. */
  lineAt(f) {
    if (!this.result) return null;
    const { header, buffers } = this.result;
    const i = f - header.line.first_frame;
    if (i < 0 || i >= header.line.frames) return null;
    const j = header.line.joints;
    const pts = [];
    for (let k = 0; k < j; k++) pts.push([buffers.line[(i * j + k) * 2], buffers.line[(i * j + k) * 2 + 1]]);
    return pts;
  }

  down(e) {
    if (!this.active) return;
    this.overlay.setPointerCapture(e.pointerId);
    const p = this.point(e);
    if (e.shiftKey) {
      const line = this.lineAt(this.studio.frame);
      if (line) {
        let best = 0, dist = Infinity;
        line.forEach((q, k) => { const d = Math.hypot(q[0] - p[0], q[1] - p[1]); if (d < dist) { dist = d; best = k; } });
        if (dist < 30) { this.drag = { start: p, at: best / (line.length - 1), frame: this.studio.frame }; return; }
      }
    }
    this.stroke = [p];
    this.dirty = true;
  }

  move(e) {
    if (this.stroke) { this.stroke.push(this.point(e)); this.dirty = true; }
  }

  up(e) {
    this.dirty = true;
    const p = this.point(e);
    if (this.drag) {
      const d = this.drag; this.drag = null;
      const imp = [(p[0] - d.start[0]) * 8, (p[1] - d.start[1]) * 8];
      this.wobbles.push({ frame: d.frame, at: d.at, impulse: imp, stiffness: 60, damping: 0.2 });
      this.update(performance.now());
      return;
    }
    if (!this.stroke) return;
    const stroke = this.stroke; this.stroke = null;
    if (stroke.length < 3) return;
    this.addStroke(this.studio.frame, stroke);
  }

  /** Adds (or redraws) the keystroke at `frame`. */
  addStroke(frame, points) {
    const t0 = performance.now();
    const bones = $('loa-bones').value || undefined;
    const old = this.keys.find((k) => k.frame === frame);
    if (old) old.points = points;
    else this.keys.push({ frame, points, stiffness: this.view.stiffness.default, damping: this.view.damping.default, bones });
    this.keys.sort((a, b) => a.frame - b.frame);
    this.table();
    return this.update(t0);
  }

  table() {
    this.dirty = true;
    const body = $('keys').querySelector('tbody');
    body.innerHTML = '';
    this.keys.forEach((k, i) => {
      const row = document.createElement('tr');
      const cell = (html) => { const td = document.createElement('td'); td.innerHTML = html; row.appendChild(td); return td; };
      // The sliders' documented ranges come from the loa crate (/api/loa/view); the server
      // refuses a typed value outside them, naming the range.
      const num = (v, step, set, range) => { const lim = range ? ` min="${range[0]}" max="${range[1]}"` : ''; const td = cell(`<input type="number" step="${step}"${lim} value="${v}">`); td.firstChild.addEventListener('change', (e) => { set(Number(e.target.value)); this.keys.sort((a, b) => a.frame - b.frame); this.table(); this.update(performance.now()); }); };
      num(k.frame, 1, (v) => { k.frame = Math.round(v); });
      num(k.stiffness, 5, (v) => { k.stiffness = v; }, this.view.stiffness.range);
      num(k.damping, 0.05, (v) => { k.damping = v; }, this.view.damping.range);
      const sel = document.createElement('select');
      for (const o of $('loa-bones').options) sel.add(new Option(o.text, o.value));
      sel.value = k.bones || '';
      sel.addEventListener('change', () => { k.bones = sel.value || undefined; this.update(performance.now()); });
      cell('').appendChild(sel);
      const del = cell('<button title="delete">✕</button>');
      del.firstChild.addEventListener('click', () => { this.keys.splice(i, 1); this.table(); this.update(performance.now()); });
      body.appendChild(row);
    });
  }

  async update(t0) {
    const s = this.studio;
    if (this.keys.length < 2) { this.result = null; this.showRest(); return; }
    if (this.inflight) { this.pending = t0; return; }
    this.inflight = true;
    try {
      const body = {
        file: s.file,
        width: this.overlay.clientWidth,
        height: this.overlay.clientHeight,
        keystrokes: this.keys.map((k) => ({ frame: k.frame, points: k.points, stiffness: k.stiffness, damping: k.damping, bones: k.bones })),
        wobbles: this.wobbles,
        // The renderer skins the motion: the answer is the skeleton's pose per frame (and
        // the binding, when the one held is not the character's).
        skin: this.binding ? this.binding.id : '',
      };
      // One answer: the line (every frame) and the character's whole motion, as float32.
      const r = await getPack('/api/loa/animate', body);
      const fetched = performance.now();
      this.result = r;
      this.dirty = true;
      s.showError('');
      const h = r.header;
      // Every answer of one file holds the same triangles: the viewport keeps its mesh (and
      // the index uploaded to the GPU) when they are the array it already draws.
      const tri = r.buffers.triangles, shown = s.view.anim && s.view.anim.triangles;
      const triangles = shown && shown.length === tri.length && shown.every((t, i) => t === tri[i]) ? shown : tri;
      const skin = h.motion.skin;
      if (skin && r.buffers['skin.rest']) {
        const b = r.buffers;
        this.binding = { id: skin.id, rest: b['skin.rest'], index: b['skin.index'], weight: b['skin.weight'], node: b['skin.node'], inverse: b['skin.inverse'] };
      }
      if (skin && this.binding && this.binding.id === skin.id) {
        s.view.setSkinned({ triangles, binding: this.binding, world: r.buffers['skin.world'], nodes: skin.nodes, frames: h.motion.frames, vertices: h.motion.vertices });
      } else {
        s.view.setAnimation({ triangles, positions: r.buffers.positions, frames: h.motion.positions_frames, vertices: h.motion.vertices }, { frame: false });
      }
      s.setTimeline(Math.max(TIMELINE, h.line.first_frame + h.line.frames + 12), 24);
      this.onFrame(s.frame);
      const applied = performance.now();
      await s.view.rendered();
      const ms = performance.now() - t0;
      const stat = { ms, server_ms: h.seconds.total * 1000, bytes: r.bytes, fetch_ms: fetched - t0, apply_ms: applied - fetched, draw_ms: performance.now() - applied };
      s.stats.loa.push(stat);
      s.stats.loaAll.push(stat);
      $('loa-report').textContent = loaSummary(h) + `\n\nredrawn in ${ms.toFixed(0)} ms: line ${(h.seconds.line * 1000).toFixed(0)} ms, motion ${(h.seconds.animate * 1000).toFixed(0)} ms on the server, ${(r.bytes / 1048576).toFixed(1)} MiB`;
    } catch (e) {
      s.showError(e.message);
    } finally {
      this.inflight = false;
      if (this.pending !== undefined && this.pending !== null) { const t = this.pending; this.pending = null; this.update(t); }
    }
  }

  draw() {
    const c = this.overlay, ctx = this.ctx;
    const f = this.studio.frame;
    // Drawn only when what it shows changed: an overlay redrawn every animation frame keeps
    // the page compositing (on the CPU with software GL) while the server answers a stroke.
    const size = `${c.clientWidth}x${c.clientHeight}`;
    if (!this.dirty && size === this.shown) return;
    this.dirty = false; this.shown = size;
    if (c.width !== c.clientWidth || c.height !== c.clientHeight) { c.width = c.clientWidth; c.height = c.clientHeight; }
    ctx.clearRect(0, 0, c.width, c.height);
    const path = (pts, color, width) => {
      if (!pts || pts.length < 2) return;
      ctx.strokeStyle = color; ctx.lineWidth = width; ctx.beginPath();
      ctx.moveTo(pts[0][0], pts[0][1]);
      for (const p of pts.slice(1)) ctx.lineTo(p[0], p[1]);
      ctx.stroke();
    };
    for (const k of this.keys) path(k.points, k.frame === f ? 'rgba(80,200,255,0.9)' : 'rgba(200,200,200,0.35)', 2);
    path(this.lineAt(f), 'rgba(255,140,40,0.95)', 4);
    path(this.stroke, 'rgba(80,200,255,0.9)', 2);
  }

  async export(name, what) {
    try {
      const r = await postJSON('/api/loa/export', { name, what });
      this.studio.status(`wrote ${r.written}`);
    } catch (e) { this.studio.showError(e.message); }
  }
}
