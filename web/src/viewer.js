// probecast's browser viewer. Subscribes to a producer's probe stream on the bus (nats-server's
// WebSocket listener: the newest message of every brick, then each new version), decodes it with
// the codec compiled to WebAssembly, loads the scene the stream names (every file checked against
// the stream's manifest) and lights it in WebGL2 with three.js: direct light from the scene's
// lights, diffuse indirect light from the probes. It renders every display frame from the newest
// volume it holds, whatever the stream does.
//
// URL: index.html?nats=ws://HOST:PORT&stream=NAME&scene=URL-OF-THE-SCENE-FOLDER#token=TOKEN
// (the token in the fragment: it never reaches a web server's logs). Optional: camera=px,py,pz,tx,ty,tz,fovDeg,
// exposure=X (as the native viewer's --exposure), xr=emulate (a headset emulated in the page, for
// trying WebXR without one), lkg=URL-OF-VISUAL.JSON (drive a Looking Glass: the canvas becomes the
// panel's interleaved image; lkgview=WxH sets the size of each view, by default the model's). Where the browser offers immersive VR, an "Enter VR" button opens a
// session that renders each eye from the same probes, starting where the page's camera stands.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { ProbeStream } from './probe_stream.js';
import { useProbecastCurve, LinearLightView } from './tone_curve.js';
import { lightingBackground } from './environment.js';
import { checkedManifest, printable, sceneFileUrl, sha256Hex } from './scene_rules.js';
import { LookingGlassOutput, parseCalibration } from './looking_glass.js';

const params = new URLSearchParams(location.search);
// The fragment's token=…, percent-decoded but with '+' kept (a base64 token holds '+', which
// form decoding would turn into a space).
function fragmentValue(name) {
  for (const part of location.hash.slice(1).split('&')) {
    const eq = part.indexOf('=');
    if (eq > 0 && part.slice(0, eq) === name) {
      try { return decodeURIComponent(part.slice(eq + 1)); } catch { return part.slice(eq + 1); }
    }
  }
  return null;
}
const config = {
  nats: params.get('nats'),
  stream: params.get('stream') || 'probes',  // serve --stream's default
  scene: params.get('scene'),
  token: fragmentValue('token') || params.get('token') || '',
  camera: params.get('camera'),
  lkg: params.get('lkg'),
  lkgView: params.get('lkgview'),
  // timing=1: each frame waits for the GPU to finish drawing and the time is shown (drawMs), for
  // measurement; the frame interval alone hides drawing that overlaps the next frame.
  timing: params.get('timing') === '1',
};

// What the page shows, and what a test reads (window.probecast).
const state = {
  connection: 'starting',
  error: '',
  checksum: '',
  bricks: 0,
  bricksHeld: 0,
  messages: 0,
  bytes: 0,
  frames: 0,
  frameMs: 0,
  decodeMs: 0,
  sceneHash: '',
  sceneLoaded: false,
  representation: '',
  lastBrickAt: 0,
  epochs: 0,
};
window.probecast = state;

const statusEl = document.getElementById('status');
const canvas = document.getElementById('view');

// A failure the page cannot get past (a wrong address or token: the address must change).
let fatal = '';
function fail(message) {
  fatal = message;
  showErrors();
}

// Failures the page recovers from by itself (the bus, the stream, the scene's files): shown by
// name while they last, gone once put right.
const problems = new Map();
function problem(key, message) {
  if (message) problems.set(key, message);
  else problems.delete(key);
  showErrors();
}

function showErrors() {
  state.error = [fatal, ...problems.values()].filter(Boolean).join('\n');
  statusEl.classList.toggle('error', state.error !== '');
}

if (!/^[A-Za-z0-9_-]+$/.test(config.stream)) fail(`stream name "${config.stream}" is not letters, digits, - and _`);
if (!config.nats) fail('no bus given: open index.html?nats=ws://HOST:PORT&stream=NAME&scene=URL#token=TOKEN');

// ---- rendering -----------------------------------------------------------------------------
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
useProbecastCurve(renderer, Number(params.get('exposure') || 1));  // the native viewer's picture
const linearView = new LinearLightView();  // its anti-aliasing: samples averaged before the curve
renderer.shadowMap.enabled = true;
renderer.shadowMap.type = THREE.PCFSoftShadowMap;
const scene = new THREE.Scene();
let camera = new THREE.PerspectiveCamera(45, 1, 0.01, 1000);
// The stream (web/src/probe_stream.js): the bus, the codec, and the light the materials read.
const stream = config.nats && !fatal ? new ProbeStream({ servers: config.nats, token: config.token, stream: config.stream }) : null;
const lighting = stream?.lighting;

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== w || canvas.height !== h) renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}

