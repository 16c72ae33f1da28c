// The stopmo panel: seeds clicked on the face, the segmentation as a job with progress and
// cancel (StopShop Section 4); parts coloured, seams drawn as lines over the face. Then the
// library size-vs-error curve (StopShop Fig. 8) as a job drawn as a chart; a click on a
// point builds that library; its reconstruction plays beside the original with the piece
// id of every part at the current frame; the library folder is exported.
import * as THREE from 'three';
import { getJSON, getPack, postJSON } from './api.js';
import { segmentSummary } from './report.js';
import { computeVertexNormals } from './normals.js';

const $ = (id) => document.getElementById(id);

/** The jobs as the panel names them. */
const JOB_NAMES = { 'stopmo.segment': 'segmentation', 'stopmo.curve': 'size curve', 'stopmo.build': 'library' };
const COLORS = [[0.95, 0.55, 0.3], [0.35, 0.6, 0.95], [0.45, 0.85, 0.45], [0.9, 0.8, 0.3], [0.8, 0.45, 0.85], [0.4, 0.85, 0.85]];

export class StopmoPanel {
  constructor(studio) {
    this.studio = studio;
    this.name = 'stopmo';
    this.active = false;
    this.seeds = [[], []];
    this.job = null;
    $('gl').addEventListener('click', (e) => this.click(e));
    $('stopmo-add-part').addEventListener('click', () => { this.seeds.push([]); $('stopmo-part').add(new Option(String(this.seeds.length))); $('stopmo-part').value = String(this.seeds.length); this.list(); });
    $('stopmo-clear').addEventListener('click', () => { this.seeds = this.seeds.map(() => []); this.list(); this.colour(null); });
    $('stopmo-run').addEventListener('click', () => this.run());
    $('stopmo-cancel').addEventListener('click', () => this.cancel());
    $('stopmo-curve').addEventListener('click', () => this.curve());
    $('stopmo-export').addEventListener('click', () => this.exportFolder());
    this.seams = null;
    this.recon = null;
  }

  async activate() {
    this.active = true;
    const s = this.studio;
    // The face (a file that is not a character) is the natural stopmo input: switch to it.
    const face = s.info.files.find((f) => !f.character);
    if (face && s.info.files[s.file].character) {
      s.file = face.index;
      $('file').value = String(face.index);
      $('file').dispatchEvent(new Event('change'));
      return;
    }
    await this.reload();
  }

  deactivate() { this.active = false; this.studio.view.setVertexColors(null); this.clearLibrary(); this.setSeams(null); }

  async reload() {
    const s = this.studio;
    s.view.setActionCamera(null);
    s.view.clearEffects();
    s.view.setOffsets(null);
    this.anim = await s.loadClip(s.file, s.clip);
    s.view.setAnimation({ ...this.anim });
    s.setTimeline(this.anim.frames, this.anim.fps);
    this.labels = null;
    this.result = null;
    this.framed = false;
    this.colour(null);
    this.setSeams(null);
    this.clearLibrary();
  }

  onFrame(f) {
    this.studio.view.setFrame(f);
    this.placeSeams();
    this.placeReconstruction();
  }

  click(e) {
    if (!this.active || e.shiftKey) return;
    const r = e.target.getBoundingClientRect();
    const hit = this.studio.view.pick(e.clientX - r.left, e.clientY - r.top);
    if (hit === -1) return;
    const part = Number($('stopmo-part').value) - 1;
    this.seeds[part].push(hit.triangle);
    this.list();
    this.colour(this.labels);
  }

  list() {
    $('stopmo-seeds').textContent = this.seeds.map((s, i) => `part ${i + 1}: ${s.length ? `${s.length} seed${s.length === 1 ? '' : 's'} placed` : 'no seed yet — click the face'}`).join('\n');
  }

