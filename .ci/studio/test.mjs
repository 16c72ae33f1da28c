// Browser test of toonkit studio: Debian's chromium (headless) driven by playwright-core
// against a running `toonkit studio` (URL in argv[2]); screenshots into argv[3].
// Prints the latency figures and a closing "N passed, N failed" line; exit 1 on any failure.
import { chromium } from 'playwright-core';
import { mkdirSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { inflateRawSync } from 'node:zlib';

const url = process.argv[2];
const shots = process.argv[3] || 'target/studio-shots';
mkdirSync(shots, { recursive: true });
let passed = 0, failed = 0;
const check = (name, ok, detail = '') => {
  if (ok) passed++; else failed++;
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}${detail ? ': ' + detail : ''}`);
};
const median = (xs) => { const s = [...xs].sort((a, b) => a - b); return s[Math.floor(s.length / 2)]; };

/** The entries of a zip (stored or deflated) by name, read through its central directory. */
function unzip(buf) {
  const entries = {};
  let end = buf.length - 22;
  while (end > 0 && buf.readUInt32LE(end) !== 0x06054b50) end--;
  let at = buf.readUInt32LE(end + 16);
  for (let i = buf.readUInt16LE(end + 10); i > 0; i--) {
    const method = buf.readUInt16LE(at + 10), size = buf.readUInt32LE(at + 20);
    const nameLen = buf.readUInt16LE(at + 28);
    const name = buf.toString('utf8', at + 46, at + 46 + nameLen);
    const local = buf.readUInt32LE(at + 42);
    const start = local + 30 + buf.readUInt16LE(local + 26) + buf.readUInt16LE(local + 28);
    const data = buf.subarray(start, start + size);
    entries[name] = method === 8 ? inflateRawSync(data) : data;
    at += 46 + nameLen + buf.readUInt16LE(at + 30) + buf.readUInt16LE(at + 32);
  }
  return entries;
}

/** The exported library as a print shop gets it: with the magnet and 3MF asked for in the
 * panel, every piece has a pocket and a plate in report.json, each part's mount is a whole
 * binary STL, and library.3mf holds one named object per piece in millimetres. */
function exportedWithMagnets(folder, written) {
  const report = JSON.parse(readFileSync(join(folder, 'report.json'), 'utf8'));
  const p = report.printing || {};
  const pieces = p.pieces || [];
  check('the export carries the panel\'s magnet and print format', p.magnet && p.magnet.diameter_mm === 3 && p.magnet.height_mm === 2 && p.print_format === 'stl,3mf' && p.clearance_mm > 0, JSON.stringify({ magnet: p.magnet, format: p.print_format }));
  check('every exported piece has a magnet pocket and a plate', pieces.length > 0 && pieces.every((q) => q.magnet && q.plate >= 1 && q.volume_mm3 > 0 && q.frames.length > 0) && (p.parts || []).every((q) => q.magnet_pocket), `${pieces.length} pieces`);
  const mounts = (p.parts || []).map((q) => `stopmo_library/pieces/${q.name}_back.stl`);
  const whole = mounts.every((m) => {
    if (!written.includes(m)) return false;
    const stl = readFileSync(join(folder, '..', m));
    return stl.length === 84 + 50 * stl.readUInt32LE(80) && stl.readUInt32LE(80) > 0;
  });
  check('each part\'s mount with the matching pocket is exported', whole, mounts.join(', '));
  let objects = [];
  let unit = '';
  if (written.includes('stopmo_library/library.3mf')) {
    const model = unzip(readFileSync(join(folder, 'library.3mf')))['3D/3dmodel.model'];
    const xml = model ? model.toString('utf8') : '';
    unit = (xml.match(/<model[^>]*unit="([a-z]+)"/) || [])[1] || '';
    objects = [...xml.matchAll(/<object [^>]*>/g)].map((m) => (m[0].match(/ name="([^"]+)"/) || [])[1]);
  }
  const ids = pieces.map((q) => q.id).sort();
  check('library.3mf holds one object per piece, named by its ID, in millimetres', unit === 'millimeter' && JSON.stringify([...objects].sort()) === JSON.stringify(ids), `${unit}: ${objects.join(', ')} vs ${ids.join(', ')}`);
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
    '--use-gl=angle', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  // launch() gives every run a fresh temporary user-data-dir.
});
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 760 } });
  const consoleErrors = [];
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(e.message));
  await page.goto(url);
  await page.waitForFunction(() => window.studio && window.studio.ready && window.studio.stats.smearAll.length > 0, null, { timeout: 120000 });

  // Canvas not blank: pixels differ from the background somewhere.
  // Pixels and screenshots of the settled view: on a software renderer a change is drawn at
  // the interactive scale, then again at full resolution (web/viewport.js).
  const settled = () => page.waitForFunction(() => window.studio && window.studio.view && window.studio.view.settled, null, { timeout: 10000 });
  const shot = async (path) => { await settled(); await page.screenshot({ path }); };
  const readPixels = () => page.evaluate(() => {
    const src = document.getElementById('gl');
    const c = document.createElement('canvas');
    c.width = src.width; c.height = src.height;
    const ctx = c.getContext('2d');
    ctx.drawImage(src, 0, 0);
    return Array.from(ctx.getImageData(0, 0, c.width, c.height).data);
  });
  const pixels = async () => { await settled(); return readPixels(); };
  // The server is the binary alone in an empty folder (.ci/studio.sh): three.js came from it.
  // Read until the character shows (at most 10 s): the panel's text may still be laying out,
  // and a canvas being resized is blank until it is drawn again.
  let before, width, height, lit, x0, x1, y0, y1, centred;
  for (const t0 = Date.now(); ;) {
    before = await pixels();
    const bg = [before[0], before[1], before[2]];
    width = await page.evaluate(() => document.getElementById('gl').width);
    lit = 0; x0 = Infinity; x1 = -1; y0 = Infinity; y1 = -1;
    for (let i = 0; i < before.length; i += 4) {
      if (Math.abs(before[i] - bg[0]) + Math.abs(before[i + 1] - bg[1]) + Math.abs(before[i + 2] - bg[2]) <= 30) continue;
      lit++;
      const x = (i / 4) % width, y = Math.floor(i / 4 / width);
      x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
    }
    height = before.length / 4 / width;
    centred = x0 < width / 2 && x1 > width / 2 && y0 < height / 2 && y1 > height / 2;
    if ((lit > 2000 && centred) || Date.now() - t0 > 10000) break;
    await page.waitForTimeout(200);
  }
  check('the viewport shows the character (three.js embedded in the binary)', lit > 2000 && centred, `${lit} pixels differ from the background, in x ${x0}–${x1}, y ${y0}–${y1} of ${width}×${height}`);
  // The viewport's own vertex normals (web/normals.js, per frame shown) against three.js's
  // computeVertexNormals on the same geometry: the same float32 values.
  const normals = await page.evaluate(async () => {
    const { computeVertexNormals } = await import('/normals.js');
    const g = window.studio.view.mesh.geometry;
    const ours = g.clone(), theirs = g.clone();
    computeVertexNormals(ours);
    theirs.deleteAttribute('normal');
    theirs.computeVertexNormals();
    const a = ours.attributes.normal.array, b = theirs.attributes.normal.array;
    let differ = 0;
    for (let i = 0; i < a.length; i++) if (!Object.is(a[i], b[i])) differ++;
    return { values: a.length, differ, vertices: g.attributes.position.count };
  });
  check('the viewport\'s vertex normals equal three.js computeVertexNormals bit for bit', normals.values === normals.vertices * 3 && normals.values > 0 && normals.differ === 0, JSON.stringify(normals));

  // β max slider: pixels change; latency slider → geometry drawn.
  const setSlider = (v) => page.evaluate((v) => {
    const s = document.getElementById('beta-max');
    s.value = v; s.dispatchEvent(new Event('input'));
  }, v);
  await page.evaluate(() => { window.studio.setFrame(40); });
  await page.waitForTimeout(200);
  const n0 = await page.evaluate(() => window.studio.stats.smear.length);
  const atRest = await pixels();
  await setSlider(20);
  await page.waitForFunction((n) => window.studio.stats.smear.length > n, n0, { timeout: 60000 });
  await page.waitForTimeout(100);
  const stretched = await pixels();
  let changed = 0;
  for (let i = 0; i < atRest.length; i += 4) if (Math.abs(atRest[i] - stretched[i]) + Math.abs(atRest[i + 1] - stretched[i + 1]) + Math.abs(atRest[i + 2] - stretched[i + 2]) > 30) changed++;
  check('moving the β-max slider changes the rendered pixels', changed > 200, `${changed} pixels changed`);
  await shot(join(shots, 'smear.png'));
  // Latency: ten slider moves, each waited for until the whole clip has arrived too (a user
  // moving the slider and looking). Measured in the page: from the input event to the render
  // (in requestAnimationFrame) after the current frame's new buffers are uploaded.
  const counts = (what) => page.evaluate((w) => window.studio.stats[w].length, what);
  const lat = [], latAll = [];
  for (let k = 0; k < 10; k++) {
    const n = await counts('smear'), nAll = await counts('smearAll');
    await setSlider(2 + k * 1.5);
    await page.waitForFunction((n) => window.studio.stats.smear.length > n, n, { timeout: 60000 });
    await page.waitForFunction((n) => window.studio.stats.smearAll.length > n, nAll, { timeout: 60000 });
    lat.push(await page.evaluate(() => window.studio.stats.smear.at(-1)));
    latAll.push(await page.evaluate(() => window.studio.stats.smearAll.at(-1)));
  }
  // On a software renderer the frames drawn while the slider moves are drawn at the
  // interactive scale, and the view settles to full resolution (web/viewport.js). What a
  // change looks like while it is drawn (not asserted: the settle may come first):
  await page.screenshot({ path: join(shots, 'smear-interactive.png') });
  await settled();
  const sharp = await page.evaluate(() => {
    const v = window.studio.view, c = document.getElementById('gl');
    return { software: v.software, scale: v.scale, width: c.width, css: c.clientWidth };
  });
  const scales = lat.map((l) => l.scale);
  check('changes are drawn at the interactive scale on software GL, the still view at full resolution',
    (sharp.software ? scales.every((x) => x === 0.5) : scales.every((x) => x === 1)) && sharp.scale === 1 && sharp.width === sharp.css,
    `${JSON.stringify(sharp)}, drawn at ${JSON.stringify([...new Set(scales)])}`);
  // Figures printed, not asserted (a shared CI machine's load moves them; targets from the
  // studio's issue): slider → current frame ≤ 16 ms, slider → every frame ≤ 50 ms.
  const smearMs = median(lat.map((l) => l.ms));
  console.log(`latency smear slider → current frame's new geometry drawn (robot Dance, 7,214 vertices): median ${smearMs.toFixed(1)} ms of ${lat.length}, max ${Math.max(...lat.map((l) => l.ms)).toFixed(1)} ms, server median ${median(lat.map((l) => l.server_ms)).toFixed(1)} ms, ${(median(lat.map((l) => l.bytes)) / 1024).toFixed(0)} KiB; target 16 ms`);
  const part = (k) => median(lat.map((l) => l[k])).toFixed(1);
  console.log(`  of which: request until answer ${part('fetch_ms')} ms, buffers into the scene ${part('apply_ms')} ms, until the next render is done ${part('draw_ms')} ms (one render of the page ${part('render_ms')} ms: software GL)`);
  console.log(`latency smear slider → all 81 frames drawn: median ${median(latAll.map((l) => l.ms)).toFixed(1)} ms of ${latAll.length}, server median ${median(latAll.map((l) => l.server_ms)).toFixed(1)} ms, ${(median(latAll.map((l) => l.bytes)) / 1048576).toFixed(2)} MiB; target 50 ms`);
  const partAll = (k) => median(latAll.map((l) => l[k])).toFixed(1);
  console.log(`  of which: request left ${partAll('sent_ms')} ms, its headers ${partAll('headers_ms')} ms, answer ${partAll('fetch_ms')} ms, laid over the clip and into the scene ${partAll('apply_ms')} ms, until the next render is done ${partAll('draw_ms')} ms; drawn again ${latAll.filter((l) => l.redrawn).length} of ${latAll.length} times (the frame on screen already showed the new style)`);
  const whole = await page.evaluate(() => { const p = window.studio.panels.smear; return { body: p.body.length, frames: p.anim.frames, vertices: p.anim.vertices }; });
  // The quantized answer (crates/studio/src/api/changes.rs) against the core's float32 body.
  const quant = await page.evaluate(async () => {
    const s = window.studio, p = s.panels.smear;
    const r = await fetch('/api/smear/stylize', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ file: s.file, clip: s.clip, style: p.style }) });
    const m = await r.arrayBuffer(), view = new DataView(m), len = view.getUint32(0, true);
    const head = JSON.parse(new TextDecoder().decode(new Uint8Array(m, 4, len)));
    const b = head.buffers.find((x) => x.name === 'body');
    const exact = new Float32Array(m, 4 + len + b.offset, b.count), input = p.anim.positions;
    let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < input.length; i++) { lo[i % 3] = Math.min(lo[i % 3], input[i]); hi[i % 3] = Math.max(hi[i % 3], input[i]); }
    const diag = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    let worst = 0;
    for (let i = 0; i < exact.length; i++) worst = Math.max(worst, Math.abs(exact[i] - p.body[i]));
    return { worst, diag, rel: worst / diag, floats: exact.length };
  });
  check('the whole clip drawn matches the core\'s body within 1e-5 of the diagonal', quant.floats === 81 * whole.vertices * 3 && quant.rel <= 1e-5, JSON.stringify(quant));
  check('every slider move brings the whole clip (81 frames × every vertex)', latAll.every((l) => l.frames === 81) && whole.frames === 81 && whole.body === 81 * whole.vertices * 3, `${JSON.stringify(latAll.map((l) => l.frames))}; body ${whole.body} floats`);
  // The panel's report of the whole clip in sight (docs/studio.png).
  await page.evaluate(() => document.getElementById('smear-report').scrollIntoView());
  await shot(join(shots, 'smear-report.png'));
  await page.evaluate(() => { const c = document.getElementById('show-offsets'); c.checked = true; c.dispatchEvent(new Event('change')); });
  await page.waitForTimeout(1500);
  await shot(join(shots, 'smear-offsets.png'));

  // --- smear keyframes and weight-group picker (#18) ---
  {
    await page.evaluate(() => { const c = document.getElementById('show-offsets'); c.checked = false; c.dispatchEvent(new Event('change')); });
    const smearDone = async (fn, ...args) => {
      const n = await counts('smear'), nAll = await counts('smearAll');
      await page.evaluate(fn, ...args);
      await page.waitForFunction((n) => window.studio.stats.smear.length > n, n, { timeout: 60000 });
      await page.waitForFunction((n) => window.studio.stats.smearAll.length > n, nAll, { timeout: 120000 });
    };
    // β max 0 keyed at frame 10, 20 keyed at frame 40 (the second a keyed field's edit).
    await smearDone(() => { window.studio.setFrame(10); const s = document.getElementById('beta-max'); s.value = 0; s.dispatchEvent(new Event('input')); });
    await smearDone(() => document.querySelector('button.key[data-key="beta-max"]').click());
    await smearDone(() => { window.studio.setFrame(40); const s = document.getElementById('beta-max'); s.value = 20; s.dispatchEvent(new Event('input')); });
    const markers = await page.evaluate(() => [...document.querySelectorAll('#key-track .key-marker[data-param="beta-max"]')].map((m) => Number(m.dataset.frame)));
    check('two β-max keys show two markers under the timeline at frames 10 and 40', JSON.stringify(markers) === '[10,40]', JSON.stringify(markers));
    const toml = await page.evaluate(() => document.getElementById('style-toml').value);
    check('the style TOML carries the keys', /by = \[\[10\.0, 0\.0\], \[40\.0, 20\.0\]\]/.test(toml), toml.split('\n').filter((l) => l.includes('by')).join(' | '));
    // The drawn geometry (the viewport mesh's positions) against the input at the two keys
    // and halfway: β = 0 is the input, β = 20 and the interpolated β = 10 stretch.
    const drawnDiff = (f) => page.evaluate((f) => {
      const s = window.studio, p = s.panels.smear;
      s.setFrame(f);
      const pos = s.view.mesh.geometry.attributes.position.array;
      const n = p.anim.vertices * 3, input = p.anim.positions.subarray(f * n, (f + 1) * n);
      let d = 0;
      for (let i = 0; i < n; i++) d = Math.max(d, Math.abs(pos[i] - input[i]));
      return d;
    }, f);
    const [d10, d25, d40] = [await drawnDiff(10), await drawnDiff(25), await drawnDiff(40)];
    check('keyed β: frame 10 (β = 0) draws the input, frames 25 (β = 10) and 40 (β = 20) are stretched', d10 < 1e-5 && d40 > 1e-3 && d25 > 1e-4, `max |Δ| ${d10.toExponential(2)}, ${d25.toExponential(2)}, ${d40.toExponential(2)}`);
    const field = await page.evaluate(() => { window.studio.setFrame(25); return Number(document.getElementById('beta-max').value); });
    check('between keys the β field shows the interpolated value', Math.abs(field - 10) < 1e-3, String(field));
    // A marker click jumps to its frame.
    await page.click('#key-track .key-marker[data-param="beta-max"][data-frame="10"]');
    check('clicking a marker jumps to its frame', await page.evaluate(() => window.studio.frame) === 10);
    // Weight group: the right shoulder and below (the robot's bones, SMEAR Fig. 15b).
    const options = await page.evaluate(() => [...document.getElementById('weight-source').options].map((o) => o.text));
    check('the weight-group picker lists the robot\'s bones', options.includes('bone ShoulderR and below') && options.length > 20, `${options.length} options`);
    await page.evaluate(() => window.studio.setFrame(40));
    const before40 = await page.evaluate(() => Array.from(window.studio.panels.smear.body.subarray(40 * window.studio.panels.smear.anim.vertices * 3, 41 * window.studio.panels.smear.anim.vertices * 3)));
    await smearDone(() => {
      const sel = document.getElementById('weight-source');
      sel.value = [...sel.options].find((o) => o.text === 'bone ShoulderR and below').value;
      sel.dispatchEvent(new Event('change'));
    });
    await page.waitForFunction(() => window.studio.view.vertexColors, null, { timeout: 30000 });
    const overlay = await page.evaluate(() => {
      const c = window.studio.view.mesh.geometry.attributes.color.array;
      let hot = 0, grey = 0;
      for (let i = 0; i < c.length; i += 3) { if (c[i] > 0.95 && c[i + 2] < 0.2) hot++; else if (Math.abs(c[i] - 0.78) < 0.01) grey++; }
      return { hot, grey };
    });
    check('the weight overlay colours the arm orange and the rest grey', overlay.hot > 100 && overlay.grey > overlay.hot, JSON.stringify(overlay));
    const picked = await page.evaluate(() => ({ weights: window.studio.panels.smear.style.weights, toml: document.getElementById('style-toml').value }));
    check('picking a group sets the style\'s weights', picked.weights && picked.weights.group && picked.weights.group[0] === 'ShoulderR' && picked.toml.includes('ShoulderR'), JSON.stringify(picked.weights));
    const after40 = await page.evaluate(() => Array.from(window.studio.panels.smear.body.subarray(40 * window.studio.panels.smear.anim.vertices * 3, 41 * window.studio.panels.smear.anim.vertices * 3)));
    let moved = 0;
    for (let i = 0; i < after40.length; i++) if (Math.abs(after40[i] - before40[i]) > 1e-4) moved++;
    check('the weight group restyles the smear (vertices off the arm stop stretching)', moved > 300, `${moved} coordinates changed at frame 40`);
    // The picture at frame 25 (β = 10 between the keys: the arm stretches), the generated
    // "all parameters" block open.
    await page.evaluate(() => { document.getElementById('all-params-box').open = true; window.studio.setFrame(25); });
    await page.waitForTimeout(300);
    await shot(join(shots, 'smear-keyframes.png'));
    // Right-click deletes a key.
    await page.click('#key-track .key-marker[data-param="beta-max"][data-frame="40"]', { button: 'right' });
    const left = await page.evaluate(() => [...document.querySelectorAll('#key-track .key-marker[data-param="beta-max"]')].map((m) => Number(m.dataset.frame)));
    check('right-clicking a marker deletes its key', JSON.stringify(left) === '[10]', JSON.stringify(left));
    await page.waitForTimeout(500);

    // The "all parameters" block, generated from the style: Fig. 16's preset (elongation,
    // multiples, lines) lists every leaf; τ_max of its line-length expression (SMEAR Eq. 13,
    // `length = step(speed - vmin) * tau * delta`), not a quick field, keyed 0 at frame 10 and
    // 10 at frame 40: τ = 0 draws no line at frame 10, frame 40 keeps the unkeyed lines.
    await smearDone(() => { const p = document.getElementById('preset'); p.value = 'fig16_combined'; p.dispatchEvent(new Event('change')); });
    const listed = await page.evaluate(() => [...document.querySelectorAll('#all-params input')].map((i) => i.id));
    const tau = 'p:lines.length.params.tau';
    check('the generated block lists every style parameter (≥ 10, τ of the line length among them)', listed.length >= 10 && listed.includes(tau) && listed.includes('p:multiples.overlap') && listed.includes('p:lines.color.0'), `${listed.length} fields`);
    const lineVerts = (f) => page.evaluate((f) => window.studio.panels.smear.lines.reduce((n, set) => n + set[f].positions.length / 3, 0), f);
    const [base10, base40] = [await lineVerts(10), await lineVerts(40)];
    await smearDone((id) => { window.studio.setFrame(10); document.getElementById(id).value = 0; document.querySelector(`button.key[data-key="${id}"]`).click(); }, tau);
    await smearDone((id) => { window.studio.setFrame(40); const i = document.getElementById(id); i.value = 10; i.dispatchEvent(new Event('change', { bubbles: true })); }, tau);
    const tauMarkers = await page.evaluate((id) => [...document.querySelectorAll(`#key-track .key-marker[data-param="${id}"]`)].map((m) => Number(m.dataset.frame)), tau);
    check('two τ keys show two markers under the timeline at frames 10 and 40', JSON.stringify(tauMarkers) === '[10,40]', JSON.stringify(tauMarkers));
    const tauToml = await page.evaluate(() => document.getElementById('style-toml').value);
    check('the style TOML carries the τ keys', /tau = \[\[10\.0, 0\.0\], \[40\.0, 10\.0\]\]/.test(tauToml), tauToml.split('\n').filter((l) => l.includes('tau')).join(' | '));
    const [k10, k40] = [await lineVerts(10), await lineVerts(40)];
    check('keyed τ: frame 10 (τ = 0) draws no lines, frame 40 (τ = 10) the unkeyed lines', base10 > 0 && k10 === 0 && k40 === base40 && k40 > 0, `line vertices at 10 / 40: ${base10} / ${base40} unkeyed, ${k10} / ${k40} keyed`);
    const tauField = await page.evaluate((id) => { window.studio.setFrame(25); return Number(document.getElementById(id).value); }, tau);
    check('between keys the generated τ field shows the interpolated value', Math.abs(tauField - 5) < 1e-3, String(tauField));
    await page.evaluate(() => window.studio.setFrame(40));
    await page.waitForTimeout(300);
    await shot(join(shots, 'smear-params.png'));
  }

  // loa: three strokes at three frames by mouse.
  await page.evaluate(() => window.studio.activate('loa'));
  await page.waitForFunction(() => window.studio.panels.loa.view, null, { timeout: 60000 });
  const box = await page.locator('#overlay').boundingBox();
  const strokes = [[0, -0.12], [12, 0], [24, 0.12]];
  const drawn = [];
  for (const [frame, bend] of strokes) {
    await page.evaluate((f) => window.studio.setFrame(f), frame);
    const pts = [];
    for (let i = 0; i <= 24; i++) {
      const t = i / 24;
      pts.push([box.width * (0.5 + bend * Math.sin(Math.PI * t)), box.height * (0.25 + 0.5 * t)]);
    }
    drawn.push({ frame, pts });
    const n = await page.evaluate(() => window.studio.stats.loa.length);
    await page.mouse.move(box.x + pts[0][0], box.y + pts[0][1]);
    await page.mouse.down();
    for (const p of pts.slice(1)) await page.mouse.move(box.x + p[0], box.y + p[1]);
    await page.mouse.up();
    if (frame > 0) {
      await page.waitForFunction((n) => window.studio.stats.loa.length > n, n, { timeout: 120000 });
    }
  }
  const loaErr = await page.evaluate(() => document.getElementById('error').hidden ? '' : document.getElementById('error').textContent);
  check('three strokes give a line and a motion without error', loaErr === '', loaErr);
  const line = await page.evaluate(async () => (await fetch('/api/loa/line')).json());
  let worst = 0;
  for (const d of drawn) {
    const f = line.frames.find((x) => x.frame === d.frame);
    if (!f) { worst = Infinity; continue; }
    for (const p of d.pts) worst = Math.max(worst, Math.min(...f.points.map((q) => Math.hypot(p[0] - q[0], p[1] - q[1]))));
  }
  check('the line passes through the three strokes (API query)', worst < 0.05 * box.height, `farthest stroke point ${worst.toFixed(1)} px from the line`);
  // The core's positions of the motion (every frame × vertex), as exports write them.
  const corePositions = () => page.evaluate(async () => {
    const r = window.studio.panels.loa.result;
    const m = await (await fetch(`/api/loa/motion?version=${r.header.version}`)).arrayBuffer();
    const view = new DataView(m), len = view.getUint32(0, true);
    const head = JSON.parse(new TextDecoder().decode(new Uint8Array(m, 4, len)));
    const b = head.buffers.find((x) => x.name === 'positions');
    window.__core = new Float32Array(m, 4 + len + b.offset, b.count);
    return b.count;
  });
  await corePositions();
  const moved = await page.evaluate(() => {
    const r = window.studio.panels.loa.result, p = window.__core;
    const n = r.header.motion.vertices * 3, f = r.header.motion.frames;
    const a = p.subarray(0, n), b = p.subarray((f - 1) * n, f * n);
    let m = 0; for (let i = 0; i < n; i++) m = Math.max(m, Math.abs(a[i] - b[i]));
    return m;
  });
  check('the character moves', moved > 0.01, `largest vertex displacement ${moved.toFixed(3)}`);
  // The renderer skins the pose (SkinnedMesh): the vertices it draws at three frames (three.js
  // getVertexPosition, the shader's skinning on the CPU) against the core's skinned positions.
  const skinErr = await page.evaluate(() => {
    const s = window.studio, r = s.panels.loa.result, p = window.__core, v = s.view;
    const nv = r.header.motion.vertices, nf = r.header.motion.frames;
    let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < p.length; i++) { lo[i % 3] = Math.min(lo[i % 3], p[i]); hi[i % 3] = Math.max(hi[i % 3], p[i]); }
    const diag = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    if (!v.mesh.isSkinnedMesh) return { skinned: false, diag };
    const first = r.header.motion.first_frame, q = new v.mesh.position.constructor();
    let worst = 0;
    for (const f of [0, Math.floor(nf / 2), nf - 1]) {
      s.setFrame(first + f);
      for (let i = 0; i < nv; i++) {
        v.mesh.getVertexPosition(i, q);
        const o = (f * nv + i) * 3;
        worst = Math.max(worst, Math.hypot(q.x - p[o], q.y - p[o + 1], q.z - p[o + 2]));
      }
    }
    return { skinned: true, worst, diag, rel: worst / diag };
  });
  check('the drawn (renderer-skinned) vertices match the core\'s at three frames within 1e-4 of the diagonal', skinErr.skinned && skinErr.rel <= 1e-4, JSON.stringify(skinErr));
  await page.evaluate(() => window.studio.setFrame(6));
  await page.waitForTimeout(300);
  await shot(join(shots, 'loa.png'));
  // Latency: redraw the middle stroke five times.
  const loaAll = [];
  for (let k = 0; k < 5; k++) {
    await page.evaluate(() => window.studio.setFrame(12));
    const nAll = await counts('loaAll');
    const pts = drawn[1].pts.map(([x, y]) => [x + (k - 2) * 4, y]);
    await page.mouse.move(box.x + pts[0][0], box.y + pts[0][1]);
    await page.mouse.down();
    for (const p of pts.slice(1)) await page.mouse.move(box.x + p[0], box.y + p[1]);
    await page.mouse.up();
    await page.waitForFunction((n) => window.studio.stats.loaAll.length > n, nAll, { timeout: 120000 });
    loaAll.push(await page.evaluate(() => window.studio.stats.loaAll.at(-1)));
  }
  // Printed, not asserted (as above); target: stroke → whole motion drawn ≤ 60 ms.
  console.log(`latency new stroke → line + whole character motion drawn: median ${median(loaAll.map((l) => l.ms)).toFixed(1)} ms of ${loaAll.length}, max ${Math.max(...loaAll.map((l) => l.ms)).toFixed(1)} ms, server median ${median(loaAll.map((l) => l.server_ms)).toFixed(1)} ms, ${(median(loaAll.map((l) => l.bytes)) / 1048576).toFixed(2)} MiB; target 60 ms`);
  const partLoa = (k) => median(loaAll.map((l) => l[k])).toFixed(1);
  console.log(`  of which: request until answer ${partLoa('fetch_ms')} ms, into the scene ${partLoa('apply_ms')} ms, until the next render is done ${partLoa('draw_ms')} ms`);
  const motion = await page.evaluate(() => { const r = window.studio.panels.loa.result, m = r.header.motion; return { floats: (r.buffers['skin.world'] || []).length, nodes: m.skin && m.skin.nodes, frames: m.frames, vertices: m.vertices, drawn: window.studio.view.anim.frames }; });
  check('a stroke brings the whole motion in one answer (the pose of every frame)', motion.frames > 24 && motion.floats === motion.frames * motion.nodes * 16 && motion.drawn === motion.frames, JSON.stringify(motion));

  // stopmo: two seed clicks on the face + run → two parts.
  await page.evaluate(() => window.studio.activate('stopmo'));
  await page.waitForFunction(() => window.studio.panels.stopmo.anim && window.studio.panels.stopmo.anim.name === 'ict-face-talk.glb', null, { timeout: 120000 });
  await page.waitForTimeout(300);
  const gl = await page.locator('#gl').boundingBox();
  // Forehead and chin: scan up/down the middle column for the first/last hits.
  const hits = await page.evaluate(({ w, h }) => {
    const ys = [];
    for (let y = 0; y < h; y += 4) if (window.studio.view.pick(w / 2, y) !== -1) ys.push(y);
    return ys.length ? [ys[0] + (ys.at(-1) - ys[0]) * 0.15, ys[0] + (ys.at(-1) - ys[0]) * 0.85] : null;
  }, { w: gl.width, h: gl.height });
  check('the face is under the camera', hits !== null);
  if (hits) {
    await page.selectOption('#stopmo-part', '1');
    await page.mouse.click(gl.x + gl.width / 2, gl.y + hits[0]);
    await page.selectOption('#stopmo-part', '2');
    await page.mouse.click(gl.x + gl.width / 2, gl.y + hits[1]);
    const seeds = await page.evaluate(() => window.studio.panels.stopmo.seeds.map((s) => s.length));
    check('two seed clicks place two seeds', seeds[0] === 1 && seeds[1] === 1, JSON.stringify(seeds));
    await page.click('#stopmo-run');
    await page.waitForFunction(() => window.studio.panels.stopmo.result || !document.getElementById('error').hidden, null, { timeout: 600000 });
    const parts = await page.evaluate(() => {
      const r = window.studio.panels.stopmo.result;
      return r ? [...new Set(r.triangle_part)].length : 0;
    });
    check('run gives two parts', parts === 2, `${parts} parts`);
    await page.waitForTimeout(300);
    await shot(join(shots, 'stopmo.png'));

    // stopmo, later half: seams drawn; the size-vs-error curve (three small sizes); a click on
    // a point builds that library; the reconstruction plays beside the face with piece ids;
    // the library folder is exported.
    const stopmoError = () => page.evaluate(() => document.getElementById('error').hidden ? '' : document.getElementById('error').textContent);
    const seams = await page.evaluate(() => { const s = window.studio.panels.stopmo.seams; return s ? s.vertices.length / 6 : 0; });
    check('seams are drawn over the face', seams > 10, `${seams} segments`);
    const tCurve = Date.now();
    await page.fill('#stopmo-sizes', '1,2,3');
    await page.click('#stopmo-curve');
    await page.waitForFunction(() => document.querySelectorAll('#stopmo-chart circle').length > 0 || !document.getElementById('error').hidden, null, { timeout: 600000 });
    const points = await page.locator('#stopmo-chart circle').count();
    const labels = await page.locator('#stopmo-chart text').allTextContents();
    check('the size-vs-error chart shows its points and labelled axes', points === 3 && labels.some((t) => t.includes('pieces')) && labels.some((t) => t.includes('(mm)')), `${points} points; ${await stopmoError()}`);
    console.log(`stopmo size curve (3 sizes, ${parts} parts): ${((Date.now() - tCurve) / 1000).toFixed(1)} s`);
    if (points > 0) {
      // Printed as a studio mounts it: a 3×2 mm magnet in every piece (3.5 mm walls: a part
      // that hardly moves is as thick as its wall, and the pocket needs 2.15 mm and 1 mm in
      // front of it), STL and library.3mf.
      await page.fill('#stopmo-magnets', '3x2');
      await page.fill('#stopmo-thickness', '3.5');
      await page.selectOption('#stopmo-format', 'stl,3mf');
      const tBuild = Date.now();
      await page.click('#stopmo-chart circle[data-pieces="2"]');
      await page.waitForFunction(() => window.studio.panels.stopmo.recon || !document.getElementById('error').hidden, null, { timeout: 600000 });
      console.log(`stopmo build (2 pieces per part) and reconstruction: ${((Date.now() - tBuild) / 1000).toFixed(1)} s`);
      const recon = await page.evaluate(() => {
        const r = window.studio.panels.stopmo.recon;
        if (!r) return null;
        const ids = r.header.frame_ids;
        const other = ids.findIndex((f) => f.join() !== ids[0].join());
        return { vertices: r.header.vertices, offset: r.mesh.position.x, other };
      });
      check('clicking a point builds the library and its reconstruction appears beside the face', recon && recon.vertices > 0 && recon.offset > 0, JSON.stringify(recon) + ' ' + await stopmoError());
      if (recon && recon.other > 0) {
        await page.evaluate(() => window.studio.setFrame(0));
        const ids0 = await page.locator('#stopmo-ids').textContent();
        await page.evaluate((f) => window.studio.setFrame(f), recon.other);
        const ids1 = await page.locator('#stopmo-ids').textContent();
        check('the piece ids shown change between two frames', ids0 !== ids1 && ids0.includes('part1_') && ids1.includes('part2_'), `${ids0} → ${ids1}`);
      } else check('the piece ids shown change between two frames', false, 'every frame shows the same pieces');
      await page.click('#stopmo-export');
      await page.waitForFunction(() => window.studio.panels.stopmo.exported || !document.getElementById('error').hidden, null, { timeout: 300000 });
      const written = await page.evaluate(() => { const e = window.studio.panels.stopmo.exported; return e ? e.written : []; });
      check('the library folder is exported', written.includes('stopmo_library/assembly.csv') && written.some((f) => f.endsWith('.stl')), `${written.length} files ${await stopmoError()}`);
      const folder = await page.evaluate(() => (window.studio.panels.stopmo.exported || {}).folder);
      if (folder) exportedWithMagnets(folder, written);
      await page.waitForTimeout(300);
      await shot(join(shots, 'stopmo-library.png'));
      // Without printable solids: the same library, surfaces only, sooner.
      await page.uncheck('#stopmo-print');
      const tSurfaces = Date.now();
      await page.click('#stopmo-chart circle[data-pieces="2"]');
      await page.waitForFunction(() => (window.studio.panels.stopmo.built || {}).printed === false || !document.getElementById('error').hidden, null, { timeout: 300000 });
      console.log(`stopmo build (2 pieces per part) without solids: ${((Date.now() - tSurfaces) / 1000).toFixed(1)} s`);
      const surfaces = await page.locator('#stopmo-built').textContent();
      check('unticking printable solids builds the library as surfaces only', surfaces.includes('surfaces only'), `${surfaces} ${await stopmoError()}`);
    }
  }
  check('no console errors', consoleErrors.length === 0, consoleErrors.join(' | '));
  // The server's peak resident memory (the robot, the face, one library built).
  if (process.env.STUDIO_PID) {
    const status = readFileSync(`/proc/${process.env.STUDIO_PID}/status`, 'utf8');
    const kib = Number((status.match(/VmHWM:\s+(\d+)/) || [])[1]);
    console.log(`server peak RSS (VmHWM): ${(kib / 1024).toFixed(0)} MiB; target 400 MB`);
  }
  console.log(`screenshots in ${shots}`);
} catch (e) {
  failed++;
  console.log(`FAIL ${e.stack || e}`);
} finally {
  await browser.close();
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