let last = performance.now();
const frameTimes = [];
let animation = null;  // the scene's clips, posed at the display time every frame

// The display clock: the newest lighting's scene time, run on at its rate from the producer's wall
// clock (clocks on the page's and the producer's machines are taken to agree, as NTP keeps them).
function displayTime() {
  return stream ? stream.displayTime() : 0;
}

function pose(time) {
  if (!animation) return;
  const tau = animation.length > 0 ? ((time % animation.length) + animation.length) % animation.length : 0;
  for (const a of animation.actions) {
    a.enabled = true;
    a.time = Math.min(tau, a.getClip().duration);
  }
  animation.mixer.update(0);
  state.sceneTime = time;
}

const drawTimes = [];
let areaLightsPosedAt = null;
function frame(now, xrFrame) {
  const drawStart = performance.now();
  pose(displayTime());
  if (state.sceneLoaded) {
    // Lights on moving nodes move: chosen again, and their maps drawn, when the pose changed.
    const moved = animation && state.sceneTime !== areaLightsPosedAt;
    areaLightsPosedAt = state.sceneTime;
    if (moved) stream.setScene(loadedScene.root, loadedScene.parser, renderer);
    stream.drawShadows(renderer, scene, moved);
  }
  if (lookingGlass) {
    // The drawing buffer is the panel, pixel for pixel, whatever size the page shows it at.
    const { screenW, screenH } = lookingGlass.cal;
    if (canvas.width !== screenW || canvas.height !== screenH) renderer.setSize(screenW, screenH, false);
    if (state.sceneLoaded) {
      const distance = Math.max(0.1, sceneCentre.distanceTo(camera.getWorldPosition(new THREE.Vector3())));
      lookingGlass.render(renderer, scene, camera, distance, renderer.toneMappingExposure);
    }
  } else {
    if (renderer.xr.isPresenting) renderer.render(scene, xrCamera);
    else {
      resize();
      linearView.render(renderer, scene, camera);
    }
  }
  if (config.timing) {
    const gl = renderer.getContext();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));  // waits for the drawing
    drawTimes.push(performance.now() - drawStart);
    if (drawTimes.length > 15) drawTimes.shift();
    state.drawMs = median(drawTimes);
  }
  frameTimes.push(now - last);
  if (frameTimes.length > 60) frameTimes.shift();
  last = now;
  state.frames += 1;
  if (xrFrame) {
    if (xrPlace) placeViewer(xrFrame);
    state.xrFrames += 1;
  }
  state.frameMs = median(frameTimes);
}
renderer.setAnimationLoop(frame);

// ---- a Looking Glass ---------------------------------------------------------------------------
let lookingGlass = null;
let sceneCentre = new THREE.Vector3();  // the display plane's distance is measured to it, as natively
async function setupLookingGlass() {
  const r = await fetch(new URL(config.lkg, location.href)).catch((e) => {
    throw new Error(`the Looking Glass calibration ${config.lkg} could not be fetched (${e.message})`);
  });
  if (!r.ok) throw new Error(`the Looking Glass calibration ${config.lkg}: HTTP ${r.status}`);
  const cal = parseCalibration(await r.text());
  let viewSize = null;
  if (config.lkgView) {
    const m = /^(\d{1,5})x(\d{1,5})$/.exec(config.lkgView);
    if (!m || +m[1] < 1 || +m[2] < 1 || +m[1] > 8192 || +m[2] > 8192) throw new Error('lkgview= takes WxH, each 1..8192');
    viewSize = [+m[1], +m[2]];
  }
  const gl = renderer.getContext();
  const maxSide = Math.min(renderer.capabilities.maxTextureSize, gl.getParameter(gl.MAX_RENDERBUFFER_SIZE));
  lookingGlass = new LookingGlassOutput(cal, viewSize, maxSide);
  state.lookingGlass = { model: cal.model.name, serial: cal.serial, views: lookingGlass.views, columns: lookingGlass.columns,
                         rows: lookingGlass.rows, view: lookingGlass.tile, panel: [cal.screenW, cal.screenH], cells: cal.cells.length };
}
if (config.lkg) setupLookingGlass().catch((e) => fail(e.message));

