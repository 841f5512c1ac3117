// The page's distant light (web/src/environment.js), run in Node: maps decoded with their rows top
// first as the native loader holds them, and maps or lighting the page cannot use refused by name.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { test } from 'node:test';
import { decodeEnvironment, lightingBackground } from '../src/environment.js';

const here = new URL('.', import.meta.url);
const dawn = readFileSync(new URL('../../tests/data/envmaps/kiara_1_dawn_1k.hdr', here));
const buffer = (b) => b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength);

test('an .hdr map decodes top row first, finite and non-negative', async () => {
  const m = await decodeEnvironment(buffer(dawn), 'dawn.hdr');
  assert.deepEqual([m.width, m.height], [1024, 512]);
  const mean = (row) => {
    let sum = 0;
    for (let x = 0; x < m.width; ++x) sum += m.rgba[(row * m.width + x) * 4 + 2];
    return sum / m.width;
  };
  // The sky (top) is brighter in blue than the ground (bottom) in a dawn map.
  assert.ok(mean(10) > mean(500), `top ${mean(10)} vs bottom ${mean(500)}`);
});

test('maps and lighting the page cannot use are refused by name', async () => {
  await assert.rejects(decodeEnvironment(buffer(dawn), 'dawn.hdr', 512), /dawn.hdr: 1024x512 is not a map this page takes/);
  await assert.rejects(decodeEnvironment(new ArrayBuffer(16), 'x.png'), /x.png: not .hdr or .exr/);
  await assert.rejects(decodeEnvironment(new TextEncoder().encode('#?RADIANCE\ngarbage').buffer, 'bad.hdr'), /bad.hdr: unreadable/);
  const fetchFile = async () => buffer(dawn);
  await assert.rejects(lightingBackground({ sky: [1, 1, 1], environment: {} }, 8192, fetchFile), /not \{\} or one known kind/);
  await assert.rejects(lightingBackground({ fog: 1 }, 8192, fetchFile), /not \{\} or one known kind/);
  await assert.rejects(lightingBackground({ sky: [1, -1, 1] }, 8192, fetchFile), /sky is not 3 numbers >= 0/);
  await assert.rejects(lightingBackground({ environment: { file: 'a.hdr', intensity: -1, rotation_deg: 0 } }, 8192, fetchFile),
                       /needs a file, an intensity >= 0 and a rotation/);
  assert.equal(await lightingBackground({}, 8192, fetchFile), null);
  assert.equal(await lightingBackground(undefined, 8192, fetchFile), null);
  const mesh = await lightingBackground({ environment: { file: 'dawn.hdr', intensity: 2, rotation_deg: 90 } }, 8192, fetchFile);
  assert.ok(mesh.userData.probecastBackground);
});
