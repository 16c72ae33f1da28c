// Fetches packed answers for the page (api.js getPackOffThread) and hands their bytes over.
const controllers = new Map();
const now = () => performance.timeOrigin + performance.now();
onmessage = async ({ data }) => {
  if (data.abort !== undefined) { const c = controllers.get(data.abort); if (c) c.abort(); return; }
  const ctl = new AbortController();
  controllers.set(data.id, ctl);
  try {
    const init = data.body === null ? { signal: ctl.signal } : { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: data.body, signal: ctl.signal };
    const sent = now();
    const r = await fetch(data.url, init);
    const headers = now();
    if (!r.ok) {
      let message = `${r.status} ${r.statusText}`;
      try { message = (await r.json()).error || message; } catch (_) { /* not JSON */ }
      postMessage({ id: data.id, error: message });
      return;
    }
    const buffer = await r.arrayBuffer();
    postMessage({ id: data.id, buffer, sent, headers, body: now() }, [buffer]);
  } catch (e) {
    postMessage({ id: data.id, error: e.message, name: e.name });
  } finally {
    controllers.delete(data.id);
  }
};
