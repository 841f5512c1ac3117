// Probe visibility in the page, made as the native raster client makes it
// (renderer/src/probe_visibility.h) from the page's own scene, no wire bytes: a 32² depth cube is
// drawn from every probe (six 90° faces of distance into a float target, a row of probes a draw
// batch), read back, and turned into an octahedral map of distance moments (E[r], E[r²]) per probe,
// each texel the mean over a cos^50 lobe around its direction. probe_lighting.js weighs each of the
// 8 probes around a point by the Chebyshev bound on the point being visible from it. Each probe
// sees only as far as its reach; beyond it every direction reads the reach. The cubes are drawn a
// few batches a frame, within a time budget, so a large volume never stalls the page; the old map
// is used until the new one is whole. While the scene moves, the probes within reach of what moved
// are drawn again.
import * as THREE from 'three';
import { drawOffscreen, kMapCutout, kMapHeader, leftOutOfMaps, MapMaterials } from './offscreen.js';
import { VisibilityProxy } from './visibility_proxy.js';

export const kCube = 32;            // texels a side of each cube face (kVisibilityCubeSize)
const kLobeCube = kCube / 2;        // the faces are averaged 2×2 before the lobes
export const kOct = 16;             // RS_VIS_OCT: octahedral texels a side of a probe's map
export const kTile = kOct + 2;      // RS_VIS_TILE: with a border texel on each side
export const kTilesPerRow = 256;    // RS_VIS_TILES_PER_ROW
const kLobePower = 50;              // kVisibilityLobePower
const kNear = 0.005;                // metres: a surface nearer than this to a probe is not seen
const kBatchColumns = 16;           // probes per row of a draw batch (six faces each)
export const kMaxProbes = 1 << 16;  // kMaxVisibilityProbes: larger volumes are drawn without it
const kFrameBudgetMs = 12;          // drawing per frame while a build is under way

// The six faces seen from a probe (+x −x +y −y +z −z) and their up vectors (cubeFaceViews).
const kFaceDir = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]];
const kFaceUp = [[0, 1, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1], [0, 1, 0], [0, 1, 0]];

export function octEncode(v) {
  const s = Math.abs(v[0]) + Math.abs(v[1]) + Math.abs(v[2]);
  let x = v[0] / s, y = v[1] / s;
  if (v[2] < 0) [x, y] = [(1 - Math.abs(y)) * (x >= 0 ? 1 : -1), (1 - Math.abs(x)) * (y >= 0 ? 1 : -1)];
  return [x, y];
}

export function octDecode(x, y) {
  let v = [x, y, 1 - Math.abs(x) - Math.abs(y)];
  if (v[2] < 0) v = [(1 - Math.abs(y)) * (x >= 0 ? 1 : -1), (1 - Math.abs(x)) * (y >= 0 ? 1 : -1), v[2]];
  const l = Math.hypot(...v);
  return v.map((c) => c / l);
}

// A face camera at the origin (world axes), as the cubes are drawn.
function faceCamera(f, far) {
  const cam = new THREE.PerspectiveCamera(90, 1, kNear, far);
  cam.up.fromArray(kFaceUp[f]);
  cam.lookAt(new THREE.Vector3().fromArray(kFaceDir[f]));
  cam.updateMatrixWorld(true);
  return cam;
}

// The direction and relative solid angle of every texel of the 2×2-averaged faces (face-major,
// then row from the bottom as WebGL reads it back, then column).
function lobeCubeTexels() {
  const dir = [], solidAngle = [];
  for (let f = 0; f < 6; ++f) {
    const cam = faceCamera(f, 100);
    for (let y = 0; y < kLobeCube; ++y)
      for (let x = 0; x < kLobeCube; ++x) {
        const u = ((x + 0.5) / kLobeCube) * 2 - 1, v = ((y + 0.5) / kLobeCube) * 2 - 1;
        const d = new THREE.Vector3(u, v, 0.5).unproject(cam).normalize();
        dir.push([d.x, d.y, d.z]);
        solidAngle.push(Math.pow(1 + u * u + v * v, -1.5));
      }
  }
  return { dir, solidAngle };
}

