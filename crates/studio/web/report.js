// The panels' reports as sentences a person reads: which objects smear and how much, how
// closely the character follows the line, what the segmentation cut — every number with its
// unit, warnings with what to change. Lengths are in the file's units (glTF says metres, but
// characters come in any scale), so each is also given as a share of the model's height.

/** Three significant digits. */
const sig = (x) => Number(x.toPrecision(3)).toLocaleString('en', { maximumFractionDigits: 6 });

/** A length in scene units, with its share of `height` (the model's height) when known. */
export function length(x, height) {
  const share = height > 0 ? ` (${sig((x / height) * 100)} % of the model's height)` : '';
  return `${sig(x)} units${share}`;
}

/** A count with thousands separators. */
const n = (x) => Number(x).toLocaleString('en');

/** A count with its noun, singular or plural. */
const count = (x, noun, plural = `${noun}s`) => `${n(x)} ${x === 1 ? noun : plural}`;

/** Displacements below this share of the model's height are no visible smear. */
const STILL = 1e-4;

/** Objects listed one by one at most; the rest are counted. */
const LISTED = 6;

/** What the style does to one object of a `smear::StylizeReport`, or null when nothing. */
function smearOf(o, warnings, height) {
  const parts = [];
  if (o.elongation_max !== undefined && o.elongation_max > STILL * (height || 1)) {
    parts.push(`stretches up to ${length(o.elongation_max, height)}, ${sig(o.elongation_mean || 0)} units on average`);
  }
  if (o.multiples) {
    const shown = o.multiples_visible_vertices || 0;
    parts.push(`${count(o.multiples, 'multiple')} ${(o.multiples_spacing || 0).toFixed(2)} frames apart` + (shown ? '' : ' (never visible)'));
    if (!shown) warnings.push(`${o.name}: its multiples never show — lower the speed threshold of their opacity expression in the TOML.`);
  }
  if (o.lines_max) parts.push(`up to ${count(o.lines_max, 'motion line')} per frame`);
  if (o.squashed_frames) parts.push(`squashed on ${count(o.squashed_frames, 'frame')}`);
  if (o.subdivision_max_stretch) parts.push(`edges up to ${o.subdivision_max_stretch.toFixed(2)}× their rest length`);
  return parts.length ? parts.join(', ') : null;
}

/**
 * The smear report (`smear::StylizeReport`) of the whole clip: the objects that smear, most
 * first, the ones that do not, then warnings with the fix.
 */
export function smearSummary(report, frames, height) {
  const warnings = [];
  const rows = report.objects.map((o) => ({ o, text: smearOf(o, warnings, height) }));
  const smeared = rows.filter((r) => r.text).sort((a, b) => (b.o.elongation_max || 0) - (a.o.elongation_max || 0));
  const still = rows.filter((r) => !r.text).map((r) => r.o.name);
  const lines = [`${count(smeared.length, 'object')} of ${report.objects.length} smear over ${count(frames, 'frame')}:`];
  for (const r of smeared.slice(0, LISTED)) lines.push(`• ${r.o.name}: ${r.text}`);
  if (smeared.length > LISTED) lines.push(`• and ${smeared.length - LISTED} more`);
  if (still.length) lines.push(`not smeared (too slow for this style): ${still.join(', ')}`);
  const wantsLines = report.objects.some((o) => o.lines_max !== undefined);
  if (wantsLines && !report.objects.some((o) => o.lines_max)) warnings.push('no motion line is drawn: lower the lines\' speed threshold (vmin) or raise their length in the TOML.');
  if (!smeared.length) warnings.push('nothing smears: raise β max, or lower the speed threshold of the preset\'s expressions in the TOML.');
  return lines.concat(warnings.map((w) => `⚠ ${w}`)).join('\n');
}

/** The loa answer's header: how closely the character follows the line, and warnings. */
export function loaSummary(h) {
  const r = h.report;
  const pct = (x) => `${(x * 100).toFixed(1)} %`;
  const worst = r.line_distance_worst || { distance: 0, joint: '—', frame: 0 };
  const lines = [
    `line over ${count(h.line.frames, 'frame')} from ${count(h.line.keystroke_frames.length, 'keystroke')}; character ${count(h.motion.frames, 'frame')} at ${h.motion.fps} fps`,
    `the body follows the line within ${pct(r.line_distance_mean)} of its length on average (95 % of the points within ${pct(r.line_distance_p95)}; farthest: ${worst.joint} at frame ${worst.frame}, ${pct(worst.distance)})`,
    `largest joint turn between two frames: ${(r.max_rotation_step * 180 / Math.PI).toFixed(1)}°; body height ${sig(r.height)} units`,
  ];
  const warnings = [...h.warnings];
  if (worst.distance > 0.25) warnings.push('the body is far from the line on some frames: draw the stroke closer to the character, or raise the keystroke\'s stiffness.');
  if (r.max_rotation_step > Math.PI / 4) warnings.push('a joint turns more than 45° between two frames: space the keystrokes further apart or raise the damping.');
  return lines.concat(warnings.map((w) => `⚠ ${w}`)).join('\n');
}

/** A segmentation summary (`stopmo::SegmentSummary`): the parts, the seams, the smoothing. */
export function segmentSummary(s, height) {
  const lines = [`${count(s.parts.length, 'part')} over ${count(s.frames, 'frame')}:`];
  for (const p of s.parts) lines.push(`• ${p.name}: ${n(p.vertices)} vertices, ${count(p.triangles, 'triangle')}`);
  lines.push(`seams ${length(s.cut_length, height)} long (${n(s.seam_vertices)} vertices), cut with γ = ${s.gamma}`);
  const h = s.homogenization;
  if (h) lines.push(`seam smoothing moved vertices by ${sig(h.mean_change)} units on average, at most ${length(h.max_change, height)}`);
  if (s.parts.some((p) => p.triangles === 0)) lines.push('⚠ a part has no triangle: place its seed on the face, away from the other parts\' seeds.');
  return lines.join('\n');
}