// ---- WebXR -------------------------------------------------------------------------------------
state.xr = 'none';
state.xrFrames = 0;
const xrButton = document.getElementById('xr');
let xrPlace = false;  // place the viewer on the session's first frame
// While presenting, three draws from the head's pose relative to the XR camera's parent: the
// dolly, put where the page's camera stands (runtimes' offset reference spaces are not all
// faithful; a parent transform is).
const dolly = new THREE.Group();
dolly.matrixAutoUpdate = false;
const xrCamera = new THREE.PerspectiveCamera(50, 1, 0.01, 1000);
dolly.add(xrCamera);

// dolly = camera · head⁻¹, head the viewer's pose then: the session starts at the page's view.
function placeViewer(xrFrame) {
  const pose = xrFrame.getViewerPose(renderer.xr.getReferenceSpace());
  if (!pose) return;
  camera.updateMatrixWorld(true);
  const head = new THREE.Matrix4().fromArray(pose.transform.matrix);
  dolly.matrix.copy(camera.matrixWorld).multiply(head.invert());
  dolly.matrixWorldNeedsUpdate = true;
  if (dolly.parent !== scene) scene.add(dolly);
  xrPlace = false;
}

async function setupXr() {
  if (params.get('xr') === 'emulate') {
    const { XRDevice, metaQuest3 } = await import('iwer');
    // Both eyes (iwer draws one unless asked), and no lens mask over the picture.
    const device = new XRDevice(metaQuest3, { stereoEnabled: true, visibilityMask: null });
    device.installRuntime({ forceInstall: true });
  }
  const supported = navigator.xr && (await navigator.xr.isSessionSupported('immersive-vr').catch(() => false));
  if (!supported) return;
  state.xr = 'available';
  xrButton.hidden = false;
  xrButton.onclick = () => enterXr().catch((e) => fail('WebXR: ' + e.message));
}

async function enterXr() {
  if (renderer.xr.isPresenting) return renderer.xr.getSession().end();
  const session = await navigator.xr.requestSession('immersive-vr', { optionalFeatures: ['local-floor'] });
  renderer.xr.enabled = true;
  renderer.xr.setReferenceSpaceType('local');
  await renderer.xr.setSession(session);
  xrPlace = true;
  state.xr = 'immersive';
  xrButton.textContent = 'Exit VR';
  session.addEventListener('end', () => {
    state.xr = 'available';
    xrButton.textContent = 'Enter VR';
    renderer.xr.enabled = false;
  });
}
setupXr().catch((e) => {
  state.xr = 'failed';
  fail('WebXR: ' + e.message);
});

function median(values) {
  if (!values.length) return 0;
  const s = values.slice().sort((a, b) => a - b);
  return s[Math.floor(s.length / 2)];
}

