// Talking to the studio server: JSON, and packed float32/uint32 buffers (see crates/studio/src/pack.rs).

async function check(response) {
  if (response.ok) return response;
  let message = `${response.status} ${response.statusText}`;
  try { message = (await response.json()).error || message; } catch (_) { /* not JSON */ }
  throw new Error(message);
}

export async function getJSON(url) {
  return (await check(await fetch(url))).json();
}

export async function postJSON(url, body) {
  const r = await fetch(url, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
  return (await check(r)).json();
}

/** A packed response: `header` and typed views of its buffers by name. */
export function parsePack(buffer) {
  const view = new DataView(buffer);
  const length = view.getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, length)));
  const base = 4 + length;
  const buffers = {};
  for (const b of header.buffers) {
    const Kind = { u32: Uint32Array, i16: Int16Array, u8: Uint8Array }[b.type] || Float32Array;
    buffers[b.name] = new Kind(buffer, base + b.offset, b.count);
  }
  return { header, buffers, bytes: buffer.byteLength };
}

/**
 * A packed response (POST when `body` is given); `signal` aborts it (an AbortController's).
 * `times`: when the request left, its headers and its last byte arrived (performance.now()).
 */
export async function getPack(url, body, signal) {
  const { buffer, times } = await fetchPack(url, body, signal);
  const out = parsePack(buffer);
  out.times = times;
  return out;
}

/**
 * The bytes of a packed response, unparsed (POST when `body` is given), and when the request
 * left, its headers and its last byte arrived (`performance.now()` of the calling thread).
 */
export async function fetchPack(url, body, signal) {
  const init = body === undefined ? { signal } : { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body), signal };
  const sent = performance.now();
  const r = await check(await fetch(url, init));
  const headers = performance.now();
  const buffer = await r.arrayBuffer();
  return { buffer, times: { sent, headers, body: performance.now() } };
}

// Whole-clip answers are fetched on a worker thread (pack_worker.js): their bytes keep
// arriving while the page's thread is busy, e.g. waiting for a software-GL frame to be read
// back (docs/studio.md, "Software GL"); the page gets them in one message, not copied.
let worker = null, nextId = 0;
const waiting = new Map();

function packWorker() {
  if (worker) return worker;
  worker = new Worker('/pack_worker.js', { type: 'module' });
  worker.onmessage = ({ data }) => {
    const w = waiting.get(data.id);
    if (!w) return;
    waiting.delete(data.id);
    if (data.error !== undefined) {
      const e = new Error(data.error);
      e.name = data.name || 'Error';
      w.reject(e);
      return;
    }
    // The worker's clock starts at its own origin: its times, moved to the page's.
    const out = parsePack(data.buffer), shift = data.origin - performance.timeOrigin, t = data.times;
    out.times = { sent: t.sent + shift, headers: t.headers + shift, body: t.body + shift };
    w.resolve(out);
  };
  return worker;
}

/** `getPack` on the worker thread: the same answer and `times`; `signal` aborts it. */
export function getPackOffThread(url, body, signal) {
  const w = packWorker(), id = ++nextId;
  return new Promise((resolve, reject) => {
    waiting.set(id, { resolve, reject });
    if (signal) {
      signal.addEventListener('abort', () => {
        if (!waiting.delete(id)) return;
        w.postMessage({ abort: id });
        reject(new DOMException('the answer is no longer wanted', 'AbortError'));
      }, { once: true });
    }
    w.postMessage({ id, url: new URL(url, location.href).href, body });
  });
}
