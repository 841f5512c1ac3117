// What the page accepts of the scene a stream names over the bus: the rules the native viewer
// holds to (docs/ARCHITECTURE.md, "A viewer's trust model"). No DOM: web/test/scene_rules_test.mjs
// runs them in Node.

export const kMaxManifestBytes = 256 * 1024;
export const kMaxPackageFiles = 4096;
export const kMaxSceneBytes = 2 ** 30;

export async function sha256Hex(bytes) {
  const d = new Uint8Array(await crypto.subtle.digest('SHA-256', bytes));
  return Array.from(d, (b) => b.toString(16).padStart(2, '0')).join('');
}

// A path a package may name: relative, '/'-separated, without empty, '.' or '..' parts, control
// characters, backslashes or a URI scheme.
export function safePath(p) {
  if (typeof p !== 'string' || !p.length || p.length > 1024 || p.startsWith('/')) return false;
  if (p.split('/')[0].includes(':')) return false;
  return p.split('/').every((part) => part !== '' && part !== '.' && part !== '..' && !/[\\\x00-\x1f\x7f]/.test(part));
}

// Text from the wire as it may be shown: control characters as \xNN, at most 200 characters.
export function printable(text) {
  return String(text).slice(0, 200).replace(/[\x00-\x1f\x7f-\x9f]/g, (c) => '\\x' + c.charCodeAt(0).toString(16).padStart(2, '0'));
}

// The manifest of the stream's scene, parsed once it is known to be the stream's (its SHA-256 is
// the stream's scene hash) and to name only safe paths with whole sizes under the limit, its glTF
// among them. Throws an Error naming the first thing wrong.
export async function checkedManifest(manifestText, hash) {
  if (manifestText.length > kMaxManifestBytes) throw new Error(`the stream's scene manifest is over ${kMaxManifestBytes} bytes`);
  if ((await sha256Hex(new TextEncoder().encode(manifestText))) !== hash)
    throw new Error('the stream\'s scene manifest does not match its hash');
  const manifest = JSON.parse(manifestText);
  if (!manifest || !Array.isArray(manifest.files) || manifest.files.length > kMaxPackageFiles || !manifest.scene)
    throw new Error('the stream\'s scene manifest has no files list or no scene');
  let total = 0;
  for (const f of manifest.files) {
    if (!safePath(f.path)) throw new Error(`the stream's scene names an unsafe path '${printable(f.path)}'`);
    if (!Number.isSafeInteger(f.bytes) || f.bytes < 0) throw new Error(`the stream's scene gives '${printable(f.path)}' no size`);
    total += f.bytes;
    if (total > kMaxSceneBytes) throw new Error(`the stream's scene is over ${kMaxSceneBytes} bytes`);
  }
  if (manifest.scene.gltf !== undefined && !manifest.files.some((f) => f.path === manifest.scene.gltf))
    throw new Error('the stream\'s scene is not among its files');
  return manifest;
}

// Where a checked path is fetched: inside `folder` (a URL ending in '/'), each part percent-encoded
// so that a name such as "%2e%2e" is a name and not a step up.
export function sceneFileUrl(path, folder) {
  const url = new URL(path.split('/').map(encodeURIComponent).join('/'), folder);
  if (!url.href.startsWith(folder.href)) throw new Error(`scene file ${printable(path)} is outside the scene folder`);
  return url;
}
