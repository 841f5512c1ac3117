// The npm package (build/web-package/probecast-three-*.tgz) as an application gets it: unpacked into
// a fresh app folder's node_modules beside three and nats.ws, imported in Node (its exports), and
// its example page, copied to the app folder's top, lighting the Cornell box from a real stream in
// headless Chromium against the native client's picture (browser_test.mjs, the example as the page).
//   node web/test/package_test.mjs PROBECAST TARBALL|FOLDER-WITH-ONE SCENE.gltf OUT
import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, readdirSync, rmSync, statSync, symlinkSync, copyFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const [probecast, packed, sceneGltf, out] = process.argv.slice(2).map((a) => resolve(a));
const tarballs = statSync(packed).isDirectory() ? readdirSync(packed).filter((f) => f.endsWith('.tgz')).map((f) => join(packed, f)) : [packed];
assert.equal(tarballs.length, 1, `one package in ${packed} (${tarballs.length})`);
const tarball = tarballs[0];
const webDir = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const site = join(out, 'site');
rmSync(out, { recursive: true, force: true });
const pkg = join(site, 'node_modules', 'probecast-three');
mkdirSync(pkg, { recursive: true });
execFileSync('tar', ['xzf', tarball, '-C', pkg, '--strip-components=1']);

// What npm would install: the manifest, the module, the codec beside it, the example, the README.
const manifest = JSON.parse(readFileSync(join(pkg, 'package.json'), 'utf8'));
assert.equal(manifest.name, 'probecast-three');
assert.match(manifest.version, /^\d+\.\d+\.\d+$/);
assert.equal(manifest.type, 'module');
assert.ok(existsSync(join(pkg, manifest.exports['.'])), 'the package\'s entry is in it');
assert.deepEqual(Object.keys(manifest.peerDependencies).sort(), ['nats.ws', 'three']);
for (const f of ['dist/probecast_codec.mjs', 'dist/probecast_codec.wasm', 'dist/licenses/zstd.LICENSE', 'README.md', 'LICENSE',
  'example/index.html', 'example/example.js'])
  assert.ok(existsSync(join(pkg, f)), `the package holds ${f}`);
assert.match(readFileSync(join(pkg, 'README.md'), 'utf8'), /new ProbeStream\(/);
const bundled = readFileSync(join(pkg, manifest.exports['.']), 'utf8');
assert.ok(!/REVISION\s*=\s*["']\d+/.test(bundled), 'three.js is not bundled into the module (the application brings its own)');
console.log(`ok: the package ${manifest.name}@${manifest.version} holds its module, codec, example and README`);

// The application's own three and nats.ws, as npm would put them beside the package.
for (const dep of ['three', 'nats.ws']) symlinkSync(join(webDir, 'node_modules', dep), join(site, 'node_modules', dep), 'dir');
const mod = await import(pathToFileURL(join(pkg, manifest.exports['.'])).href);
for (const name of ['ProbeStream', 'ProbeLighting', 'AreaLighting', 'lightingBackground', 'loadCodec', 'useProbecastCurve', 'checkedManifest'])
  assert.equal(typeof mod[name], 'function', `the package exports ${name}`);
console.log('ok: the module imports in Node, its exports there (the codec is loaded in the browser below)');
assert.throws(() => new mod.ProbeStream({}), /no bus address/);
assert.throws(() => new mod.ProbeStream({ servers: 'ws://x', stream: '../x' }), /not a stream name/);

// The example at the app folder's top, lighting the scene from a real stream.
for (const f of readdirSync(join(pkg, 'example'))) copyFileSync(join(pkg, 'example', f), join(site, f));
const run = spawnSync(process.execPath, [join(webDir, 'test', 'browser_test.mjs'), probecast, site, sceneGltf, join(out, 'browser')], {
  stdio: 'inherit', env: { ...process.env, PROBECAST_WEB_QUICK: '1', PROBECAST_WEB_SCENE_FILE: '1' },
});
if (run.status !== 0) process.exit(run.status ?? 1);
console.log('npm package ok');
