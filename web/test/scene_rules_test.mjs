// The page's rules for the scene a stream names (web/src/scene_rules.js), run in Node: what a
// hostile bus could name is refused with a message, and a scene file is always fetched from inside
// the scene folder.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { checkedManifest, printable, safePath, sceneFileUrl, sha256Hex } from '../src/scene_rules.js';

const hashOf = (text) => sha256Hex(new TextEncoder().encode(text));
const manifestOf = (files, scene = 's.gltf') =>
  JSON.stringify({ files, format: 1, lighting: {}, scene: { gltf: scene } });
const file = (path, bytes = 4) => ({ bytes, path, sha256: 'a'.repeat(64) });

test('a manifest that is not the stream\'s is refused', async () => {
  const m = manifestOf([file('s.gltf')]);
  await assert.rejects(checkedManifest(m, 'b'.repeat(64)), /does not match its hash/);
  assert.equal((await checkedManifest(m, await hashOf(m))).scene.gltf, 's.gltf');
});

test('paths that leave the package are refused by name, escaped', async () => {
  for (const path of ['../secret', '/etc/passwd', 'a/../../b', 'file:x', 'https://evil/x', 'a\\b', 'a//b', './a', 'a\x1b[2J']) {
    const m = manifestOf([file('s.gltf'), file(path)]);
    await assert.rejects(checkedManifest(m, await hashOf(m)), (e) => /unsafe path/.test(e.message) && !e.message.includes('\x1b'), path);
  }
  assert.equal(printable('\x1b[2J\x9b'), '\\x1b[2J\\x9b');
  assert.ok(safePath('textures/wall a.png') && safePath('%2e%2e/x'));
});

test('sizes must be whole and their sum bounded', async () => {
  for (const files of [[file('s.gltf', -1)], [file('s.gltf', 1.5)], [file('s.gltf', 2 ** 53)],
                       [file('s.gltf', 2 ** 29), file('a', 2 ** 29), file('b', 1)]]) {
    const m = manifestOf(files);
    await assert.rejects(checkedManifest(m, await hashOf(m)), /no size|over \d+ bytes/);
  }
  const unlisted = manifestOf([file('a.bin')]);
  await assert.rejects(checkedManifest(unlisted, await hashOf(unlisted)), /not among its files/);
});

test('a scene file is fetched from inside the scene folder only', () => {
  const folder = new URL('http://host/scenes/room/');
  assert.equal(sceneFileUrl('textures/wall a.png', folder).href, 'http://host/scenes/room/textures/wall%20a.png');
  assert.equal(sceneFileUrl('%2e%2e/secret', folder).href, 'http://host/scenes/room/%252e%252e/secret');
  assert.equal(sceneFileUrl('..%2Fx', folder).href, 'http://host/scenes/room/..%252Fx');
});
