// The smear result of every clip frame as the page holds it: per clip one preallocated
// frames × vertices buffer for the body and for each multiple, filled from the answers. A
// whole-clip answer (crates/studio/src/api/changes.rs and shown.rs, docs/studio.md) is kept as
// it came and a frame is rebuilt over the input only when it is drawn (or the whole body is
// read): the answer is in the scene as soon as it has arrived, without laying 81 frames of the
// body and of every multiple over the clip first.

/** Per frame of a bit set (`words` u32 per frame): where its values start, `per` a bit. */
function starts(bits, words, count, per) {
  const out = new Uint32Array(count + 1);
  let k = 0;
  for (let f = 0; f < count; f++) {
    out[f] = k;
    for (let w = f * words, end = w + words; w < end; w++) {
      let x = bits[w];
      x -= (x >>> 1) & 0x55555555;
      x = (x & 0x33333333) + ((x >>> 2) & 0x33333333);
      k += (Math.imul((x + (x >>> 4)) & 0x0f0f0f0f, 0x01010101) >>> 24) * per;
    }
  }
  out[count] = k;
  return out;
}

/** Calls `visit(v, k)` for the `k`-th set bit `v` (from 0) of frame `j`'s words. */
function eachSet(bits, words, j, visit) {
  let k = 0;
  for (let w = 0, base = j * words; w < words; w++) {
    let word = bits[base + w];
    while (word) {
      const b = 31 - Math.clz32(word & -word);
      word &= word - 1;
      visit(w * 32 + b, k++);
    }
  }
}

/**
 * Frames `first ..+ count` to be rebuilt from a whole-clip answer, but for those in `keep`
 * (a Set of clip frames that hold the same style's float32 answer already: exact, kept).
 */
function unready(ready, first, count, keep) {
  for (let f = first; f < first + count; f++) if (!keep || !keep.has(f) || !ready[f]) ready[f] = 0;
}

/** The elongated body of every frame. */
export class ClipBody {
  /** `input`: the clip as `/api/scene` gave it ({positions, frames, vertices}). */
  constructor(input) {
    this.input = input;
    this.n3 = input.vertices * 3;
    this.words = Math.ceil(input.vertices / 32);
    this.positions = new Float32Array(input.frames * this.n3);
    // Per frame: 1 when `positions` holds it, else rebuilt from `changes` (or the input).
    this.ready = new Uint8Array(input.frames);
    this.changes = null;
  }

  /** Answer frames `first ..+ count` as float32 (`body`, frame-major). */
  setFrames(first, count, body) {
    this.positions.set(body, first * this.n3);
    this.ready.fill(1, first, first + count);
  }

  /**
   * A whole-clip answer of changes: `body.twins`, `body.changed` bits, and for the vertices
   * sent `body.step` + `body.offsets` + `body.varints` (displacements in steps) or
   * `body.positions` (frames in `keep` stay as they are). Nothing is decoded now: a frame's
   * values start at its offset (or, for positions, where a popcount of the bits says), and
   * the frames are rebuilt when asked for. A vertex not sent is where its twin is drawn
   * (itself: the input's position).
   */
  setChanges(first, count, buffers, keep = null) {
    const bits = buffers['body.changed'], exact = buffers['body.positions'], twins = buffers['body.twins'];
    // The vertices with a twin other than themselves, and their twins.
    let n = 0;
    for (let v = 0; v < twins.length; v++) if (twins[v] !== v) n++;
    const copies = new Uint32Array(2 * n);
    for (let v = 0, k = 0; v < twins.length; v++) if (twins[v] !== v) { copies[k++] = v; copies[k++] = twins[v]; }
    this.changes = { first, count, bits, copies, starts: exact ? starts(bits, this.words, count, 3) : buffers['body.offsets'], exact, varints: buffers['body.varints'], steps: buffers['body.step'] };
    unready(this.ready, first, count, keep);
  }

