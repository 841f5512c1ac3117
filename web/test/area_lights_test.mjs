// The page's choice of client area lights (web/src/area_lights.js), run in Node against the native
// rule's cases (tests/area_light_test.cpp): threshold, caps, connected pieces, materials refused.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { extractAreaLights, kMaxAreaLights } from '../src/area_lights.js';

// A unit square in the plane y = h facing down (-y), as two triangles, from x0.
function panel(x0, h, size = 1) {
  const a = [x0, h, 0], b = [x0 + size, h, 0], c = [x0 + size, h, size], d = [x0, h, size];
  return [...a, ...b, ...c, ...a, ...c, ...d];
}

const lamp = (e = 10) => ({ emission: [e, e, e], textured: false, opaque: true });
const wall = { emission: [0, 0, 0], textured: false, opaque: true };

test('an emitter over the threshold becomes one light per connected piece, facing its emitting side', () => {
  const corners = [...panel(0, 2), ...panel(5, 2), ...panel(0, 0, 4)];
  const set = extractAreaLights([lamp(), wall], corners, [0, 0, 0, 0, 1, 1], 0.05);
  assert.equal(set.lights.length, 2);  // two squares apart: two pieces
  assert.deepEqual(set.clientLitMaterial, [1, 0]);
  const l = set.lights[0];
  assert.equal(l.corners.length, 6);
  assert.ok(Math.abs(l.area - 1) < 1e-9);
  assert.deepEqual(l.centroid.map((v) => Math.round(v * 1e6) / 1e6), [0.5, 2, 0.5]);
  assert.deepEqual(l.normal.map((v) => Math.round(v * 1e6) / 1e6 + 0), [0, -1, 0]);
  assert.ok(Math.abs(set.totalEmittedPower - 2 * 10 * Math.PI) < 1e-6);
});

test('a weak emitter stays with the probes, a strong one does not', () => {
  const corners = [...panel(0, 2), ...panel(5, 2, 0.1)];  // power 100 : 1
  const set = extractAreaLights([lamp(), lamp()], corners, [0, 0, 1, 1], 0.05);
  assert.deepEqual(set.clientLitMaterial, [1, 0]);
  assert.equal(extractAreaLights([lamp(), lamp()], corners, [0, 0, 1, 1], 0).lights.length, 2);
  assert.equal(extractAreaLights([lamp(), lamp()], corners, [0, 0, 1, 1], 1).lights.length, 0);
});

test('textured, see-through and over-cap emitters stay with the probes', () => {
  const corners = panel(0, 2);
  assert.equal(extractAreaLights([{ ...lamp(), textured: true }], corners, [0, 0], 0).lights.length, 0);
  assert.equal(extractAreaLights([{ ...lamp(), opaque: false }], corners, [0, 0], 0).lights.length, 0);
  // More pieces than the cap: the whole material stays with the probes.
  const many = [], materials = [];
  for (let i = 0; i <= kMaxAreaLights; ++i) { many.push(...panel(3 * i, 2)); materials.push(0, 0); }
  assert.equal(extractAreaLights([lamp()], many, materials, 0).lights.length, 0);
  // A weaker material that fits is still taken after one that does not.
  const both = [...many, ...panel(100, 2, 0.5)];
  const set = extractAreaLights([lamp(), lamp(100)], both, [...materials, 1, 1], 0);
  assert.deepEqual(set.clientLitMaterial, [0, 1]);
});

test('nonsense is refused or ignored, never a light', () => {
  assert.throws(() => extractAreaLights([lamp()], panel(0, 2), [0, 0], NaN), /minimum power share must be in \[0, 1\]/);
  assert.throws(() => extractAreaLights([lamp()], panel(0, 2), [0, 0], 1.5), /minimum power share/);
  const nan = panel(0, 2);
  nan[0] = NaN;
  assert.equal(extractAreaLights([lamp()], nan, [0, 0], 0).lights.length, 1);  // the other triangle
  assert.equal(extractAreaLights([lamp(Infinity)], panel(0, 2), [0, 0], 0).lights.length, 0);
  assert.equal(extractAreaLights([lamp()], panel(0, 2), [7, -1], 0).lights.length, 0);  // no such material
});
