// Keyframes of the smear panel's numeric fields (SMEAR Section 5.1: "all stylization
// parameters may be keyframed"). A parameter is a number or keys [[frame, value], ...], as the
// style (and its TOML) writes it; the server's library interpolates linearly between keys and
// holds the first and last values. Keys show as markers under the timeline: click one to jump
// to its frame, right-click it to delete it.

const $ = (id) => document.getElementById(id);

/** Whether `p` is a keyed curve (not a constant). */
export const isCurve = (p) => Array.isArray(p);

/** Whether a JSON value has a keyed parameter's form, [[frame, value], ...] (one key or more). */
const isKeys = (x) => Array.isArray(x) && x.length > 0
  && x.every((k) => Array.isArray(k) && k.length === 2 && k.every((n) => typeof n === 'number'));

/** The value of `p` at `frame`, as `smear::Param::at` computes it (shown in the fields). */
export function paramAt(p, frame) {
  if (!isCurve(p)) return p;
  if (!p.length) return 0;
  if (frame <= p[0][0]) return p[0][1];
  const last = p[p.length - 1];
  if (frame >= last[0]) return last[1];
  const i = p.findIndex((k) => k[0] > frame);
  const [a, b] = [p[i - 1], p[i]];
  return a[1] + (b[1] - a[1]) * (frame - a[0]) / (b[0] - a[0]);
}

/** `p` with a key (frame, value) set: a constant becomes a one-key curve; keys stay sorted. */
export function setKey(p, frame, value) {
  const keys = isCurve(p) ? p.filter((k) => k[0] !== frame) : [];
  keys.push([frame, value]);
  return keys.sort((a, b) => a[0] - b[0]);
}

/** `p` without its key at `frame`; removing the last key leaves its value as a constant. */
export function deleteKey(p, frame) {
  if (!isCurve(p)) return p;
  const keys = p.filter((k) => k[0] !== frame);
  if (keys.length) return keys;
  return p.length ? p[0][1] : 0;
}

/** The elongation function's `scale` stage (β max of SMEAR Eq. 10). */
export function scaleStage(style) {
  const f = style.elongate && style.elongate.function;
  const stages = f && f.stages;
  return stages ? stages.find((s) => s.op === 'scale') : null;
}

const on = (section) => section && section.enabled !== false;

/** Sets a multiples count; both counts constant 0 turn the effect off. */
function setCount(s, which, p) {
  const m = { past: 1, future: 1, ...(s.multiples || { past: 0, future: 0 }), enabled: true, [which]: p };
  if (!isCurve(m.past) && !isCurve(m.future) && m.past + m.future === 0) delete s.multiples;
  else s.multiples = m;
}

/**
 * The keyable fields of the panel: the input's id, a label, a marker colour, and how to
 * read (`get`, null when absent) and write (`set`, a number or keys) the parameter in a style.
 */
export const KEYABLE = [
  {
    id: 'beta-max', label: 'β max', color: '#ffb74d',
    get: (s) => { const st = scaleStage(s); return st ? st.by : null; },
    set: (s, p) => {
      const st = scaleStage(s);
      if (st) st.by = p;
      else s.elongate = { ...(s.elongate || {}), function: { stages: [{ op: 'speed' }, { op: 'scale', by: p }] } };
    },
  },
  {
    id: 'mult-past', label: 'past copies', color: '#64b5f6',
    get: (s) => (on(s.multiples) ? (s.multiples.past ?? 1) : 0),
    set: (s, p) => setCount(s, 'past', p),
  },
  {
    id: 'mult-future', label: 'future copies', color: '#e57373',
    get: (s) => (on(s.multiples) ? (s.multiples.future ?? 1) : 0),
    set: (s, p) => setCount(s, 'future', p),
  },
  {
    id: 'line-count', label: 'motion lines', color: '#81c784',
    get: (s) => (on(s.lines) ? (s.lines.count ?? 40) : 0),
    set: (s, p) => {
      if (!isCurve(p) && p === 0) delete s.lines;
      else s.lines = { ...(s.lines || {}), enabled: true, count: p };
    },
  },
];

// Integer options of the style that are not `smear::Param`s (a curve there is refused).
const UNKEYED = new Set(['step', 'smooth', 'samples', 'sides', 'seed']);
const PALETTE = ['#ba68c8', '#4dd0e1', '#fff176', '#a1887f', '#f06292', '#aed581', '#7986cb', '#ff8a65'];

/** The value at `path` (keys and indices) in `style`, or null. */
const at = (style, path) => path.reduce((o, k) => (o === null || o === undefined ? null : o[k]), style) ?? null;

