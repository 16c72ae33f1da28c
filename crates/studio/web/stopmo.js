// The stopmo panel: seeds clicked on the face, the segmentation as a job with progress and
// cancel (StopShop Section 4); parts coloured, seams (vertices between parts) dark.
import { getJSON, postJSON } from './api.js';

const $ = (id) => document.getElementById(id);
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

  deactivate() { this.active = false; this.studio.view.setVertexColors(null); }

  async reload() {
    const s = this.studio;
    s.view.setActionCamera(null);
    s.view.clearEffects();
    s.view.setOffsets(null);
    this.anim = await s.loadClip(s.file, s.clip);
    s.view.setAnimation({ ...this.anim });
    s.setTimeline(this.anim.frames, this.anim.fps);
    this.labels = null;
    this.colour(null);
  }

  onFrame(f) { this.studio.view.setFrame(f); }

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
    $('stopmo-seeds').textContent = this.seeds.map((s, i) => `part ${i + 1}: ${s.length ? 'triangles ' + s.join(', ') : 'no seed yet'}`).join('\n');
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
    const s = this.studio;
    try {
      const { job } = await postJSON('/api/stopmo/segment', { file: s.file, clip: s.clip, seeds: this.seeds });
      this.job = job;
      $('stopmo-cancel').disabled = false;
      this.poll();
    } catch (e) { s.showError(e.message); }
  }

  async poll() {
    const s = this.studio;
    const id = this.job;
    if (id === null) return;
    try {
      const st = await getJSON(`/api/jobs/${id}`);
      $('stopmo-progress').value = st.progress;
      $('stopmo-report').textContent = `job ${id}: ${st.state}, ${st.stage} (${st.seconds.toFixed(1)} s)`;
      if (st.state === 'running') { setTimeout(() => this.poll(), 200); return; }
      this.job = null;
      $('stopmo-cancel').disabled = true;
      if (st.state === 'failed') s.showError(st.error);
      if (st.state === 'done') {
        this.labels = st.result.triangle_part;
        this.result = st.result;
        this.colour(this.labels);
        $('stopmo-report').textContent += '\n' + JSON.stringify(st.result.summary, null, 1);
      }
    } catch (e) { s.showError(e.message); }
  }

  async cancel() {
    if (this.job === null) return;
    try { await postJSON(`/api/jobs/${this.job}/cancel`, {}); } catch (e) { this.studio.showError(e.message); }
  }
}