// For every texel of a tile (borders folded back across the octahedron's edges, so they repeat
// the texel they stand for) the cube texels of its lobe and their normalised weights, flattened.
let taps = null;
export function lobeTaps() {
  if (taps) return taps;
  const cube = lobeCubeTexels();
  const start = new Uint32Array(kTile * kTile + 1), index = [], weight = [];
  for (let ty = 0; ty < kTile; ++ty)
    for (let tx = 0; tx < kTile; ++tx) {
      let ex = ((tx - 0.5) / kOct) * 2 - 1, ey = ((ty - 0.5) / kOct) * 2 - 1;
      if (Math.abs(ex) > 1) [ex, ey] = [Math.sign(ex) * 2 - ex, -ey];
      if (Math.abs(ey) > 1) [ex, ey] = [-ex, Math.sign(ey) * 2 - ey];
      const d = octDecode(ex, ey);
      const first = index.length;
      let sum = 0;
      cube.dir.forEach((c, s) => {
        const cos = d[0] * c[0] + d[1] * c[1] + d[2] * c[2];
        if (cos <= 0) return;
        const w = Math.pow(cos, kLobePower) * cube.solidAngle[s];
        if (w < 1e-4) return;
        index.push(s);
        weight.push(w);
        sum += w;
      });
      for (let k = first; k < index.length; ++k) weight[k] /= sum;
      start[ty * kTile + tx + 1] = index.length;
    }
  taps = { start, index: Uint32Array.from(index), weight: Float32Array.from(weight) };
  return taps;
}

// The moments of one probe from its cube's distances (6 faces of kCube², `read(f, x, y)`), into
// `atlas` (2 floats a texel, `width` texels a row) at the tile's corner (x0, y0).
export function octahedralMoments(read, atlas, width, x0, y0) {
  const n = 6 * kLobeCube * kLobeCube;
  const r1 = new Float32Array(n), r2 = new Float32Array(n);
  for (let f = 0; f < 6; ++f)
    for (let y = 0; y < kLobeCube; ++y)
      for (let x = 0; x < kLobeCube; ++x) {
        let sum = 0, square = 0;
        for (let k = 0; k < 4; ++k) {
          const r = read(f, 2 * x + (k % 2), 2 * y + (k >> 1));
          sum += r;
          square += r * r;
        }
        r1[(f * kLobeCube + y) * kLobeCube + x] = 0.25 * sum;
        r2[(f * kLobeCube + y) * kLobeCube + x] = 0.25 * square;
      }
  const t = lobeTaps();
  for (let ty = 0; ty < kTile; ++ty)
    for (let tx = 0; tx < kTile; ++tx) {
      const i = ty * kTile + tx;
      let mean = 0, square = 0;
      for (let k = t.start[i]; k < t.start[i + 1]; ++k) {
        mean += t.weight[k] * r1[t.index[k]];
        square += t.weight[k] * r2[t.index[k]];
      }
      const o = 2 * ((y0 + ty) * width + x0 + tx);
      atlas[o] = mean;
      atlas[o + 1] = square;
    }
}

// How far a probe of the grid needs to see (probeVisibilityReach): 1.5 cell diagonals plus a
// quarter of the smallest spacing; an axis with one probe counts the scene's extent as its cell.
export function visibilityReach(dims, bounds, extent) {
  const cell = [0, 1, 2].map((a) => (dims[a] > 1 ? (bounds.max[a] - bounds.min[a]) / (dims[a] - 1) : extent[a]));
  const steps = [0, 1, 2].filter((a) => dims[a] > 1).map((a) => cell[a]);
  if (!steps.length) return Infinity;
  return 1.5 * Math.hypot(...cell) + 0.25 * Math.min(...steps);
}

// The cubes' fragments: distance from the probe (posed meshes, cut-outs cut).
const kDistanceFragment = /* glsl */ `${kMapHeader}
uniform vec3 pvProbe;
void main() {
${kMapCutout}
  gl_FragColor = vec4(length(vWorldPosition - pvProbe), 0.0, 0.0, 1.0);
}`;

export class ProbeVisibility {
  constructor() {
    this.uniforms = {
      pcVis: { value: null },
      pcVisOn: { value: 0 },
      pcReach: { value: 1e30 },
    };
    this.probe = { value: new THREE.Vector3() };
    this.materials = new MapMaterials(kDistanceFragment, { pvProbe: this.probe });
    this.status = { probes: 0, ms: 0, ready: false, batches: 0, redrawn: 0 };  // redrawn: probes drawn again after moves
    this.root = null;
    this.rootBox = null;    // the root's extent as loaded
    this.proxy = null;      // its still geometry, simplified (visibility_proxy.js)
    this.requested = null;  // the probes, reach and grid of the last request
    this.build = null;  // the map in the making: { positions, reach, far, key, whole, queue, drawn, atlas, started }
    this.built = null;  // the map in use: { positions, reach, far, key, atlas, width, height }
    this.boxes = new Map();
    this.target = null;
  }

