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
    const Kind = b.type === 'u32' ? Uint32Array : b.type === 'i16' ? Int16Array : Float32Array;
    buffers[b.name] = new Kind(buffer, base + b.offset, b.count);
  }
  return { header, buffers, bytes: buffer.byteLength };
}

/**
 * A packed response (POST when `body` is given); `signal` aborts it (an AbortController's).
 * `times`: when the request left, its headers and its last byte arrived (performance.now()).
 */
export async function getPack(url, body, signal) {
  const init = body === undefined ? { signal } : { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body), signal };
  const sent = performance.now();
  const r = await check(await fetch(url, init));
  const headers = performance.now();
  const out = parsePack(await r.arrayBuffer());
  out.times = { sent, headers, body: performance.now() };
  return out;
}
