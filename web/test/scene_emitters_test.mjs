// The page's walk over a three.js scene for the area-light rule (web/src/scene_emitters.js), in
// Node: materials numbered and described by the glTF, mirrored nodes' winding, dark triangles left out.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import * as THREE from 'three';
import { sceneEmitters } from '../src/scene_emitters.js';
import { extractAreaLights } from '../src/area_lights.js';

// A unit square at height 2 facing down (-y) in its node's frame.
function panel(material) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute([0, 2, 0, 1, 2, 0, 1, 2, 1, 0, 2, 1], 3));
  g.setIndex([0, 1, 2, 0, 2, 3]);
  return new THREE.Mesh(g, material);
}

test('materials by glTF index and glTF description; mirrored winding; dark triangles skipped', () => {
  const lamp = new THREE.MeshStandardMaterial({ emissive: new THREE.Color(1, 1, 1), emissiveIntensity: 10 });
  const masked = new THREE.MeshStandardMaterial({ emissive: new THREE.Color(1, 1, 1), emissiveIntensity: 20 });
  const wall = new THREE.MeshStandardMaterial();
  const root = new THREE.Group();
  const mirrored = panel(lamp);
  mirrored.scale.set(-1, 1, 1);
  mirrored.position.set(5, 0, 0);
  root.add(panel(masked), mirrored, panel(wall));
  // glTF order: wall 0, lamp 1, masked 2 (its alpha mode MASK: not a solid panel).
  const parser = {
    json: { materials: [{}, {}, { alphaMode: 'MASK' }] },
    associations: new Map([[wall, { materials: 0 }], [lamp, { materials: 1 }], [masked, { materials: 2 }]]),
  };
  const { materials, corners, triangleMaterial } = sceneEmitters(root, parser);
  assert.equal(materials.length, 3);
  assert.deepEqual(materials.map((m) => m.opaque), [true, true, false]);
  assert.deepEqual(materials[1].emission, [10, 10, 10]);
  assert.deepEqual(triangleMaterial, [2, 2, 1, 1]);  // the wall's triangles are not walked
  assert.equal(corners.length, 4 * 9);
  const set = extractAreaLights(materials, corners, triangleMaterial, 0);
  assert.deepEqual(set.clientLitMaterial, [0, 1, 0]);  // the masked emitter stays with the probes
  assert.deepEqual(set.lights[0].normal.map((v) => Math.round(v)), [0, -1, 0]);  // mirrored, still facing down
  assert.deepEqual(set.lights[0].centroid.map((v) => Math.round(v * 100) / 100), [4.5, 2, 0.5]);
});
