// The 3D viewport: the animation (one frame of a frames × vertices × 3 buffer at a time),
// multiples (alpha-blended copies), motion lines, offsets colouring, part colouring,
// an orbit camera, and an orthographic action camera for drawing lines of action.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { computeVertexNormals } from './normals.js';

const BASE = new THREE.Color(0.78, 0.78, 0.8);

/**
 * On a software renderer, the share of the canvas's width and height drawn while something
 * changes (a slider, a stroke, playback, the orbit camera): a quarter of the pixels, about
 * half of the CPU a frame costs there, the CPU the server answers on.
 */
export const INTERACTIVE_SCALE = 0.5;

/**
 * Milliseconds without a new frame after which a software renderer draws the frame shown
 * again at full resolution (a change's answers arrive within this time; a still view is
 * always sharp).
 */
export const SETTLE_MS = 300;

/**
 * Whether WebGL draws on the CPU (SwiftShader, llvmpipe: a machine or VM without a GPU).
 * There a frame with 4× multisampling and physically based shading costs tens of
 * milliseconds of both cores, the cores the server restyles on, so the viewport draws
 * without multisampling and with diffuse shading instead (docs/studio.md, "Software GL").
 */
function softwareRenderer() {
  const gl = document.createElement('canvas').getContext('webgl2');
  if (!gl) return false;
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  const lose = gl.getExtension('WEBGL_lose_context');
  if (lose) lose.loseContext();
  return /swiftshader|llvmpipe|softpipe|software/i.test(name);
}