// ---- the scene the stream names ------------------------------------------------------------
async function loadScene(manifestText, hash) {
  const manifest = await checkedManifest(manifestText, hash);
  if (!manifest.scene.gltf) throw new Error('the stream names a built-in scene, which the browser does not have: serve a glTF scene');
  if (!config.scene) throw new Error('no scene folder given (scene=URL)');
  // Every file the manifest lists, fetched from inside the scene folder (each part encoded, so
  // "%2e%2e" stays a name) and checked against its size and SHA-256.
  const files = new Map();
  const folder = new URL(config.scene.endsWith('/') ? config.scene : config.scene + '/', location.href);
  for (const f of manifest.files) {
    const url = sceneFileUrl(f.path, folder);
    const r = await fetch(url).catch((e) => {
      throw new Error(`scene file ${f.path}: ${url.href} could not be fetched (${e.message}): is scene= the folder a web server serves?`);
    });
    if (!r.ok) throw new Error(`scene file ${f.path}: HTTP ${r.status} from ${url.href}`);
    const bytes = new Uint8Array(await r.arrayBuffer());
    if (bytes.length !== f.bytes || (await sha256Hex(bytes)) !== f.sha256)
      throw new Error(`scene file ${f.path} is not the stream's (size or SHA-256 differs): the scene does not match the stream ${hash.slice(0, 12)}`);
    files.set(f.path, URL.createObjectURL(new Blob([bytes])));
  }
  // The glTF reads its buffers and images from the checked copies only.
  const manager = new THREE.LoadingManager();
  manager.setURLModifier((url) => files.get(url) ?? 'data:,');
  let gltf, background = null;
  try {
    const text = await (await fetch(files.get(manifest.scene.gltf))).arrayBuffer();
    gltf = await new GLTFLoader(manager).parseAsync(text, '');
    // The distant light behind the scene, as the native client draws it. One the page cannot use
    // is named and the scene shown without it (black, as where there is none).
    try {
      background = await lightingBackground(manifest.lighting, renderer.capabilities.maxTextureSize, async (path) => {
        if (!files.has(path)) throw new Error(`the stream's environment map ${printable(path)} is not among its files`);
        return (await fetch(files.get(path))).arrayBuffer();
      });
      problem('environment', '');
    } catch (e) {
      problem('environment', `${e.message}; the scene is drawn without it`);
    }
  } finally {
    for (const url of files.values()) URL.revokeObjectURL(url);  // read: the copies are no longer needed
  }
  disposeScene(scene);
  scene.clear();
  scene.add(gltf.scene);
  if (background) scene.add(background);
  if (renderer.xr.isPresenting) scene.add(dolly);  // a session goes on in the new scene
  gltf.scene.traverse((o) => {
    if (o.isMesh) {
      o.castShadow = o.receiveShadow = true;
      const mats = Array.isArray(o.material) ? o.material : [o.material];
      for (const m of mats) {
        m.side = THREE.DoubleSide;  // scenes are two-sided, as in the tracers
        // Mip-mapped (three's default) with the native client's anisotropic taps (RasterOptions).
        for (const t of [m.map, m.emissiveMap, m.metalnessMap, m.roughnessMap, m.aoMap])
          if (t) t.anisotropy = Math.min(8, renderer.capabilities.getMaxAnisotropy());
        if (m.isMeshStandardMaterial) lighting.apply(m);
      }
    }
    if (o.isLight) {
      o.castShadow = true;
      if (o.shadow) o.shadow.mapSize.set(1024, 1024);
    }
  });
  fitSunShadows(gltf.scene);
  new THREE.Box3().setFromObject(gltf.scene).getCenter(sceneCentre);
  loadedScene = { root: gltf.scene, parser: gltf.parser };
  camera = pickCamera(gltf);
  // The scene's animation, every clip at once, looped over the longest (as the native viewers).
  animation = null;
  if (gltf.animations.length) {
    const mixer = new THREE.AnimationMixer(gltf.scene);
    const actions = gltf.animations.map((clip) => {
      const a = mixer.clipAction(clip);
      a.setLoop(THREE.LoopOnce, 1);
      a.clampWhenFinished = true;
      a.play();
      return a;
    });
    animation = { mixer, actions, length: Math.max(...gltf.animations.map((c) => c.duration)) };
  }
  state.sceneLoaded = true;
  state.sceneHash = hash;
  stream.setScene(gltf.scene, gltf.parser, renderer);  // its area lights, before the first frame
  Object.assign(state, stream.status);  // shown with the scene, not up to 100 ms after it
}

// Loads the scene the stream names, and tries again every few seconds while it fails (files
// missing or not yet the stream's: put right, the page picks them up by itself).
let sceneTriedAt = 0, sceneTried = '';
function ensureScene() {
  const codec = stream?.codec;
  if (!codec || !codec.hasVolume() || loadingScene) return;
  const hash = codec.sceneHash();
  if (!hash || hash === state.sceneHash) return;
  if (hash === sceneTried && performance.now() - sceneTriedAt < 3000) return;
  sceneTried = hash;
  sceneTriedAt = performance.now();
  loadingScene = loadScene(codec.sceneManifest(), hash)
    .then(() => problem('scene', ''))
    .catch((e) => problem('scene', e.message))
    .finally(() => { loadingScene = null; });
}
setInterval(ensureScene, 500);

// A directional light's shadow covers the whole scene (three.js's default box is 10 m wide around
// the light's node): its orthographic camera is fitted to the scene's bounds seen from the light,
// with a map large enough to keep the native client's texel size on scenes of a few tens of metres.
// Frees what the previous scene holds on the GPU (geometry, materials, textures, the background).
function disposeScene(root) {
  root.traverse((o) => {
    o.geometry?.dispose();
    for (const m of Array.isArray(o.material) ? o.material : o.material ? [o.material] : []) {
      for (const v of Object.values(m)) if (v?.isTexture) v.dispose();
      if (o.userData.probecastBackground) m.uniforms.envMap.value.dispose();  // the stream's light stays
      m.dispose();
    }
  });
}

