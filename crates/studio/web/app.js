// toonkit studio page: the timeline, the file/clip pickers, the three panels.
import { getJSON, getPack } from './api.js';
import { Viewport } from './viewport.js';
import { SmearPanel } from './smear.js';
import { LoaPanel } from './loa.js';
import { StopmoPanel } from './stopmo.js';

const $ = (id) => document.getElementById(id);

export const studio = {
  stats: { smear: [], smearAll: [], loa: [], loaAll: [], errors: [] },
  info: null,
  file: 0,
  clip: '',
  tab: 'smear',
  playing: false,
  busy: 0,
};
window.studio = studio;

export function showError(message) {
  const e = $('error');
  if (!message) { e.hidden = true; return; }
  e.textContent = message;
  e.hidden = false;
  studio.stats.errors.push(message);
}
studio.showError = showError;

export function status(text) { $('status').textContent = text; }
studio.status = status;

async function main() {
  studio.info = await getJSON('/api/info');
  const view = new Viewport($('gl'));
  studio.view = view;
  const fileSel = $('file');
  for (const f of studio.info.files) fileSel.add(new Option(f.name, f.index));

  studio.timeline = { frames: 1, fps: 24 };
  studio.setTimeline = (frames, fps) => {
    studio.timeline = { frames, fps };
    $('frame').max = Math.max(0, frames - 1);
    if (view.frameIndex >= frames) setFrame(frames - 1);
    updateLabel();
  };
  studio.frame = 0;
  const updateLabel = () => { $('frame-label').textContent = `${studio.frame} / ${studio.timeline.frames - 1}`; };
  const setFrame = (f) => {
    studio.frame = Math.max(0, Math.min(Math.round(f), studio.timeline.frames - 1));
    $('frame').value = studio.frame;
    updateLabel();
    for (const p of panels) if (p.active) p.onFrame(studio.frame);
  };
  studio.setFrame = setFrame;
  $('frame').addEventListener('input', (e) => setFrame(Number(e.target.value)));
  $('play').addEventListener('click', () => { studio.playing = !studio.playing; $('play').textContent = studio.playing ? '❚❚' : '▶'; });

  studio.loadClip = async (file, clip) => {
    const t0 = performance.now();
    const { header, buffers } = await getPack(`/api/scene?file=${file}&clip=${encodeURIComponent(clip)}`);
    status(`${header.name}: ${header.frames} frames, ${header.vertices} vertices (${Math.round(performance.now() - t0)} ms)`);
    return { triangles: buffers.triangles, positions: buffers.positions, frames: header.frames, vertices: header.vertices, fps: header.fps, name: header.name, height: header.bbox[1][1] - header.bbox[0][1] };
  };

  const clipSel = $('clip');
  const fillClips = () => {
    clipSel.innerHTML = '';
    const clips = studio.info.files[studio.file].clips;
    for (const c of clips) clipSel.add(new Option(c, c));
    const dance = clips.indexOf('Dance');
    studio.clip = clips.length ? clips[dance >= 0 ? dance : 0] : '';
    clipSel.value = studio.clip;
  };
  fillClips();

  const smear = new SmearPanel(studio);
  const loa = new LoaPanel(studio);
  const stopmo = new StopmoPanel(studio);
  const panels = [smear, loa, stopmo];
  studio.panels = { smear, loa, stopmo };

  const activate = async (name) => {
    studio.tab = name;
    for (const b of document.querySelectorAll('aside nav button')) b.classList.toggle('active', b.dataset.tab === name);
    for (const p of panels) { $(`tab-${p.name}`).hidden = p.name !== name; if (p.active && p.name !== name) p.deactivate(); }
    const p = studio.panels[name];
    try { showError(''); await p.activate(); } catch (e) { showError(e.message); }
  };
  studio.activate = activate;
  for (const b of document.querySelectorAll('aside nav button')) b.addEventListener('click', () => activate(b.dataset.tab));
  fileSel.addEventListener('change', async () => { studio.file = Number(fileSel.value); fillClips(); await studio.panels[studio.tab].reload(); });
  clipSel.addEventListener('change', async () => { studio.clip = clipSel.value; await studio.panels[studio.tab].reload(); });

  let last = performance.now(), acc = 0, fpsFrames = 0, fpsTime = 0;
  const fpsLabel = $('fps-label');
  const loop = (now) => {
    const dt = (now - last) / 1000; last = now;
    fpsFrames++; fpsTime += dt;
    if (fpsTime > 0.5) {
      // Written only when it reads differently: a new text is laid out, painted and
      // composited again (on the CPU with software GL), twice a second on an idle page.
      const text = `${Math.round(fpsFrames / fpsTime)} fps draw${view.software ? ' (software GL: plain shading)' : ''} · ${studio.timeline.fps} fps clip`;
      if (fpsLabel.textContent !== text) fpsLabel.textContent = text;
      fpsFrames = 0; fpsTime = 0;
    }
    if (studio.playing) {
      acc += dt * studio.timeline.fps;
      if (acc >= 1) { const step = Math.floor(acc); acc -= step; setFrame((studio.frame + step) % studio.timeline.frames); }
    }
    // Render only when something changed: an idle page leaves the CPU to the server (software
    // GL renders on the CPU).
    if (view.controls.update() || view.dirty) view.render();
    for (const p of panels) if (p.active && p.draw) p.draw();
    requestAnimationFrame(loop);
  };
  requestAnimationFrame(loop);
  await activate('smear');
  studio.ready = true;
}

window.addEventListener('error', (e) => showError(e.message));
window.addEventListener('unhandledrejection', (e) => showError(String(e.reason && e.reason.message || e.reason)));
main().catch((e) => showError(e.message));