  /** Colours vertices by part (seam vertices dark) and marks seed triangles white. */
  colour(labels) {
    const a = this.anim;
    const out = new Float32Array(a.vertices * 3).fill(0.78);
    if (labels) {
      const part = new Int32Array(a.vertices).fill(-1);
      for (let t = 0; t < labels.length; t++) {
        for (let k = 0; k < 3; k++) {
          const v = a.triangles[t * 3 + k];
          part[v] = part[v] === -1 || part[v] === labels[t] ? labels[t] : -2;
        }
      }
      for (let v = 0; v < a.vertices; v++) {
        const c = part[v] === -2 ? [0.1, 0.1, 0.1] : part[v] >= 0 ? COLORS[part[v] % COLORS.length] : [0.78, 0.78, 0.78];
        out.set(c, v * 3);
      }
    }
    this.seeds.forEach((seeds, i) => {
      for (const t of seeds) for (let k = 0; k < 3; k++) out.set(COLORS[i % COLORS.length].map((x) => Math.min(1, x + 0.3)), a.triangles[t * 3 + k] * 3);
    });
    this.studio.view.setVertexColors(out);
  }

  async run() {
    this.clearLibrary();
    this.start('/api/stopmo/segment', { file: this.studio.file, clip: this.studio.clip, seeds: this.seeds }, (r) => {
      this.labels = r.triangle_part;
      this.result = r;
      this.colour(this.labels);
      this.setSeams(r);
      $('stopmo-curve').disabled = false;
      this.segmentText = segmentSummary(r.summary, this.anim && this.anim.height);
      $('stopmo-report').textContent += '\n' + this.segmentText;
    });
  }

  /** Starts a job (POST url body) and calls done(result) when it finishes. */
  async start(url, body, done) {
    const s = this.studio;
    try {
      const { job } = await postJSON(url, body);
      this.job = job;
      $('stopmo-cancel').disabled = false;
      this.poll(done);
    } catch (e) { s.showError(e.message); }
  }

  async poll(done) {
    const s = this.studio;
    const id = this.job;
    if (id === null) return;
    try {
      const st = await getJSON(`/api/jobs/${id}`);
      $('stopmo-progress').value = st.progress;
      const what = JOB_NAMES[st.kind] || st.kind;
      const line = st.state === 'running' ? `${what}: ${st.stage}… ${st.seconds.toFixed(1)} s` : `${what} ${st.state === 'done' ? 'done' : st.state} in ${st.seconds.toFixed(1)} s`;
      // The segmentation's summary stays in sight under the later jobs' progress.
      $('stopmo-report').textContent = line + (this.segmentText && st.kind !== 'stopmo.segment' ? '\n' + this.segmentText : '');
      if (st.state === 'running') { setTimeout(() => this.poll(done), 200); return; }
      this.job = null;
      $('stopmo-cancel').disabled = true;
      if (st.state === 'failed') s.showError(st.error);
      if (st.state === 'done') await done(st.result);
    } catch (e) { s.showError(e.message); }
  }

  async cancel() {
    if (this.job === null) return;
    try { await postJSON(`/api/jobs/${this.job}/cancel`, {}); } catch (e) { this.studio.showError(e.message); }
  }