export class Viewport {
  constructor(canvas) {
    this.canvas = canvas;
    this.software = softwareRenderer();
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: !this.software, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(1);
    // Drawn at INTERACTIVE_SCALE while things change on a software renderer (`render`),
    // at full resolution once they settle.
    this.scale = 1;
    this.settleTimer = 0;
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x33363b);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x444455, 2.2));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(2, 4, 3);
    this.scene.add(sun);
    this.perspective = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
    this.ortho = new THREE.OrthographicCamera(-1, 1, 1, -1, -1000, 1000);
    this.camera = this.perspective;
    this.controls = new OrbitControls(this.perspective, canvas);
    this.material = this.surface({ color: 0xffffff, vertexColors: true, roughness: 0.7, side: THREE.DoubleSide });
    this.mesh = null;
    this.anim = null;
    this.frame = 0;
    this.copies = [];
    this.lines = [];
    this.offsets = null;
    this.vertexColors = null;
    this.resize();
    // Resizing clears the canvas: drawn again at once, so that it never shows blank until
    // the next animation frame.
    new ResizeObserver(() => { this.resize(); this.render(); }).observe(canvas);
  }

  /** A surface material: physically based on a GPU, diffuse on a software renderer. */
  surface({ roughness, ...options }) {
    return this.software ? new THREE.MeshLambertMaterial(options) : new THREE.MeshStandardMaterial({ roughness, ...options });
  }

  resize() {
    const w = this.canvas.clientWidth || 1, h = this.canvas.clientHeight || 1;
    this.renderer.setSize(w, h, false);
    this.perspective.aspect = w / h;
    this.perspective.updateProjectionMatrix();
    if (this.action) this.setActionCamera(this.action);
    this.dirty = true;
  }

  /**
   * Shows an animation: {triangles: Uint32Array, positions: Float32Array, frames, vertices},
   * optionally `frameAt(f)` giving frame f's positions (a clip rebuilt frame by frame as it is
   * drawn) instead of reading them from `positions`.
   */
  setAnimation(anim, { frame = true } = {}) {
    const reuse = this.mesh && !this.mesh.isSkinnedMesh && this.anim && this.anim.vertices === anim.vertices && this.anim.triangles === anim.triangles;
    this.anim = anim;
    this.skinned = null;
    if (!reuse) {
      if (this.mesh) { this.scene.remove(this.mesh); this.mesh.geometry.dispose(); }
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(anim.vertices * 3), 3));
      g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(anim.vertices * 3).fill(0.78), 3));
      g.setIndex(new THREE.BufferAttribute(anim.triangles, 1));
      this.mesh = new THREE.Mesh(g, this.material);
      this.mesh.frustumCulled = false;
      this.scene.add(this.mesh);
      if (frame) this.frameCamera(anim);
    }
    this.setFrame(Math.min(this.frame, anim.frames - 1));
  }

  /**
   * Shows a motion the renderer skins (three.js SkinnedMesh, linear blend skinning):
   * {triangles, binding: {rest, index, weight, node, inverse} (crates/studio/src/loa_skin.rs),
   * world (frames × nodes × 16, column-major), nodes, frames, vertices}. The mesh and its
   * buffers stay on the GPU while the binding and triangles are the same: a new motion
   * uploads only the bone matrices of the frame shown.
   */
  setSkinned(skinned) {
    const b = skinned.binding;
    const reuse = this.mesh && this.mesh.isSkinnedMesh && this.skinned && this.skinned.binding === b && this.skinned.triangles === skinned.triangles;
    this.anim = { triangles: skinned.triangles, frames: skinned.frames, vertices: skinned.vertices, positions: null };
    this.skinned = skinned;
    if (!reuse) {
      if (this.mesh) { this.scene.remove(this.mesh); this.mesh.geometry.dispose(); }
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(b.rest, 3));
      g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(skinned.vertices * 3).fill(0.78), 3));
      g.setAttribute('skinIndex', new THREE.BufferAttribute(Uint16Array.from(b.index), 4));
      g.setAttribute('skinWeight', new THREE.BufferAttribute(b.weight, 4));
      g.setIndex(new THREE.BufferAttribute(skinned.triangles, 1));
      computeVertexNormals(g);
      // One bone per node of the pose, its world matrix set from the answer (not from a
      // scene graph); the palette repeats a bone under each mesh's inverse bind matrix.
      this.bones = Array.from({ length: skinned.nodes }, () => {
        const bone = new THREE.Bone();
        bone.matrixAutoUpdate = false; bone.matrixWorldAutoUpdate = false;
        return bone;
      });
      const palette = Array.from(b.node, (n) => this.bones[n]);
      const inverses = Array.from(b.node, (_, k) => new THREE.Matrix4().fromArray(b.inverse, k * 16));
      const mesh = new THREE.SkinnedMesh(g, this.material);
      mesh.bind(new THREE.Skeleton(palette, inverses), new THREE.Matrix4());
      mesh.frustumCulled = false;
      this.mesh = mesh;
      this.scene.add(mesh);
    }
    this.setFrame(Math.min(this.frame, skinned.frames - 1));
  }

  frameCamera(anim) {
    const n = anim.vertices;
    const box = new THREE.Box3();
    const p = new THREE.Vector3();
    const first = anim.frameAt ? anim.frameAt(0) : anim.positions;
    for (let i = 0; i < n; i++) box.expandByPoint(p.fromArray(first, i * 3));
    const c = box.getCenter(new THREE.Vector3());
    const r = box.getSize(new THREE.Vector3()).length() / 2 || 1;
    this.perspective.near = r / 100; this.perspective.far = r * 100;
    this.perspective.position.set(c.x, c.y + r * 0.2, c.z + r * 2.6);
    this.perspective.updateProjectionMatrix();
    this.controls.target.copy(c);
    this.controls.update();
  }

  /** The orthographic action camera of /api/loa/view (or null for the orbit camera). */
  setActionCamera(action) {
    this.action = action;
    if (!action) { this.camera = this.perspective; this.controls.enabled = true; this.dirty = true; return; }
    const w = this.canvas.clientWidth || 1, h = this.canvas.clientHeight || 1;
    const hh = action.half_height, hw = hh * w / h;
    const o = this.ortho;
    o.left = -hw; o.right = hw; o.top = hh; o.bottom = -hh;
    const c = new THREE.Vector3(...action.center), f = new THREE.Vector3(...action.forward);
    o.position.copy(c).addScaledVector(f, -hh * 10);
    o.up.set(...action.up);
    o.lookAt(c);
    o.near = -hh * 100; o.far = hh * 100;
    o.updateProjectionMatrix();
    this.camera = o;
    this.controls.enabled = false;
    this.dirty = true;
  }

  setFrame(f) {
    if (!this.anim) return;
    this.frame = Math.max(0, Math.min(f, this.anim.frames - 1));
    if (this.skinned) {
      const s = this.skinned, base = this.frame * s.nodes * 16;
      this.bones.forEach((bone, i) => bone.matrixWorld.fromArray(s.world, base + i * 16));
      this.mesh.skeleton.update();
    } else {
      const n = this.anim.vertices * 3;
      const pos = this.mesh.geometry.attributes.position;
      const a = this.anim;
      pos.array.set(a.frameAt ? a.frameAt(this.frame) : a.positions.subarray(this.frame * n, (this.frame + 1) * n));
      pos.needsUpdate = true;
      computeVertexNormals(this.mesh.geometry);
      this.mesh.geometry.computeBoundingSphere();
    }
    this.updateColors();
    for (const c of this.copies) this.copyFrame(c);
    for (const l of this.lines) this.lineFrame(l);
    this.dirty = true;
  }

  /** Per-frame offsets (frames × vertices) to colour red (leading) / blue (trailing), or null. */
  setOffsets(offsets) { this.offsets = offsets; this.updateColors(); this.dirty = true; }

  /** Fixed per-vertex colours (Float32Array vertices × 3), or null. */
  setVertexColors(colors) { this.vertexColors = colors; this.updateColors(); this.dirty = true; }

  updateColors() {
    if (!this.mesh) return;
    const col = this.mesh.geometry.attributes.color;
    const n = this.anim.vertices;
    if (this.vertexColors && this.vertexColors.length === n * 3) {
      col.array.set(this.vertexColors);
    } else if (this.offsets && this.offsets.length >= (this.frame + 1) * n) {
      const d = this.offsets.subarray(this.frame * n, (this.frame + 1) * n);
      for (let i = 0; i < n; i++) {
        const v = Math.max(-1, Math.min(1, d[i]));
        const a = Math.abs(v);
        const [r, g, b] = v >= 0 ? [1, 1 - a, 1 - a] : [1 - a, 1 - a, 1];
        col.array[i * 3] = r * 0.9; col.array[i * 3 + 1] = g * 0.9; col.array[i * 3 + 2] = b * 0.9;
      }
    } else {
      for (let i = 0; i < n; i++) { col.array[i * 3] = BASE.r; col.array[i * 3 + 1] = BASE.g; col.array[i * 3 + 2] = BASE.b; }
    }
    col.needsUpdate = true;
  }

  clearEffects() {
    for (const o of [...this.copies, ...this.lines]) { this.scene.remove(o.mesh); o.mesh.geometry.dispose(); o.mesh.material.dispose(); }
    this.copies = []; this.lines = [];
  }

  /**
   * Multiples: [{positions (frames × v × 3), alpha (frames × v), triangles, vertices}], or
   * with `frameAt(f)` giving frame f's {positions, alpha} and `frames` instead.
   */
  setCopies(copies) {
    for (const c of this.copies) { this.scene.remove(c.mesh); c.mesh.geometry.dispose(); c.mesh.material.dispose(); }
    this.copies = copies.map((c) => {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(c.vertices * 3), 3));
      g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(c.vertices * 4), 4));
      g.setIndex(new THREE.BufferAttribute(c.triangles, 1));
      const m = this.surface({ vertexColors: true, roughness: 1, transparent: true, depthWrite: false, side: THREE.DoubleSide });
      const mesh = new THREE.Mesh(g, m);
      mesh.frustumCulled = false;
      this.scene.add(mesh);
      const o = { ...c, mesh };
      this.copyFrame(o);
      return o;
    });
    this.dirty = true;
  }

  copyFrame(c) {
    const n = c.vertices, f = Math.min(this.frame, (c.frameAt ? c.frames : c.positions.length / (n * 3)) - 1);
    const g = c.mesh.geometry;
    const fr = c.frameAt ? c.frameAt(f) : { positions: c.positions.subarray(f * n * 3, (f + 1) * n * 3), alpha: c.alpha.subarray(f * n, (f + 1) * n) };
    g.attributes.position.array.set(fr.positions);
    const col = g.attributes.color.array;
    for (let i = 0; i < n; i++) { col[i * 4] = 0.8; col[i * 4 + 1] = 0.8; col[i * 4 + 2] = 0.8; col[i * 4 + 3] = fr.alpha[i]; }
    g.attributes.position.needsUpdate = true; g.attributes.color.needsUpdate = true;
    computeVertexNormals(g);
  }

  /** Motion lines: [{frames: [{positions, triangles}]}] — one mesh per clip frame. */
  setLines(lines) {
    for (const l of this.lines) { this.scene.remove(l.mesh); l.mesh.geometry.dispose(); l.mesh.material.dispose(); }
    this.lines = lines.map((l) => {
      const m = new THREE.MeshBasicMaterial({ color: 0x111111, transparent: true, opacity: 0.9, side: THREE.DoubleSide });
      const mesh = new THREE.Mesh(new THREE.BufferGeometry(), m);
      mesh.frustumCulled = false;
      this.scene.add(mesh);
      const o = { ...l, mesh };
      this.lineFrame(o);
      return o;
    });
    this.dirty = true;
  }

  lineFrame(l) {
    const fr = l.frames[Math.min(this.frame, l.frames.length - 1)];
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(fr.positions, 3));
    g.setIndex(new THREE.BufferAttribute(fr.triangles, 1));
    l.mesh.geometry.dispose();
    l.mesh.geometry = g;
  }

  /** The triangle under a canvas pixel, or -1. */
  pick(x, y) {
    if (!this.mesh) return -1;
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    const ray = new THREE.Raycaster();
    ray.setFromCamera(new THREE.Vector2((x / w) * 2 - 1, -(y / h) * 2 + 1), this.camera);
    const hit = ray.intersectObject(this.mesh, false)[0];
    return hit ? { triangle: hit.faceIndex, point: hit.point } : -1;
  }

  render() {
    const t = performance.now();
    if (this.software) {
      // A change: drawn at the interactive scale, and sharp again once nothing changes.
      this.setScale(INTERACTIVE_SCALE);
      clearTimeout(this.settleTimer);
      this.settleTimer = setTimeout(() => this.settle(), SETTLE_MS);
    }
    this.renderer.render(this.scene, this.camera);
    this.renderMs = performance.now() - t;
    this.dirty = false;
  }

  /** The frame shown, drawn again at full resolution (software renderer, nothing changing). */
  settle() {
    this.settleTimer = 0;
    this.setScale(1);
    this.renderer.render(this.scene, this.camera);
  }

  /** Whether the canvas holds the frame shown at full resolution. */
  get settled() { return this.scale === 1 && !this.dirty; }

  /** Canvas pixels per CSS pixel (a new drawing buffer when it changes). */
  setScale(scale) {
    if (this.scale === scale) return;
    this.scale = scale;
    this.renderer.setPixelRatio(scale);
  }

  /**
   * Renders now (new geometry is drawn as soon as it is in the scene, not at the next
   * animation frame) and resolves once done.
   */
  rendered() { this.render(); return Promise.resolve(); }
}
