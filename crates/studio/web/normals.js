// Vertex normals of a deformed mesh, recomputed whenever the viewport shows another frame.
//
// The same numbers as three.js's `BufferGeometry.computeVertexNormals` (each triangle's
// (c − b) × (a − b) added to its corners' normals in triangle order, stored as float32 after
// every addition, then each normal scaled by 1 / length), computed over the typed arrays
// directly: three.js goes through a `Vector3` per corner, about 7× slower on the robot's
// 7,214 vertices (2.0 against 0.3 ms in V8), which a slider move or a scrub pays per frame
// shown.
import { BufferAttribute } from 'three';

/**
 * Recomputes `geometry`'s `normal` attribute (created when missing) from its positions,
 * bit-identical to three.js's `computeVertexNormals`. A geometry without an index is left to
 * three.js.
 */
export function computeVertexNormals(geometry) {
  const index = geometry.index, position = geometry.attributes.position;
  if (!index || !position || position.itemSize !== 3 || position.isInterleavedBufferAttribute) {
    geometry.computeVertexNormals();
    return;
  }
  let normal = geometry.attributes.normal;
  if (!normal || normal.count !== position.count) {
    normal = new BufferAttribute(new Float32Array(position.count * 3), 3);
    geometry.setAttribute('normal', normal);
  }
  vertexNormals(position.array, index.array, normal.array);
  normal.needsUpdate = true;
}

/** Writes into `out` (vertices × 3, float32) the normals of triangles `index` over `pos`. */
export function vertexNormals(pos, index, out) {
  out.fill(0);
  for (let t = 0; t + 2 < index.length; t += 3) {
    const a = index[t] * 3, b = index[t + 1] * 3, c = index[t + 2] * 3;
    const bx = pos[b], by = pos[b + 1], bz = pos[b + 2];
    const cbx = pos[c] - bx, cby = pos[c + 1] - by, cbz = pos[c + 2] - bz;
    const abx = pos[a] - bx, aby = pos[a + 1] - by, abz = pos[a + 2] - bz;
    const nx = cby * abz - cbz * aby, ny = cbz * abx - cbx * abz, nz = cbx * aby - cby * abx;
    out[a] += nx; out[a + 1] += ny; out[a + 2] += nz;
    out[b] += nx; out[b + 1] += ny; out[b + 2] += nz;
    out[c] += nx; out[c + 1] += ny; out[c + 2] += nz;
  }
  for (let i = 0; i + 2 < out.length; i += 3) {
    const x = out[i], y = out[i + 1], z = out[i + 2];
    const s = 1 / (Math.sqrt(x * x + y * y + z * z) || 1);
    out[i] = x * s; out[i + 1] = y * s; out[i + 2] = z * s;
  }
}
