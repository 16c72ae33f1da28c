// Fetches packed answers for the page (api.js `getPackOffThread`) and hands their bytes over
// (transferred, not copied), with the times of `fetchPack` on this worker's clock.
import { fetchPack } from './api.js';

const controllers = new Map();

onmessage = async ({ data }) => {
  if (data.abort !== undefined) {
    const c = controllers.get(data.abort);
    if (c) c.abort();
    return;
  }
  const ctl = new AbortController();
  controllers.set(data.id, ctl);
  try {
    const { buffer, times } = await fetchPack(data.url, data.body, ctl.signal);
    postMessage({ id: data.id, buffer, times, origin: performance.timeOrigin }, [buffer]);
  } catch (e) {
    postMessage({ id: data.id, error: e.message, name: e.name });
  } finally {
    controllers.delete(data.id);
  }
};