  // The scene the probes see (the glTF root, posed); a new root is drawn again whole. Its extent
  // (which sets the probes' reach and the open distance) is taken once, as loaded, as the native
  // client takes the scene's bounds.
  // moving: the meshes that move (visibility_proxy.js's movingMeshes); the others are drawn as a
  // simplified proxy once the simplifier has loaded.
  setRoot(root, moving = new Set()) {
    if (root === this.root) return;
    this.root = root;
    this.proxy?.dispose();
    this.proxy = new VisibilityProxy(root, moving);
    this.rootBox = new THREE.Box3().setFromObject(root, true);
    this.requested = null;
  }

  // The volume's probes: positions (xyz a probe, grid point plus offset), the grid (dims, bounds).
  // A build starts when they, or the reach, change.
  request(positions, dims, bounds) {
    if (!this.root) return;
    const count = positions.length / 3;
    if (count < 1 || count > kMaxProbes) {
      this.uniforms.pcVisOn.value = 0;
      this.build = this.built = this.requested = null;
      this.status = { probes: 0, ms: 0, ready: false, batches: 0, redrawn: 0, skipped: count > kMaxProbes ? `${count} probes` : '' };
      return;
    }
    const box = this.rootBox.clone();
    box.expandByPoint(new THREE.Vector3().fromArray(bounds.min)).expandByPoint(new THREE.Vector3().fromArray(bounds.max));
    const extent = box.getSize(new THREE.Vector3()).toArray();
    const reach = visibilityReach(dims, bounds, extent);
    const far = Math.max(2 * Math.hypot(...extent), 1);
    const last = this.requested, key = dims.join('x');
    if (last && last.reach === reach && last.far === far && last.key === key && last.positions.length === positions.length &&
        last.positions.every((v, i) => v === positions[i])) return;
    this.requested = { positions: Float32Array.from(positions), reach, far, key };
    this.start(this.requested.positions, reach, far, null, key);
  }

  // Starts drawing `which` probes (null: all, into a new map); `key`: the grid's dimensions.
  start(positions, reach, far, which, key) {
    const count = positions.length / 3;
    const whole = which === null;
    const width = Math.min(count, kTilesPerRow) * kTile, height = Math.ceil(count / kTilesPerRow) * kTile;
    const atlas = whole ? new Float32Array(width * height * 2) : this.built.atlas;
    this.build = { positions, reach, far, key, whole, width, height, atlas, started: performance.now(),
                   queue: whole ? Array.from({ length: count }, (_, i) => i) : which, drawn: 0 };
    if (!whole) return;
    this.status.ready = false;
    // What moves from now on is drawn again once this map is made.
    this.rememberBoxes();
    // A map of another grid's probes would be read at the wrong tiles: none until the new one is made.
    if (this.built?.key !== key) this.uniforms.pcVisOn.value = 0;
  }

  // Draws what is pending, a few batches a frame; `moving`: the scene's pose changed this frame.
  draw(renderer, scene, moving) {
    if (moving && this.built && this.root && !this.build?.whole) this.followMoved();
    const b = this.build;
    if (!b) return;
    const until = performance.now() + kFrameBudgetMs;
    const t0 = performance.now();
    do {
      const batch = b.queue.splice(0, kBatchColumns);
      this.drawBatch(renderer, scene, batch);
      b.drawn += batch.length;
    } while (b.queue.length && performance.now() < until);
    b.drawingMs = (b.drawingMs || 0) + performance.now() - t0;
    if (b.queue.length) return;
    this.build = null;
    this.finish(b);
    if (b.whole && this.root) this.followMoved();  // what moved while it was drawn
  }

  finish(b) {
    this.built = { positions: b.positions, reach: b.reach, far: b.far, key: b.key, atlas: b.atlas, width: b.width, height: b.height };
    const u = this.uniforms;
    if (!u.pcVis.value || u.pcVis.value.image.width !== b.width || u.pcVis.value.image.height !== b.height) {
      u.pcVis.value?.dispose();
      const t = new THREE.DataTexture(b.atlas, b.width, b.height, THREE.RGFormat, THREE.FloatType);
      t.minFilter = t.magFilter = THREE.NearestFilter;
      u.pcVis.value = t;
    }
    u.pcVis.value.image.data = b.atlas;
    u.pcVis.value.needsUpdate = true;
    u.pcReach.value = Number.isFinite(b.reach) ? b.reach : 1e30;
    u.pcVisOn.value = 1;
    if (b.whole) this.status = { probes: b.positions.length / 3, ms: performance.now() - b.started, drawingMs: b.drawingMs,
                                 ready: true, batches: this.status.batches, redrawn: 0, triangles: this.status.triangles };
    else this.status.redrawn += b.drawn;
  }