/**
 * The description of a generated field (id `p:` + its dotted path in the style), in the
 * KEYABLE form plus `kind` ('number' | 'bool' | 'text'), `keyed` (may carry keys) and
 * `integer`.
 */
function leaf(style, path, kind, row) {
  const name = path[path.length - 1];
  // A function stage is named by its op (`elongate.function.scale.by`), another index (a
  // colour channel) by [i].
  const parts = [];
  path.forEach((k, i) => {
    if (path[i - 1] === 'stages') parts[parts.length - 1] = at(style, path.slice(0, i + 1)).op || `stage[${k}]`;
    else if (typeof k === 'number') parts[parts.length - 1] += `[${k}]`;
    else parts.push(k);
  });
  const keyed = kind === 'number' && !UNKEYED.has(name);
  return {
    id: `p:${path.join('.')}`, label: parts.join('.'), color: PALETTE[row % PALETTE.length], kind, keyed,
    integer: UNKEYED.has(name),
    get: (s) => at(s, path),
    set: (s, p) => { const o = at(s, path.slice(0, -1)); if (o) o[name] = p; },
  };
}

/**
 * Every parameter of `style`, walked in its JSON: numbers and keyed curves (keyable unless an
 * integer option), booleans, and expression / group strings (shown read-only; the TOML
 * editor edits them). `op` names the stage and is not a field.
 */
export function styleParams(style) {
  const out = [];
  const walk = (v, path) => {
    if (v === null || v === undefined) return;
    const name = path[path.length - 1];
    if (typeof v === 'number' || isKeys(v)) out.push(leaf(style, path, 'number', out.length));
    else if (typeof v === 'boolean') out.push(leaf(style, path, 'bool', out.length));
    else if (typeof v === 'string') { if (name !== 'op') out.push(leaf(style, path, 'text', out.length)); }
    else if (Array.isArray(v) && v.length && v.every((x) => typeof x === 'string')) out.push(leaf(style, path, 'text', out.length));
    else if (Array.isArray(v)) v.forEach((x, i) => walk(x, [...path, i]));
    else if (typeof v === 'object') for (const k of Object.keys(v).sort()) walk(v[k], [...path, k]);
  };
  walk(style, []);
  return out;
}

/** The field `id`'s description: a quick field, or a generated one (`p:` + its path). */
export function keyable(id, style) {
  const quick = KEYABLE.find((d) => d.id === id);
  if (quick || !style) return quick;
  return styleParams(style).find((d) => d.id === id);
}

/**
 * Draws the key markers of `style` under the timeline's range input (one row per keyed
 * field) and marks the key buttons of the fields keyed at `frame`. `jump(frame)` and
 * `remove(id, frame)` are called on a click / right-click of a marker.
 */
export function drawKeys(style, frame, frames, { jump, remove }) {
  const track = $('key-track');
  track.replaceChildren();
  const range = $('frame').getBoundingClientRect();
  const base = track.getBoundingClientRect();
  // The range's thumb centre runs from half a thumb in from each end.
  const thumb = 8, span = Math.max(1, range.width - 2 * thumb);
  const x = (f) => range.left - base.left + thumb + span * (frames > 1 ? f / (frames - 1) : 0);
  let row = 0;
  // The quick fields, then the generated ones; a curve a quick field already shows (the same
  // array in the style) gets its buttons updated but no second row of markers.
  const shown = new Set();
  const all = [...KEYABLE, ...(style ? styleParams(style).filter((d) => d.keyed) : [])];
  for (const d of all) {
    const p = style ? d.get(style) : null;
    const button = document.querySelector(`button.key[data-key="${d.id}"]`);
    const keyedHere = isCurve(p) && p.some((k) => k[0] === frame);
    if (button) { button.classList.toggle('keyed', keyedHere); button.textContent = keyedHere ? '◆' : '◇'; }
    const unkey = document.querySelector(`button.unkey[data-key="${d.id}"]`);
    if (unkey) unkey.disabled = !keyedHere;
    if (!isCurve(p) || shown.has(p)) continue;
    shown.add(p);
    for (const [f, v] of p) {
      const m = document.createElement('button');
      m.className = 'key-marker';
      m.dataset.param = d.id;
      m.dataset.frame = f;
      m.style.left = `${x(f)}px`;
      m.style.top = `${row * 8}px`;
      m.style.background = d.color;
      m.title = `${d.label} = ${+Number(v).toFixed(3)} at frame ${f} (click: go there, right-click: delete)`;
      m.addEventListener('click', () => jump(f));
      m.addEventListener('contextmenu', (e) => { e.preventDefault(); remove(d.id, f); });
      track.append(m);
    }
    row++;
  }
  track.style.height = `${Math.max(1, row) * 8 + 2}px`;
  track.hidden = row === 0;
}
