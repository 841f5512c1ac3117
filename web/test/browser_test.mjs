// The browser viewer end to end, in headless Chromium against a real nats-server (WebSocket
// listener, token) and a real `probecast serve` publishing to it:
//   - the page connects, holds every brick, and its volume's checksum equals the native client's;
//   - it renders (a screenshot), and reports its page weight, decode and frame times;
//   - a wrong token gets a clear message;
//   - the producer restarts (a new epoch): the page follows and holds the same volume again.
// Usage: node browser_test.mjs PROBECAST WEB_DIR SCENE_GLTF WORK_DIR
import { spawn, execFileSync } from 'node:child_process';
import { createServer } from 'node:http';
import { readFileSync, writeFileSync, mkdirSync, rmSync, statSync, existsSync, readdirSync } from 'node:fs';
import { dirname, join, extname, resolve, basename, sep } from 'node:path';
import { chromium } from 'playwright-core';

const [probecast, webDir, sceneGltf, work] = process.argv.slice(2).map((p) => resolve(p));
// PROBECAST_WEB_LKG=visual.json: also drive that Looking Glass from the page (lkg=, views of
// PROBECAST_WEB_LKG_VIEW) and set its panel image against the native viewer's.
const lkgCalibration = process.env.PROBECAST_WEB_LKG ? resolve(process.env.PROBECAST_WEB_LKG) : '';
if (!work) throw new Error('usage: node browser_test.mjs PROBECAST WEB_DIR SCENE_GLTF WORK_DIR');
rmSync(work, { recursive: true, force: true });
mkdirSync(work, { recursive: true });
const sceneDir = dirname(sceneGltf);
const children = [];
const deadline = setTimeout(() => { console.error('browser test: over 240 s'); cleanup(); process.exit(1); }, 240000);

function cleanup() {
  for (const c of children) try { c.kill('SIGTERM'); } catch {}
}
process.on('exit', cleanup);

function start(cmd, args, log) {
  const out = [];
  const child = spawn(cmd, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  child.stdout.on('data', (d) => out.push(d));
  child.stderr.on('data', (d) => out.push(d));
  child.on('exit', () => writeFileSync(join(work, log), Buffer.concat(out)));
  child.text = () => Buffer.concat(out).toString();
  children.push(child);
  return child;
}

async function until(what, test, seconds = 30) {
  const end = Date.now() + seconds * 1000;
  for (;;) {
    const v = await test();
    if (v) return v;
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await new Promise((r) => setTimeout(r, 100));
  }
}

function check(ok, message) {
  if (!ok) { console.error('FAILED: ' + message); cleanup(); process.exit(1); }
  console.log('ok: ' + message);
}

const base = 20000 + Math.floor(Math.random() * 20000);
const ports = { nats: base, ws: base + 1, grpc: base + 2, http: base + 3 };
// '+', '/' and '=' as a base64 token has them: the address carries it as it is.
const busToken = 'bus+' + Math.random().toString(36).slice(2) + '/x=';

// nats-server: JetStream, a token, and a WebSocket listener on loopback (plain ws: loopback only).
writeFileSync(join(work, 'bus-token'), busToken + '\n');
writeFileSync(join(work, 'nats.conf'), `authorization { token: "${busToken}" }
websocket { listen: "127.0.0.1:${ports.ws}", no_tls: true }
`);
const natsBin = ['/usr/sbin/nats-server', '/usr/bin/nats-server'].find(existsSync) || 'nats-server';
const natsArgs = ['-c', join(work, 'nats.conf'), '-a', '127.0.0.1', '-p', String(ports.nats), '-js', '-sd', join(work, 'nats')];
let nats = start(natsBin, natsArgs, 'nats.log');

// PROBECAST_WEB_AREA_LIGHTS: bake's --area-lights (bake's default, on: the page draws the emitters
// the rule leaves to viewers, as the native client does; off: the probes hold every emitter).
// PROBECAST_WEB_SPP: paths per probe (the README's screenshot takes 512).
// PROBECAST_WEB_TIME: the scene time the probes are traced at (an animated scene is posed there).
const sceneTime = process.env.PROBECAST_WEB_TIME || '0';
// PROBECAST_WEB_ENVIRONMENT: an .hdr or .exr map around the scene (bake, serve and view take it; the
// page fetches it from the scene folder's environment/, as the scene's package names it).
const environment = process.env.PROBECAST_WEB_ENVIRONMENT || '';
// PROBECAST_WEB_SKY: R,G,B, a uniform sky instead.
const envArgs = environment ? ['--environment', environment]
  : process.env.PROBECAST_WEB_SKY ? ['--sky', ...process.env.PROBECAST_WEB_SKY.split(',')] : [];
execFileSync(probecast, ['bake', ...envArgs, '--scene', sceneGltf, ...(process.env.PROBECAST_WEB_AREA_LIGHTS ? ['--area-lights', process.env.PROBECAST_WEB_AREA_LIGHTS] : []), '--grid', '6,6,6', '--spp', process.env.PROBECAST_WEB_SPP || '32', '--updates', '1',
  '--time', sceneTime, '--out', join(work, 'served.pcpv')], { stdio: 'ignore' });
const serveArgs = ['serve', ...envArgs, '--probes', join(work, 'served.pcpv'), '--scene', sceneGltf, '--listen', `127.0.0.1:${ports.grpc}`,
  '--plaintext', '--token', 't0k', '--seconds', '200', '--publish', `nats://127.0.0.1:${ports.nats}`, '--stream', 'web',
  '--nats-token-file', join(work, 'bus-token'), '--nats-plaintext'];
let serve = start(probecast, serveArgs, 'serve.log');
await until('serve to listen', () => /on port/.test(serve.text()));

// The native client's checksum of the same stream.
const sub = execFileSync(probecast, ['subscribe', '--connect', `127.0.0.1:${ports.grpc}`, '--token', 't0k', '--seconds', '2']).toString();
const native = /volume checksum ([0-9a-f]{8})/.exec(sub)?.[1];
check(!!native, `the native client reports a checksum (${native})`);

// Static files: the page at /, the scene's folder at /scene/.
const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.wasm': 'application/wasm',
  '.gltf': 'model/gltf+json', '.bin': 'application/octet-stream', '.png': 'image/png', '.jpg': 'image/jpeg' };
