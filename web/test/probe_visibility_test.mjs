// The page's probe visibility (web/src/probe_visibility.js), run in Node: the octahedral mapping,
// the lobes, the moments of known depth cubes, the tile borders and the reach, as the native
// client's (renderer/src/probe_visibility.cpp) define them; and, where the native fixture is built
// (PROBECAST_MOMENTS_FIXTURE, as ctest sets it), the same cubes' moments against the native code's.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { test } from 'node:test';
import * as THREE from 'three';
import { kCube, kOct, kTile, lobeTaps, octDecode, octEncode, octahedralMoments, visibilityReach } from '../src/probe_visibility.js';

// The world direction of texel (x, y) of face f of a cube as the page draws it (rows from the
// bottom, as WebGL reads them back).
const kDir = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]];
const kUp = [[0, 1, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1], [0, 1, 0], [0, 1, 0]];
const cams = kDir.map((d, f) => {
  const c = new THREE.PerspectiveCamera(90, 1, 0.005, 100);
  c.up.fromArray(kUp[f]);
  c.lookAt(new THREE.Vector3().fromArray(d));
  c.updateMatrixWorld(true);
  return c;
});
function texelDir(f, x, y) {
  const v = new THREE.Vector3(((x + 0.5) / kCube) * 2 - 1, ((y + 0.5) / kCube) * 2 - 1, 0.5).unproject(cams[f]).normalize();
  return [v.x, v.y, v.z];
}

// The moments of a cube whose distance toward d is dist(d), at the tile's interior texel toward `toward`.
function momentsOf(dist) {
  const atlas = new Float32Array(kTile * kTile * 2);
  octahedralMoments((f, x, y) => dist(texelDir(f, x, y)), atlas, kTile, 0, 0);
  const at = (toward) => {
    const e = octEncode(toward);
    const tx = 1 + Math.min(kOct - 1, Math.floor((e[0] * 0.5 + 0.5) * kOct)), ty = 1 + Math.min(kOct - 1, Math.floor((e[1] * 0.5 + 0.5) * kOct));
    return [atlas[2 * (ty * kTile + tx)], atlas[2 * (ty * kTile + tx) + 1]];
  };
  return { atlas, at };
}

test('directions survive the octahedral map', () => {
  for (const d of [[1, 0, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1], [0.3, -0.5, -0.81], [-0.7, 0.1, 0.7]]) {
    const l = Math.hypot(...d), n = d.map((c) => c / l);
    const back = octDecode(...octEncode(n));
    back.forEach((c, i) => assert.ok(Math.abs(c - n[i]) < 1e-6, `${n} -> ${back}`));
  }
});

test('every lobe is a normalised set of nearby cube texels', () => {
  const t = lobeTaps();
  for (let i = 0; i < kTile * kTile; ++i) {
    let sum = 0;
    for (let k = t.start[i]; k < t.start[i + 1]; ++k) sum += t.weight[k];
    assert.ok(t.start[i + 1] - t.start[i] >= 8, `texel ${i} has a lobe of ${t.start[i + 1] - t.start[i]} taps`);
    assert.ok(Math.abs(sum - 1) < 1e-5, `texel ${i}'s weights sum to ${sum}`);
  }
});

test('a probe at the centre of a sphere sees its radius every way, with no spread', () => {
  const { atlas } = momentsOf(() => 2.5);
  for (let i = 0; i < kTile * kTile; ++i) {
    assert.ok(Math.abs(atlas[2 * i] - 2.5) < 1e-5);
    assert.ok(Math.abs(atlas[2 * i + 1] - 6.25) < 1e-4);
  }
});

test('a wall one metre along +x is near that way and open the other', () => {
  const open = 10;
  const { at } = momentsOf((d) => (d[0] > 1e-6 ? Math.min(open, 1 / d[0]) : open));
  const [m1, m2] = at([1, 0, 0]);
  assert.ok(m1 > 1 && m1 < 1.1, `toward the wall the mean distance is ${m1}`);
  assert.ok(m2 - m1 * m1 < 0.02, `and the spread small (${m2 - m1 * m1})`);
  assert.ok(Math.abs(at([-1, 0, 0])[0] - open) < 1e-4, 'away from it, open');
  // Grazing the wall, the lobe mixes near and far: the mean between, the spread large.
  const [g1, g2] = at([0, 0, 1]);
  assert.ok(g1 > 3 && g1 < open, `grazing mean ${g1}`);
  assert.ok(g2 - g1 * g1 > 1, `grazing spread ${g2 - g1 * g1}`);
});

test('tile borders repeat the texels across the octahedron\'s edges', () => {
  const { atlas } = momentsOf((d) => 1 + 0.5 * d[0] + 0.25 * d[1] * d[1] + 0.1 * d[2]);
  const v = (x, y) => atlas[2 * (y * kTile + x)];
  // Column 0 stands for (−1 − ε, v): the same point as (−1 + ε, −v), interior column 1 mirrored.
  for (let y = 1; y <= kOct; ++y) assert.ok(Math.abs(v(0, y) - v(1, kTile - 1 - y)) < 1e-5, `row ${y}`);
  for (let x = 1; x <= kOct; ++x) assert.ok(Math.abs(v(x, kTile - 1) - v(kTile - 1 - x, kOct)) < 1e-5, `column ${x}`);
});

test('the reach is 1.5 cell diagonals and a quarter spacing', () => {
  const bounds = { min: [0, 0, 0], max: [4, 2, 6] };
  const r = visibilityReach([5, 3, 4], bounds, [4, 2, 6]);
  assert.ok(Math.abs(r - (1.5 * Math.hypot(1, 1, 2) + 0.25)) < 1e-9, `${r}`);
  // One probe along y: that axis counts the scene's extent.
  assert.ok(Math.abs(visibilityReach([5, 1, 4], bounds, [4, 3, 6]) - (1.5 * Math.hypot(1, 3, 2) + 0.25)) < 1e-9);
  assert.equal(visibilityReach([1, 1, 1], bounds, [4, 2, 6]), Infinity);
});

// The page's cubes (three.js cameras, WebGL's rows) and the native ones (Vulkan's) share no code:
// the same distance functions must give the same moments, texel for texel.
test('the moments equal the native client\'s for the same cubes', { skip: !process.env.PROBECAST_MOMENTS_FIXTURE }, () => {
  const native = JSON.parse(execFileSync(process.env.PROBECAST_MOMENTS_FIXTURE, { encoding: 'utf8' }));
  assert.equal(native.tile, kTile);
  const functions = {
    wall: (d) => (d[0] > 1e-6 ? Math.min(10, 1 / d[0]) : 10),
    smooth: (d) => 1 + 0.5 * d[0] + 0.25 * d[1] * d[1] + 0.1 * d[2],
  };
  for (const [name, dist] of Object.entries(functions)) {
    const { atlas } = momentsOf(dist);
    assert.equal(native[name].length, atlas.length);
    let worst = 0;
    atlas.forEach((v, i) => { worst = Math.max(worst, Math.abs(v - native[name][i]) / Math.max(1, Math.abs(native[name][i]))); });
    assert.ok(worst < 1e-4, `${name}: the page's moments differ from the native client's by up to ${worst} (relative)`);
  }
});
