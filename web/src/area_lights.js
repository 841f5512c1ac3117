// Which emitters the page lights itself: the native rule (renderer/scene/src/area_lights.cpp) on the
// scene's world-space triangles, so that the page and the stream agree on what the probes leave
// out. No DOM and no three.js: web/test/area_lights_test.mjs runs it in Node.
//
// A material with constant emission, opaque to rays, whose triangles together emit at least
// `share` of the scene's emitted power becomes client-lit, strongest first, while the lights (its
// connected pieces) stay within 8 and the triangles within 64: rule version 1's caps.

export const kAreaLightRuleVersion = 1;
export const kMaxAreaLights = 8;
export const kMaxAreaTriangles = 64;

const kPi = 3.14159265358979;

function luminance(c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
function length(a) { return Math.hypot(a[0], a[1], a[2]); }

// Corner k (0..2) of triangle t, from 9 floats a triangle.
function corner(corners, t, k) { return [corners[9 * t + 3 * k], corners[9 * t + 3 * k + 1], corners[9 * t + 3 * k + 2]]; }

function triangleArea(corners, t) {
  const a = corner(corners, t, 0);
  return 0.5 * length(cross(sub(corner(corners, t, 1), a), sub(corner(corners, t, 2), a)));
}

// Pieces of `triangles` that share a vertex position exactly (as single-precision floats, as the
// native loader holds them).
function connectedPieces(corners, triangles) {
  const parent = triangles.map((_, i) => i);
  const root = (i) => {
    while (parent[i] !== i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const owner = new Map();
  triangles.forEach((t, i) => {
    for (let k = 0; k < 3; ++k) {
      const key = corner(corners, t, k).map(Math.fround).join(',');
      if (owner.has(key)) parent[root(i)] = root(owner.get(key));
      else owner.set(key, i);
    }
  });
  const byRoot = new Map();
  triangles.forEach((t, i) => {
    const r = root(i);
    if (!byRoot.has(r)) byRoot.set(r, []);
    byRoot.get(r).push(t);
  });
  return [...byRoot.keys()].sort((a, b) => a - b).map((r) => byRoot.get(r));
}

function makeLight(corners, material, radiance, piece) {
  const out = { material, radiance: radiance.slice(), corners: [], centroid: [0, 0, 0], normal: [0, -1, 0], area: 0 };
  const weightedNormal = [0, 0, 0], weightedCentroid = [0, 0, 0];
  for (const t of piece) {
    const a = corner(corners, t, 0), b = corner(corners, t, 1), c = corner(corners, t, 2);
    const cr = cross(sub(b, a), sub(c, a));
    const area = 0.5 * length(cr);
    out.corners.push(a, b, c);
    for (let i = 0; i < 3; ++i) {
      weightedNormal[i] += 0.5 * cr[i];
      weightedCentroid[i] += area * (a[i] + b[i] + c[i]) / 3;
    }
    out.area += area;
  }
  out.centroid = out.area > 0 ? weightedCentroid.map((v) => v / out.area) : out.corners[0].slice();
  const len = length(weightedNormal);
  if (len > 0) out.normal = weightedNormal.map((v) => v / len);
  out.power = luminance(out.radiance) * out.area * kPi;
  return out;
}

// materials: [{ emission: [r, g, b] (linear, strength applied), textured: bool (an emissive
// texture), opaque: bool (alpha mode OPAQUE, no transmission) }]; corners: 9 numbers a triangle
// (world space, counter-clockwise seen from the emitting side); triangleMaterial: an index into
// materials a triangle. share: the stream's threshold, in [0, 1].
// Returns { lights, clientLitMaterial (0/1 a material), totalEmittedPower }.
export function extractAreaLights(materials, corners, triangleMaterial, share) {
  if (!(share >= 0 && share <= 1)) throw new Error('area lights: the minimum power share must be in [0, 1]');
  const out = { lights: [], clientLitMaterial: materials.map(() => 0), totalEmittedPower: 0 };
  const power = materials.map(() => 0);
  const triangles = materials.map(() => []);
  let total = 0;
  for (let t = 0; t < triangleMaterial.length; ++t) {
    const m = triangleMaterial[t];
    if (!(m >= 0 && m < materials.length)) continue;
    const p = luminance(materials[m].emission) * triangleArea(corners, t) * kPi;
    if (!(p > 0) || !Number.isFinite(p)) continue;
    total += p;
    power[m] += p;
    triangles[m].push(t);
  }
  out.totalEmittedPower = total;
  if (!(total > 0) || !Number.isFinite(total)) return out;
  const order = materials.map((_, i) => i).sort((a, b) => power[b] - power[a] || a - b);
  let used = 0;
  for (const m of order) {
    const mat = materials[m];
    if (mat.textured || !mat.opaque || !triangles[m].length) continue;
    if (power[m] < Math.fround(share) * total) break;  // the rest are weaker
    const pieces = connectedPieces(corners, triangles[m]);
    // A material is client-lit whole or not at all (the updater's rule is per material).
    if (out.lights.length + pieces.length > kMaxAreaLights || used + triangles[m].length > kMaxAreaTriangles) continue;
    for (const piece of pieces) out.lights.push(makeLight(corners, m, mat.emission, piece));
    used += triangles[m].length;
    out.clientLitMaterial[m] = 1;
  }
  return out;
}