const served = new Map();
const http = createServer((req, res) => {
  const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
  const [root, rel] = environment && path === `/scene/environment/${basename(environment)}` ? [dirname(resolve(environment)), basename(environment)]
    : path.startsWith('/scene/') ? [sceneDir, path.slice(7)]
    : lkgCalibration && path === '/lkg/visual.json' ? [dirname(lkgCalibration), basename(lkgCalibration)]
    : path.startsWith('/altered/') ? [join(work, 'altered'), path.slice(9)] : [webDir, path === '/' ? 'index.html' : path.slice(1)];
  const file = resolve(root, rel);
  if (!file.startsWith(root + sep) || !existsSync(file) || !statSync(file).isFile()) { res.writeHead(404); res.end(); return; }
  const body = readFileSync(file);
  if (root === webDir) served.set(rel, body.length);
  res.writeHead(200, { 'content-type': types[extname(file)] || 'application/octet-stream' });
  res.end(body);
}).listen(ports.http, '127.0.0.1');

const browser = await chromium.launch({
  executablePath: process.env.PROBECAST_CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--disable-gpu-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic'],
});
// PROBECAST_WEB_VIEWPORT=WxH: another size (the README's screenshot is 640x480).
const [vw, vh] = (process.env.PROBECAST_WEB_VIEWPORT || '320x240').split('x').map(Number);
const page = await browser.newPage({ viewport: { width: vw || 320, height: vh || 240 } });
const consoleLines = [];
page.on('console', (m) => consoleLines.push(m.text()));
page.on('pageerror', (e) => consoleLines.push('page error: ' + e.message));
// PROBECAST_WEB_SCENE_FILE=1: scene= names the glTF file, not its folder (the npm package's example).
const sceneParam = process.env.PROBECAST_WEB_SCENE_FILE ? `/scene/${basename(sceneGltf)}` : '/scene/';
const url = (token) => `http://127.0.0.1:${ports.http}/index.html?nats=ws://127.0.0.1:${ports.ws}&stream=web&scene=${sceneParam}#token=${token}`;
const probe = () => page.evaluate(() => ({ ...window.probecast }));

