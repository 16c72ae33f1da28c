// Keyframes of the smear panel's numeric fields (SMEAR Section 5.1: "all stylization
// parameters may be keyframed"). A parameter is a number or keys [[frame, value], ...], as the
// style (and its TOML) writes it; the server's library interpolates linearly between keys and
// holds the first and last values. Keys show as markers under the timeline: click one to jump
// to its frame, right-click it to delete it.

const $ = (id) => document.getElementById(id);

/** Whether `p` is a keyed curve (not a constant). */
export const isCurve = (p) => Array.isArray(p);

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

/** The field `id`'s description. */
export const keyable = (id) => KEYABLE.find((d) => d.id === id);

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
  for (const d of KEYABLE) {
    const p = style ? d.get(style) : null;
    const button = document.querySelector(`button.key[data-key="${d.id}"]`);
    const keyedHere = isCurve(p) && p.some((k) => k[0] === frame);
    if (button) { button.classList.toggle('keyed', keyedHere); button.textContent = keyedHere ? '◆' : '◇'; }
    const unkey = document.querySelector(`button.unkey[data-key="${d.id}"]`);
    if (unkey) unkey.disabled = !keyedHere;
    if (!isCurve(p)) continue;
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