  // The world boxes of the meshes as posed now (skinned, instanced and batched meshes measured
  // again: three keeps their boxes from when they were first asked for).
  meshBoxes() {
    const boxes = new Map();
    this.root.traverse((o) => {
      if (!o.isMesh) return;
      if (o.boundingBox !== undefined) o.computeBoundingBox();
      boxes.set(o, new THREE.Box3().setFromObject(o));
    });
    return boxes;
  }

  // The boxes the map in the making is drawn against (what moves is compared with them).
  rememberBoxes() { this.boxes = this.root ? this.meshBoxes() : new Map(); }

  // The probes within reach of a mesh that moved since the map was drawn, drawn again.
  followMoved() {
    const now = this.meshBoxes(), moved = [];
    for (const [o, box] of now) {
      const before = this.boxes.get(o);
      if (!before || !before.equals(box)) moved.push(before ? box.clone().union(before) : box);
    }
    this.boxes = now;
    if (!moved.length) return;
    const { positions, reach, far, key } = this.built;
    const pending = new Set(this.build ? this.build.queue : []);
    const p = new THREE.Vector3();
    for (let i = 0; i < positions.length / 3; ++i) {
      p.fromArray(positions, 3 * i);
      if (moved.some((box) => box.distanceToPoint(p) <= reach)) pending.add(i);
    }
    if (pending.size) this.start(positions, reach, far, [...pending], key);
  }

  // One row of probes: six faces each into the float target, read back, moments into the atlas.
  drawBatch(renderer, scene, probes) {
    const b = this.build;
    const w = kBatchColumns * 6 * kCube;
    if (!this.target) {
      this.target = new THREE.WebGLRenderTarget(w, kCube, { type: THREE.FloatType, format: THREE.RGBAFormat,
        minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter, depthBuffer: true, generateMipmaps: false });
    }
    const cameraFar = Number.isFinite(b.reach) ? Math.min(b.far, b.reach * 1.75) : b.far;
    const cams = kFaceDir.map((_, f) => faceCamera(f, cameraFar));
    this.withDistanceMaterials(renderer, scene, () => {
      probes.forEach((probe, k) => {
        this.probe.value.fromArray(b.positions, 3 * probe);
        cams.forEach((cam, f) => {
          cam.position.copy(this.probe.value);
          cam.updateMatrixWorld(true);
          this.target.viewport.set((k * 6 + f) * kCube, 0, kCube, kCube);
          this.target.scissor.set((k * 6 + f) * kCube, 0, kCube, kCube);
          renderer.setRenderTarget(this.target);
          renderer.render(scene, cam);
        });
      });
    });
    const pixels = new Float32Array(w * kCube * 4);
    renderer.readRenderTargetPixels(this.target, 0, 0, w, kCube, pixels);
    const open = Math.min(b.far, b.reach);
    probes.forEach((probe, k) => {
      const read = (f, x, y) => {
        const o = 4 * (y * w + (k * 6 + f) * kCube + x);
        return pixels[o + 3] > 0.5 ? Math.min(pixels[o], b.reach) : open;
      };
      octahedralMoments(read, b.atlas, b.width, (probe % kTilesPerRow) * kTile, Math.floor(probe / kTilesPerRow) * kTile);
    });
    this.status.batches += 1;
  }

  // Runs `draw` with every opaque mesh drawn in distance (cut-outs cut as their material cuts) and
  // everything else hidden: see-through casters, the background, points, lines and sprites, as the
  // native cubes leave them out. Alpha 0: nothing seen that way.
  withDistanceMaterials(renderer, scene, draw) {
    const proxy = this.proxy?.for(this.build.reach);
    const hide = proxy ? (o) => leftOutOfMaps(o) || this.proxy.replaced.has(o) : leftOutOfMaps;
    if (proxy) scene.add(proxy);
    try {
      drawOffscreen(renderer, scene, { target: this.target, clearColor: 0x000000, clearAlpha: 0, materials: this.materials, hide }, draw);
    } finally {
      if (proxy) scene.remove(proxy);
    }
    this.status.triangles = proxy ? { ...this.proxy.triangles } : null;
  }

  dispose() {
    this.target?.dispose();
    this.uniforms.pcVis.value?.dispose();
    this.materials.dispose();
    this.proxy?.dispose();
  }
}