  /**
   * Clip frame `f`'s positions: the input's with the sent vertices set and the others where
   * their twins are (the core's numbers within 1e-5 of the clip's diagonal, docs/studio.md;
   * unmoved vertices exact).
   */
  frame(f) {
    const n3 = this.n3, out = this.positions.subarray(f * n3, (f + 1) * n3);
    if (this.ready[f]) return out;
    out.set(this.input.positions.subarray(f * n3, (f + 1) * n3));
    const c = this.changes, j = c ? f - c.first : -1;
    if (c && j >= 0 && j < c.count && c.exact) {
      const exact = c.exact, k0 = c.starts[j];
      eachSet(c.bits, this.words, j, (v, i) => {
        const o = v * 3, k = k0 + i * 3;
        out[o] = exact[k]; out[o + 1] = exact[k + 1]; out[o + 2] = exact[k + 2];
      });
    } else if (c && j >= 0 && j < c.count) {
      // Zigzag LEB128 integers (crates/studio/src/api/changes.rs): 7 bits a byte from the
      // lowest, the high bit set on every byte but the last, the low bit the sign.
      const bytes = c.varints, step = c.steps[j];
      let k = c.starts[j];
      eachSet(c.bits, this.words, j, (v) => {
        for (let o = v * 3, end = o + 3; o < end; o++) {
          let b = bytes[k++], z = b & 127;
          for (let shift = 7; b & 128; shift += 7) { b = bytes[k++]; z |= (b & 127) << shift; }
          out[o] += ((z >>> 1) ^ -(z & 1)) * step;
        }
      });
    }
    if (c && j >= 0 && j < c.count) {
      // A vertex not sent is where its twin is: the twin (the first vertex of its point,
      // never itself a copy) is final after the values above.
      const copies = c.copies, bits = c.bits, base = j * this.words;
      for (let i = 0; i < copies.length; i += 2) {
        const v = copies[i];
        if (bits[base + (v >>> 5)] & (1 << (v & 31))) continue;
        const o = v * 3, t = copies[i + 1] * 3;
        out[o] = out[t]; out[o + 1] = out[t + 1]; out[o + 2] = out[t + 2];
      }
    }
    this.ready[f] = 1;
    return out;
  }

  /** Every frame rebuilt: frames × vertices × 3. */
  all() {
    for (let f = 0; f < this.input.frames; f++) this.frame(f);
    return this.positions;
  }
}

/**
 * One multiple of every frame: positions and opacities of a copy of the input's vertices
 * `first ..+ vertices` (one object). A frame not answered is the input, transparent.
 */
export class ClipCopy {
  constructor(input, first, vertices) {
    Object.assign(this, { input, first, vertices, words: Math.ceil(vertices / 32) });
    this.positions = new Float32Array(input.frames * vertices * 3);
    this.alpha = new Float32Array(input.frames * vertices);
    this.ready = new Uint8Array(input.frames);
    this.shown = null;
  }

  /** Answer frames `first ..+ count` as float32 positions and opacities. */
  setFrames(first, count, positions, alpha) {
    this.positions.set(positions, first * this.vertices * 3);
    this.alpha.set(alpha, first * this.vertices);
    this.ready.fill(1, first, first + count);
  }

  /** A whole-clip answer of the shown vertices (`copyN.shown`, `.shown_positions`, `.shown_alpha`). */
  setShown(first, count, bits, positions, alpha, keep = null) {
    this.shown = { first, count, bits, starts: starts(bits, this.words, count, 1), positions, alpha };
    unready(this.ready, first, count, keep);
  }

  /** Clip frame `f`: {positions, alpha}. */
  frame(f) {
    const n = this.vertices;
    const out = { positions: this.positions.subarray(f * n * 3, (f + 1) * n * 3), alpha: this.alpha.subarray(f * n, (f + 1) * n) };
    if (this.ready[f]) return out;
    const from = (f * this.input.vertices + this.first) * 3;
    out.positions.set(this.input.positions.subarray(from, from + n * 3));
    out.alpha.fill(0);
    const c = this.shown, j = c ? f - c.first : -1;
    if (c && j >= 0 && j < c.count) {
      const k0 = c.starts[j], p = c.positions, a = c.alpha, pos = out.positions, alpha = out.alpha;
      eachSet(c.bits, this.words, j, (v, i) => {
        const k = k0 + i;
        pos[v * 3] = p[k * 3]; pos[v * 3 + 1] = p[k * 3 + 1]; pos[v * 3 + 2] = p[k * 3 + 2];
        alpha[v] = a[k];
      });
    }
    this.ready[f] = 1;
    return out;
  }
}