function fitSunShadows(root) {
  root.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromObject(root);
  if (box.isEmpty()) return;
  const corners = [];
  for (let i = 0; i < 8; ++i)
    corners.push(new THREE.Vector3(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y, i & 4 ? box.max.z : box.min.z));
  const size = Math.min(4096, renderer.capabilities.maxTextureSize);
  root.traverse((o) => {
    if (!o.isDirectionalLight || !o.shadow) return;
    const lightPos = o.getWorldPosition(new THREE.Vector3());
    const dir = o.target.getWorldPosition(new THREE.Vector3()).sub(lightPos).normalize();
    const centre = box.getCenter(new THREE.Vector3()), radius = box.getSize(new THREE.Vector3()).length() / 2;
    // The light's position only sets the shadow camera's place: put it outside the scene, up-beam,
    // and its target (glTF lights carry it as a child) one metre down the beam from there.
    const place = centre.clone().addScaledVector(dir, -2 * radius);
    o.position.copy(o.parent ? o.parent.worldToLocal(place.clone()) : place);
    o.updateMatrixWorld(true);
    if (o.target.parent !== o) {
      if (!o.target.parent) scene.add(o.target);
      o.target.position.copy(o.target.parent.worldToLocal(place.clone().add(dir)));
      o.target.updateMatrixWorld(true);
    }
    const cam = o.shadow.camera;
    o.shadow.updateMatrices(o);
    const bounds = new THREE.Box3();
    for (const c of corners) bounds.expandByPoint(c.clone().applyMatrix4(cam.matrixWorldInverse));
    cam.left = bounds.min.x;
    cam.right = bounds.max.x;
    cam.bottom = bounds.min.y;
    cam.top = bounds.max.y;
    cam.near = Math.max(0.01, -bounds.max.z - 0.01 * radius);
    cam.far = -bounds.min.z + 0.01 * radius;
    cam.updateProjectionMatrix();
    o.shadow.mapSize.set(size, size);
    o.shadow.bias = -0.0002;
    o.shadow.normalBias = 1.5 * Math.max(bounds.max.x - bounds.min.x, bounds.max.y - bounds.min.y) / size;
  });
}

function pickCamera(gltf) {
  if (config.camera) {
    const v = config.camera.split(',').map(Number);
    if (v.length === 7 && v.every(Number.isFinite)) {
      const c = new THREE.PerspectiveCamera(v[6], 1, 0.01, 1000);
      c.position.set(v[0], v[1], v[2]);
      c.lookAt(v[3], v[4], v[5]);
      return c;
    }
    fail('camera= takes 7 numbers: px,py,pz,tx,ty,tz,fovDeg');
  }
  if (gltf.cameras.length) {
    const c = gltf.cameras[0];
    c.updateMatrixWorld(true);
    return c;
  }
  const box = new THREE.Box3().setFromObject(gltf.scene);
  const c = new THREE.PerspectiveCamera(45, 1, 0.01, 1000);
  const centre = box.getCenter(new THREE.Vector3());
  c.position.copy(centre).add(new THREE.Vector3(0, 0, box.getSize(new THREE.Vector3()).length()));
  c.lookAt(centre);
  return c;
}

// ---- the stream ----------------------------------------------------------------------------
let loadingScene = null;
let loadedScene = null;

// ---- the status line -----------------------------------------------------------------------
let bytesBefore = 0, rate = 0;
setInterval(() => {
  rate = state.bytes - bytesBefore;
  bytesBefore = state.bytes;
  state.bytesPerSecond = rate;
}, 1000);
setInterval(() => {
  const age = state.lastBrickAt ? ((performance.now() - state.lastBrickAt) / 1000).toFixed(1) + ' s' : '–';
  const lines = [
    `${state.connection}  ${config.stream}  ${state.representation}  bricks ${state.bricksHeld}/${state.bricks}  checksum ${state.checksum || '–'}`,
    `frame ${state.frameMs.toFixed(1)} ms${config.timing ? ` (drawn in ${(state.drawMs || 0).toFixed(1)} ms)` : ''}  newest light ${age} ago  ${(rate / 1024).toFixed(1)} kB/s  decode ${state.decodeMs.toFixed(2)} ms/message`,
  ];
  if (state.lookingGlass) {
    const g = state.lookingGlass;
    lines.push(`Looking Glass ${g.model}: ${g.views} views of ${g.view.join('x')}, panel ${g.panel.join('x')}`);
  }
  if (state.warning) lines.push(state.warning);
  if (state.error) lines.push(state.error);
  statusEl.textContent = lines.join('\n');
}, 250);

if (stream) {
  stream.on('problem', problem).on('fatal', fail).on('epoch', ensureScene);
  setInterval(() => Object.assign(state, stream.status), 100);
  stream.start().catch((e) => fail('the WebAssembly codec did not load: ' + e.message));
}
