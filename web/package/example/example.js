// A three.js application that lights its own glTF scene from a probecast stream:
//   index.html?nats=ws://127.0.0.1:8443&stream=cornell&scene=CornellBox-Original.gltf#token=TOKEN
// The scene should be the one the stream is traced in (the same file `serve --scene` was given).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { ProbeStream, useProbecastCurve, LinearLightView } from 'probecast-three';

const params = new URLSearchParams(location.search);
const token = decodeURIComponent((/(?:^|&)token=([^&]*)/.exec(location.hash.slice(1)) || [])[1] || '');
const canvas = document.getElementById('view');
const statusEl = document.getElementById('status');

const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.shadowMap.enabled = true;
useProbecastCurve(renderer);  // optional: the native viewer's curve, to compare pictures with it
const view = new LinearLightView();  // optional: edges averaged in linear light, as the native viewer
const scene = new THREE.Scene();

// The light: every standard material of the scene takes the stream's probes and area lights.
const stream = new ProbeStream({ servers: params.get('nats'), token, stream: params.get('stream') || 'probes' });
const gltf = await new GLTFLoader().loadAsync(params.get('scene'));
scene.add(gltf.scene);
gltf.scene.traverse((o) => {
  if (o.isMesh) {
    o.castShadow = o.receiveShadow = true;
    for (const m of Array.isArray(o.material) ? o.material : [o.material]) {
      m.side = THREE.DoubleSide;
      stream.apply(m);
    }
  }
  if (o.isLight) o.castShadow = true;
});
await stream.start();
stream.setScene(gltf.scene, gltf.parser, renderer);

// The glTF's first camera, or one that looks at the whole scene.
let camera = gltf.cameras[0];
if (!camera) {
  const box = new THREE.Box3().setFromObject(gltf.scene);
  const centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length();
  camera = new THREE.PerspectiveCamera(45, 1, size / 1000, size * 10);
  camera.position.copy(centre).add(new THREE.Vector3(0, 0, size));
  camera.lookAt(centre);
}

const errors = new Map();
stream.on('problem', (key, message) => (message ? errors.set(key, message) : errors.delete(key)));
stream.on('fatal', (message) => errors.set('fatal', message));

// What the page holds, for a status line and for tests (window.probecast).
const state = { sceneLoaded: true, frames: 0 };
window.probecast = state;

renderer.setAnimationLoop(() => {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== w || canvas.height !== h) renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  stream.drawShadows(renderer, scene);
  view.render(renderer, scene, camera);
  state.frames += 1;
});

setInterval(() => {
  Object.assign(state, stream.status, { error: [...errors.values()].join('\n') });
  const s = stream.status;
  statusEl.textContent = `${s.connection}  ${s.representation}  bricks ${s.bricksHeld}/${s.bricks}  ${s.areaLights} area lights` +
    (state.error ? `\n${state.error}` : '') + (s.warning ? `\n${s.warning}` : '');
}, 100);