  /** Seams as line segments: two points per segment, each Σ w·x of three input vertices. */
  setSeams(r) {
    const scene = this.studio.view.scene;
    if (this.seams) { scene.remove(this.seams.lines); this.seams.lines.geometry.dispose(); this.seams.lines.material.dispose(); this.seams = null; }
    if (r && r.seam_vertices.length) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(r.seam_vertices.length), 3));
      const m = new THREE.LineBasicMaterial({ color: 0xffee33, depthTest: false });
      const lines = new THREE.LineSegments(g, m);
      lines.frustumCulled = false;
      lines.renderOrder = 2;
      scene.add(lines);
      this.seams = { lines, vertices: r.seam_vertices, weights: r.seam_weights };
      this.placeSeams();
    }
    this.studio.view.dirty = true;
  }

  placeSeams() {
    if (!this.seams) return;
    const { lines, vertices, weights } = this.seams;
    const a = this.anim, base = this.studio.frame * a.vertices * 3;
    const out = lines.geometry.attributes.position.array;
    for (let p = 0; p < vertices.length / 3; p++) {
      for (let c = 0; c < 3; c++) {
        let x = 0;
        for (let k = 0; k < 3; k++) x += weights[p * 3 + k] * a.positions[base + vertices[p * 3 + k] * 3 + c];
        out[p * 3 + c] = x;
      }
    }
    lines.geometry.attributes.position.needsUpdate = true;
  }

  /** The size-vs-error curve job, then its chart. */
  curve() {
    const sizes = $('stopmo-sizes').value.split(',').map((x) => Number(x.trim())).filter((x) => x > 0);
    this.clearLibrary();
    this.start('/api/stopmo/curve', { sizes }, (r) => { this.points = r.points; this.chart(); });
  }

  /** StopShop Fig. 8: library size (pieces over all parts) against the mean error (mm). */
  chart() {
    const pts = this.points || [];
    const W = 320, H = 200, L = 46, R = 10, T = 10, B = 34;
    const xmax = Math.max(...pts.map((p) => p.total_pieces), 1), ymax = Math.max(...pts.map((p) => p.mean_error_mm), 1e-9) * 1.1;
    const x = (v) => L + (W - L - R) * v / xmax, y = (v) => T + (H - T - B) * (1 - v / ymax);
    const ns = 'http://www.w3.org/2000/svg';
    const svg = document.createElementNS(ns, 'svg');
    svg.setAttribute('viewBox', `0 0 ${W} ${H}`);
    const add = (tag, attrs, text) => { const e = document.createElementNS(ns, tag); for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v); if (text !== undefined) e.textContent = text; svg.appendChild(e); return e; };
    add('line', { class: 'axis', x1: L, y1: H - B, x2: W - R, y2: H - B });
    add('line', { class: 'axis', x1: L, y1: T, x2: L, y2: H - B });
    for (let k = 0; k <= 4; k++) {
      const v = ymax * k / 4;
      add('text', { x: L - 4, y: y(v) + 3, 'text-anchor': 'end' }, v.toFixed(v < 1 ? 2 : 1));
    }
    for (const p of pts) add('text', { x: x(p.total_pieces), y: H - B + 12, 'text-anchor': 'middle' }, String(p.total_pieces));
    add('text', { x: (L + W - R) / 2, y: H - 4, 'text-anchor': 'middle' }, 'library size (pieces, all parts)');
    add('text', { x: 10, y: (T + H - B) / 2, 'text-anchor': 'middle', transform: `rotate(-90 10 ${(T + H - B) / 2})` }, 'mean error (mm)');
    add('polyline', { points: pts.map((p) => `${x(p.total_pieces)},${y(p.mean_error_mm)}`).join(' '), fill: 'none', stroke: '#4a9fe8' });
    for (const p of pts) {
      const c = add('circle', { cx: x(p.total_pieces), cy: y(p.mean_error_mm), r: 6, 'data-pieces': p.pieces });
      add('title', {}, `${p.pieces} per part, ${p.total_pieces} pieces: mean ${p.mean_error_mm.toFixed(3)} mm, max ${p.max_error_mm.toFixed(3)} mm`);
      c.addEventListener('click', () => this.build(p.pieces));
    }
    $('stopmo-chart').replaceChildren(svg);
  }

  /** Builds the library of a curve point, then shows its reconstruction beside the face. */
  build(pieces) {
    for (const c of document.querySelectorAll('#stopmo-chart circle')) c.classList.toggle('picked', Number(c.dataset.pieces) === pieces);
    this.start('/api/stopmo/build', { pieces, ...this.printOptions() }, async (r) => {
      const { header, buffers } = await getPack('/api/stopmo/reconstruction');
      this.setReconstruction(header, buffers);
      this.built = r;
      $('stopmo-built').textContent = `library of ${r.pieces} pieces per part (${r.total_pieces} in all${r.printed ? '' : ', surfaces only'}): mean error ${r.errors_mm.position_mean.toFixed(3)} mm, max ${r.errors_mm.position_max.toFixed(3)} mm` + r.warnings.map((w) => `\n⚠ ${w}`).join('');
      $('stopmo-export').disabled = false;
    });
  }

  /** The printing fields of the panel as the build request's options (empty fields: the
   * tool's defaults). */
  printOptions() {
    const opts = { print: $('stopmo-print').checked, print_format: $('stopmo-format').value };
    const magnets = $('stopmo-magnets').value.trim();
    if (magnets) opts.magnets = magnets;
    const clearance = $('stopmo-clearance').value.trim();
    if (clearance) opts.clearance_mm = Number(clearance);
    const plate = $('stopmo-plate').value.trim();
    if (plate) opts.plate_mm = plate.split(/x/i).map(Number);
    const thickness = $('stopmo-thickness').value.trim();
    if (thickness) opts.thickness_mm = Number(thickness);
    const minWall = $('stopmo-min-wall').value.trim();
    if (minWall) opts.min_wall_mm = Number(minWall);
    const minFeature = $('stopmo-min-feature').value.trim();
    if (minFeature) opts.min_feature_mm = Number(minFeature);
    return opts;
  }

  setReconstruction(header, buffers) {
    this.clearLibrary();
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(header.vertices * 3), 3));
    g.setIndex(new THREE.BufferAttribute(buffers.triangles, 1));
    const mesh = new THREE.Mesh(g, this.studio.view.surface({ color: 0xd9c7a3, roughness: 0.8, side: THREE.DoubleSide }));
    mesh.frustumCulled = false;
    // Beside the original: shifted by 1.15 × the face's width.
    const [lo, hi] = header.bbox;
    mesh.position.x = (hi[0] - lo[0]) * 1.15;
    this.studio.view.scene.add(mesh);
    if (!this.framed) {
      // Once per clip: orbit around both faces and back off so both are in view.
      const view = this.studio.view, cam = view.perspective, target = view.controls.target;
      const away = cam.position.clone().sub(target);
      target.x += mesh.position.x / 2;
      cam.position.copy(target).addScaledVector(away, 1.6);
      view.controls.update();
      this.framed = true;
    }
    // Where each part's pieces start in `pieces` and its vertices in the merged mesh.
    const starts = [], at = [];
    let p0 = 0, v0 = 0;
    header.part_vertices.forEach((n, i) => { starts.push(p0); at.push(v0); p0 += header.part_pieces[i] * n * 3; v0 += n * 3; });
    this.recon = { mesh, header, pieces: buffers.pieces, labels: buffers.labels, starts, at };
    this.placeReconstruction();
  }

  clearLibrary() {
    if (this.recon) { this.studio.view.scene.remove(this.recon.mesh); this.recon.mesh.geometry.dispose(); this.recon.mesh.material.dispose(); this.recon = null; }
    this.built = null;
    $('stopmo-ids').textContent = '';
    $('stopmo-export').disabled = true;
    this.studio.view.dirty = true;
  }

  placeReconstruction() {
    if (!this.recon) return;
    const { mesh, header, pieces, labels, starts, at } = this.recon;
    const f = Math.min(this.studio.frame, header.frames - 1), parts = header.part_vertices.length;
    const pos = mesh.geometry.attributes.position;
    // Each part shows its frame's piece (the library's labels): a copy of that piece.
    header.part_vertices.forEach((n, i) => {
      const k = labels[f * parts + i], from = starts[i] + k * n * 3;
      pos.array.set(pieces.subarray(from, from + n * 3), at[i]);
    });
    pos.needsUpdate = true;
    computeVertexNormals(mesh.geometry);
    this.ids = header.frame_ids[f];
    $('stopmo-ids').textContent = `frame ${f} pieces: ${this.ids.join(' · ')}`;
    this.studio.view.dirty = true;
  }

  async exportFolder() {
    try {
      const r = await postJSON('/api/stopmo/export', { folder: $('stopmo-folder').value });
      this.exported = r;
      $('stopmo-built').textContent = `wrote ${r.written.length} files to ${r.folder}`;
    } catch (e) { this.studio.showError(e.message); }
  }
}
