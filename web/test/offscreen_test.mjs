// The maps' materials (web/src/offscreen.js), run in Node: a cut-out is drawn as the application's
// material stands when the map is drawn, not as it stood the first time.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import * as THREE from 'three';
import { MapMaterials } from '../src/offscreen.js';

const kShader = 'void main() { gl_FragColor = vec4(1.0); }';

test('a cut-out follows its material: map, cutoff and opacity', () => {
  const maps = new MapMaterials(kShader, {});
  const first = new THREE.Texture(), second = new THREE.Texture();
  const m = new THREE.MeshStandardMaterial({ map: first, alphaTest: 0.5, opacity: 1 });
  const d = maps.for(m);
  assert.notEqual(d, maps.solid);
  assert.equal(d.uniforms.alphaTest.value, 0.5);
  assert.equal(d.uniforms.map.value, first);
  const version = d.version;

  m.alphaTest = 0.25;
  m.opacity = 0.75;
  assert.equal(maps.for(m), d, 'the same map material, not a new one per draw');
  assert.equal(d.uniforms.alphaTest.value, 0.25);
  assert.equal(d.alphaTest, 0.25);
  assert.equal(d.uniforms.opacity.value, 0.75);
  assert.equal(d.version, version, 'no new shader for new values');

  m.map = second;
  second.channel = 1;
  assert.equal(maps.for(m), d);
  assert.equal(d.uniforms.map.value, second);
  assert.equal(d.map, second, 'the shader reads the new map and its uv channel');
  assert.equal(d.uniforms.mapTransform.value, second.matrix);
  assert.ok(d.version > version, 'the shader is made again');

  const remade = d.version;
  second.channel = 2;  // the same map, read from another uv channel
  assert.equal(maps.for(m), d);
  assert.ok(d.version > remade, 'the shader is made again for the new channel');

  m.alphaTest = 0;  // no longer a cut-out: drawn solid
  assert.equal(maps.for(m), maps.solid);
  m.alphaTest = 0.5;
  assert.equal(maps.for(m), d);
  assert.equal(d.uniforms.alphaTest.value, 0.5);
  maps.dispose();
});

test('a solid material, or a cutoff without a map, is drawn solid', () => {
  const maps = new MapMaterials(kShader, {});
  assert.equal(maps.for(new THREE.MeshStandardMaterial()), maps.solid);
  assert.equal(maps.for(new THREE.MeshStandardMaterial({ alphaTest: 0.5 })), maps.solid);
  assert.equal(maps.for(undefined), maps.solid);
  maps.dispose();
});