try {
  const t0 = Date.now();
  await page.goto(url(busToken));
  // (Sponza's 216 depth cubes take about 40 s in SwiftShader on 2 cores, a batch a frame.)
  const s = await until('the page to hold the whole volume and its probes\' visibility', async () => {
    const v = await probe();
    return v.bricks > 0 && v.bricksHeld === v.bricks && v.checksum && v.sceneLoaded && v.frames > 10 && v.visibility?.ready ? v : null;
  }, 150);
  const firstVolumeMs = Date.now() - t0;
  check(s.checksum === native, `the page's decoded volume equals the native client's (checksum ${s.checksum} vs ${native})`);
  check(!s.error, `no error on the page (${s.error || 'none'})`);
  check(!s.warning, `no warning on the page (${s.warning || 'none'})`);
  await new Promise((r) => setTimeout(r, 500));  // the status line's next refresh
  await page.screenshot({ path: join(work, 'page.png') });
  // The same camera rendered by the native raster client from the same probes: PSNR of the page's
  // canvas against it, both 8-bit pictures through the same curve.
  const nativeText = execFileSync(probecast, ['view', ...envArgs, '--scene', sceneGltf, '--probes', join(work, 'served.pcpv'), '--repr', s.representation,
    '--time', sceneTime, '--views', 'mono', '--size', `${vw || 320}x${vh || 240}`, '--out', join(work, 'native')], { encoding: 'utf8' });
  // Client area lights: the page draws those the native client draws (none where the probes hold
  // every emitter), and every shader the page uses compiles.
  const nativeLights = Number((/client area lights on .*: (\d+) lights/.exec(nativeText) || [0, 0])[1]);
  // Probe visibility: the page weighs the probes by depth moments it made itself, for every probe
  // the native client made them for.
  const nativeVisible = Number((/probe visibility for (\d+) probes/.exec(nativeText) || [0, 0])[1]);
  const tri = s.visibility.triangles;
  console.log(`the page's probe visibility: ${s.visibility.probes} probes made in ${s.visibility.ms.toFixed(0)} ms (${s.visibility.drawingMs.toFixed(0)} ms of it drawing them, ${s.visibility.batches} batches)` +
              (tri ? `, the still geometry's ${tri.scene} triangles drawn as ${tri.proxy}` : ', the scene as it is'));
  check(nativeVisible > 0 && s.visibility.probes === nativeVisible, `the page made visibility for the native client's ${nativeVisible} probes (${s.visibility.probes})`);
  if (process.env.PROBECAST_WEB_TIME) {
    // When the map was begun before the scene was posed at the stream's time (the volume came
    // first), the probes near what moved are drawn again, and only those.
    await new Promise((r) => setTimeout(r, 3000));
    const v = (await probe()).visibility;
    if (v.redrawn > 0) {
      console.log(`the page drew ${v.redrawn} probes' cubes again after the scene was posed`);
      check(v.redrawn < v.probes, `only probes within reach of what moved (${v.redrawn} of ${v.probes})`);
    } else console.log('the map was begun with the scene already posed: nothing to draw again');
  }
  check((s.areaLights || 0) === nativeLights, `the page draws the native client's ${nativeLights} client area lights (${s.areaLights || 0})`);
  if (process.env.PROBECAST_WEB_AREA_LIGHTS === 'on') check(nativeLights > 0, `the scene has client area lights (${nativeLights})`);
  const shaderErrors = consoleLines.filter((l) => /Shader Error|Can not resolve #include|WebGLProgram/.test(l));
  check(!shaderErrors.length, `every shader of the page compiles${shaderErrors.length ? ": " + shaderErrors[0].slice(0, 2000) : ""}`);
  const nativePng = 'data:image/png;base64,' + readFileSync(join(work, 'native', 'quilt.png')).toString('base64');
  const compare = (png, on = page) => on.evaluate(async (url) => {
    const img = new Image();
    img.src = url;
    await img.decode();
    const view = document.getElementById('view');
    const pixels = (source) => {
      const c = document.createElement('canvas');
      c.width = view.width;
      c.height = view.height;
      const g = c.getContext('2d');
      g.drawImage(source, 0, 0);
      return g.getImageData(0, 0, c.width, c.height).data;
    };
    const a = pixels(view), b = pixels(img);
    let se = 0;
    for (let i = 0; i < a.length; i += 4) for (let k = 0; k < 3; ++k) se += (a[i + k] - b[i + k]) ** 2;
    const mse = se / (3 * (a.length / 4));
    return { psnr: 10 * Math.log10((255 * 255) / Math.max(mse, 1e-12)), canvas: view.toDataURL('image/png'),
             size: [view.width, view.height], nativeSize: [img.naturalWidth, img.naturalHeight] };
  }, png);
  const compared = await compare(nativePng);
  writeFileSync(join(work, 'canvas.png'), Buffer.from(compared.canvas.split(',')[1], 'base64'));
  check(compared.size.join('x') === compared.nativeSize.join('x'), `the native render has the page's size (${compared.nativeSize.join('x')})`);
  console.log(`page against the native raster client, same camera and probes: ${compared.psnr.toFixed(2)} dB PSNR`);
  const minPsnr = Number(process.env.PROBECAST_WEB_MIN_PSNR || 0);
  check(compared.psnr >= minPsnr, `the page's picture is within ${minPsnr} dB of the native client's (${compared.psnr.toFixed(2)} dB)`);
  if (Number(sceneTime) !== 0) {
    // The page poses the scene at the stream's time: the native picture of the scene at rest
    // (same probes) is farther from it.
    execFileSync(probecast, ['view', ...envArgs, '--scene', sceneGltf, '--probes', join(work, 'served.pcpv'), '--repr', s.representation, '--time', '0',
      '--views', 'mono', '--size', `${vw || 320}x${vh || 240}`, '--out', join(work, 'native-at-rest')], { stdio: 'ignore' });
    const atRest = await compare('data:image/png;base64,' + readFileSync(join(work, 'native-at-rest', 'quilt.png')).toString('base64'));
    check(atRest.psnr < compared.psnr - 3, `the page poses the scene at the stream's time ${sceneTime} s (${compared.psnr.toFixed(2)} dB against the native picture then, ${atRest.psnr.toFixed(2)} dB against the scene at rest)`);
  }
  if (lkgCalibration) {
    // The same camera on a Looking Glass: the page's panel image against the native viewer's.
    // 'model': each view at the display model's own size, in the page and natively.
    const view = process.env.PROBECAST_WEB_LKG_VIEW || '96x128';
    const lkg = await browser.newPage({ viewport: { width: 320, height: 240 } });
    lkg.on('pageerror', (e) => consoleLines.push('lkg page error: ' + e.message));
    const lkgParams = (view === 'model' ? '&lkg=/lkg/visual.json' : `&lkg=/lkg/visual.json&lkgview=${view}`) + '&timing=1';
    await lkg.goto(url(busToken).replace('&scene=', `${lkgParams}&scene=`));
    const shown = await until('the Looking Glass page to draw the panel', async () => {
      const v = await lkg.evaluate(() => ({ ...window.probecast }));
      if (v.error) throw new Error('the Looking Glass page says: ' + v.error);
      return v.sceneLoaded && v.checksum === native && v.lookingGlass && v.frames > 5 && v.drawMs > 0 ? v : null;
    }, 90);
    execFileSync(probecast, ['view', ...envArgs, '--scene', sceneGltf, '--probes', join(work, 'served.pcpv'), '--repr', s.representation, '--time', sceneTime,
      '--looking-glass', lkgCalibration, ...(view === 'model' ? [] : ['--size', view]), '--out', join(work, 'native-lkg')],
    { stdio: 'ignore' });
    const panel = await compare('data:image/png;base64,' + readFileSync(join(work, 'native-lkg', 'looking_glass.png')).toString('base64'), lkg);
    writeFileSync(join(work, 'lkg_canvas.png'), Buffer.from(panel.canvas.split(',')[1], 'base64'));
    const g = shown.lookingGlass;
    check(panel.size.join('x') === panel.nativeSize.join('x') && panel.size.join('x') === g.panel.join('x'),
      `the page draws the panel at its own size (${panel.size.join('x')}; native ${panel.nativeSize.join('x')})`);
    console.log(`Looking Glass ${g.model} (${g.views} views of ${g.view.join('x')}, ${g.cells} subpixel cells): page against the native panel image ${panel.psnr.toFixed(2)} dB PSNR, ${shown.drawMs.toFixed(1)} ms a frame drawn, ${shown.frameMs.toFixed(1)} ms between frames`);
    const minLkg = Number(process.env.PROBECAST_WEB_LKG_MIN_PSNR || 0);
    check(panel.psnr >= minLkg, `the page's panel image is within ${minLkg} dB of the native one (${panel.psnr.toFixed(2)} dB)`);
    await lkg.close();
  }
  if (process.env.PROBECAST_WEB_QUICK) {  // the picture only
    console.log('browser viewer picture ok');
    await browser.close().catch(() => {});
    http.close();
    cleanup();
    process.exit(0);
  }
  const f0 = (await probe()).frames;
  await new Promise((r) => setTimeout(r, 1000));
  const f1 = (await probe()).frames;
  check(f1 > f0, `the page keeps rendering (${f1 - f0} frames in 1 s)`);

  // The producer restarts: a new epoch; the page follows and ends with the same volume.
  serve.kill('SIGTERM');
  await until('serve to stop', () => serve.exitCode !== null || serve.signalCode !== null, 10);
  const epochsBefore = (await probe()).epochs;
  await new Promise((r) => setTimeout(r, 1000));
  const stalled = await probe();
  check(stalled.frames > f1, 'frames go on while the producer is away');
  serve = start(probecast, serveArgs, 'serve2.log');
  const after = await until('the page to take the new epoch', async () => {
    const v = await probe();
    return v.epochs > epochsBefore && v.bricksHeld === v.bricks && v.checksum === native ? v : null;
  }, 60);
  check(after.checksum === native, `after the producer's restart the page holds the same volume (epochs ${after.epochs})`);

  // The bus restarts (same store): the page reconnects and holds the producer's volume again.
  nats.kill('SIGTERM');
  await until('nats-server to stop', () => nats.exitCode !== null || nats.signalCode !== null, 10);
  await until('the page to notice', async () => (await probe()).connection !== 'connected', 20);
  const framesWithoutBus = (await probe()).frames;
  nats = start(natsBin, natsArgs, 'nats2.log');
  const back = await until('the page to reconnect to the bus', async () => {
    const v = await probe();
    return v.connection === 'connected' && v.frames > framesWithoutBus && v.bricksHeld === v.bricks && v.checksum === native ? v : null;
  }, 60);
  check(back.checksum === native, `after the bus restarts the page reconnects and holds the same volume (${back.connection})`);

  // WebXR: a Meta Quest 3 emulated in the page (iwer); the button opens an immersive session and
  // both eyes are drawn, side by side on the canvas, from the probes.
  const xr = await browser.newPage({ viewport: { width: vw || 320, height: vh || 240 } });
  xr.on('pageerror', (e) => consoleLines.push('xr page error: ' + e.message));
  await xr.goto(url(busToken).replace('&scene=', '&xr=emulate&scene='));
  await until('the XR page to hold the volume', async () => {
    const v = await xr.evaluate(() => ({ ...window.probecast }));
    return v.sceneLoaded && v.checksum === native && v.xr === 'available' && v.visibility?.ready ? v : null;
  }, 150);
  await xr.click('#xr', { timeout: 30000 });
  const inXr = await until('frames of the immersive session', async () => {
    const v = await xr.evaluate(() => ({ ...window.probecast }));
    return v.xr === 'immersive' && v.xrFrames > 10 ? v : null;
  }, 60);
  const eyes = await xr.evaluate(() => {
    const view = document.getElementById('view');
    const c = document.createElement('canvas');
    c.width = view.width;
    c.height = view.height;
    const g = c.getContext('2d');
    g.drawImage(view, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    const half = c.width / 2;
    let left = 0, right = 0, differ = 0;
    for (let y = 0; y < c.height; ++y)
      for (let x = 0; x < half; ++x) {
        const a = (y * c.width + x) * 4, b = (y * c.width + x + half) * 4;
        left += d[a] + d[a + 1] + d[a + 2];
        right += d[b] + d[b + 1] + d[b + 2];
        differ += Math.abs(d[a] - d[b]) + Math.abs(d[a + 1] - d[b + 1]) + Math.abs(d[a + 2] - d[b + 2]);
      }
    const n = 3 * half * c.height;
    return { left: left / n, right: right / n, differ: differ / n, size: [c.width, c.height], png: view.toDataURL('image/png') };
  });
  writeFileSync(join(work, 'xr_eyes.png'), Buffer.from(eyes.png.split(',')[1], 'base64'));
  await xr.screenshot({ path: join(work, 'xr_page.png') });
  check(eyes.left > 5 && eyes.right > 5 && Math.abs(eyes.left - eyes.right) < 0.2 * eyes.left, `both eyes are drawn, alike (mean ${eyes.left.toFixed(1)} and ${eyes.right.toFixed(1)} of 255, ${inXr.xrFrames} XR frames, ${eyes.size.join('x')})`);
  check(eyes.differ > 0.3, `the eyes see from two places (mean difference ${eyes.differ.toFixed(2)} of 255)`);
  await xr.close();

  // A wrong token: a clear message, no volume.
  const bad = await browser.newPage({ viewport: { width: 320, height: 240 } });
  await bad.goto(url('wrong-token'));
  const refused = await until('the refusal', async () => {
    const v = await bad.evaluate(() => ({ ...window.probecast, text: document.getElementById('status').textContent }));
    return v.connection === 'refused' && /not authorised/.test(v.text) ? v : null;
  }, 30);
  check(/not authorised/.test(refused.text), `a wrong token is refused with a message: "${refused.error}"`);

  // A scene folder whose glTF is not the stream's (one byte more): refused, with the reason.
  mkdirSync(join(work, 'altered'), { recursive: true });
  for (const f of readdirSync(sceneDir)) writeFileSync(join(work, 'altered', f), readFileSync(join(sceneDir, f)));
  writeFileSync(join(work, 'altered', basename(sceneGltf)), Buffer.concat([readFileSync(sceneGltf), Buffer.from(' ')]));
  const altered = await browser.newPage({ viewport: { width: 320, height: 240 } });
  await altered.goto(url(busToken).replace('&scene=/scene/', '&scene=/altered/'));
  const mismatch = await until('the scene to be refused', async () => {
    const v = await altered.evaluate(() => ({ ...window.probecast }));
    return /does not match the stream/.test(v.error) ? v : null;
  }, 30);
  check(!mismatch.sceneLoaded, `a scene that is not the stream's is refused: "${mismatch.error}"`);
  // Put right, the page picks the files up by itself and the message goes.
  writeFileSync(join(work, 'altered', basename(sceneGltf)), readFileSync(sceneGltf));
  const mended = await until('the mended scene to load', async () => {
    const v = await altered.evaluate(() => ({ ...window.probecast }));
    return v.sceneLoaded && !v.error ? v : null;
  }, 30);
  check(mended.sceneLoaded && !mended.error, 'once the scene folder is the stream\'s, the page loads it and the error goes');
  await altered.close();

  // A stream no producer publishes, and a bus that is not there: each named on the page.
  const named = async (address, what, pattern) => {
    const p = await browser.newPage({ viewport: { width: 320, height: 240 } });
    await p.goto(address);
    const v = await until(what, async () => {
      const s = await p.evaluate(() => ({ ...window.probecast, text: document.getElementById('status').textContent }));
      return pattern.test(s.error) && s.text.includes(s.error) ? s : null;
    }, 30);
    check(true, `${what}: "${v.error}"`);
    await p.close();
  };
  await named(url(busToken).replace('&stream=web', '&stream=nosuch'), 'a missing stream is named', /no stream "nosuch"/);
  await named(url(busToken).replace(`ws://127.0.0.1:${ports.ws}`, 'ws://127.0.0.1:1'), 'an unreachable bus is named', /unreachable/);

  const weight = [...served].filter(([f]) => /\.(js|mjs|wasm|html)$/.test(f)).reduce((a, [, b]) => a + b, 0);
  const report = {
    command: process.argv.join(' '),
    checksum: s.checksum,
    psnr_against_native_db: Number(compared.psnr.toFixed(2)),
    probes: s.bricks,
    page_bytes: weight,
    page_files: Object.fromEntries(served),
    first_volume_ms: firstVolumeMs,
    decode_ms_per_message_median: s.decodeMs,
    frame_ms_median: s.frameMs,
    bytes_received: after.bytes,
  };
  writeFileSync(join(work, 'report.json'), JSON.stringify(report, null, 2) + '\n');
  console.log(JSON.stringify(report));
} catch (e) {
  console.error('FAILED: ' + e.message);
  console.error('page console:\n' + consoleLines.slice(-20).join('\n'));
  console.error('page state: ' + JSON.stringify(await probe().catch(() => ({}))));
  cleanup();
  process.exit(1);
} finally {
  await browser.close().catch(() => {});
  http.close();
  clearTimeout(deadline);
  cleanup();
}
