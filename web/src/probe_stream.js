// A probe stream from the bus (a JetStream stream a producer publishes, over NATS WebSocket),
// decoded by the codec in WebAssembly into the light a three.js scene is drawn with: the probes'
// diffuse and glossy light (ProbeLighting) and the client area lights the stream leaves to its
// viewers (AreaLighting). The viewer page is built on it; so can any three.js application be.
//
//   const stream = await new ProbeStream({ servers: 'wss://bus:8443', token, stream: 'cornell' }).start();
//   scene.traverse((o) => o.isMesh && stream.apply(o.material));  // every MeshStandardMaterial
//   stream.setScene(gltf.scene, gltf.parser, renderer);          // for its area lights
//   renderer.setAnimationLoop(() => { stream.drawShadows(renderer, scene); renderer.render(scene, camera); });
import { connect, DeliverPolicy } from 'nats.ws';
import { loadCodec } from './codec.js';
import { ProbeLighting } from './probe_lighting.js';
import { AreaLighting } from './area_light_shading.js';
import { ProbeVisibility } from './probe_visibility.js';
import { movingMeshes } from './visibility_proxy.js';
import { kAreaLightRuleVersion } from './area_lights.js';
import { DisplayClock } from './display_clock.js';

function sleep(ms) { return new Promise((r) => setTimeout(r, ms)); }
function median(values) {
  if (!values.length) return 0;
  const s = values.slice().sort((a, b) => a - b);
  return s[Math.floor(s.length / 2)];
}

export class ProbeStream {
  // servers: the bus's WebSocket address(es); token: its token; stream: serve --stream's name.
  constructor({ servers, token = '', stream = 'probes' } = {}) {
    if (!servers) throw new Error('ProbeStream: no bus address (servers)');
    if (!/^[A-Za-z0-9_-]+$/.test(stream)) throw new Error(`ProbeStream: "${stream}" is not a stream name (letters, digits, - and _)`);
    this.config = { servers, token, stream };
    this.area = new AreaLighting();
    this.visibility = new ProbeVisibility();
    this.lighting = new ProbeLighting(this.area, this.visibility);
    this.codec = null;
    // What a status line shows: the connection, counts, the volume's checksum and representation.
    this.status = { connection: 'starting', messages: 0, bytes: 0, epochs: 0, checksum: '', bricks: 0, bricksHeld: 0,
                    representation: '', lastBrickAt: 0, decodeMs: 0, lastRefusal: '', areaLights: 0, warning: '' };
    this.listeners = { problem: [], fatal: [], epoch: [] };
    this.dirty = false;
    this.stopped = false;
    this.scene = null;
    this.areaKey = '';
    this.clock = new DisplayClock();
  }

  // Events: 'problem' (key, message; '' when put right), 'fatal' (message: the token was refused),
  // 'epoch' (a new volume: its scene may have changed, codec.sceneHash()).
  on(event, fn) {
    this.listeners[event].push(fn);
    return this;
  }

  emit(event, ...args) { for (const fn of this.listeners[event]) fn(...args); }

  // Loads the codec and starts following the stream (reconnecting by itself). codecOptions: the
  // codec module's (locateFile, where an application serves the .wasm from elsewhere).
  async start(codecOptions = {}) {
    this.codec = await loadCodec(codecOptions);
    this.timer = setInterval(() => this.refresh(), 100);
    this.run();
    return this;
  }

  stop() {
    this.stopped = true;
    clearInterval(this.timer);
    this.nc?.close().catch(() => {});
  }

  // Patches a MeshStandardMaterial or MeshPhysicalMaterial (or each of an array of them, as a
  // mesh with groups holds) to take the stream's light; other materials are left as they are.
  apply(material) {
    for (const m of Array.isArray(material) ? material : [material]) if (m?.isMeshStandardMaterial) this.lighting.apply(m);
  }

  // The scene the stream's area lights are chosen from (its glTF root and GLTFLoader parser, posed
  // as drawn); renderer: the WebGLRenderer (whether it can draw their shadows). Call again when
  // nodes move: the lights are chosen again from the posed scene.
  setScene(root, parser, renderer) {
    const canShadow = renderer.extensions.has('EXT_color_buffer_float');
    this.scene = { root, parser, canShadow };
    this.areaKey = '';  // chosen again whatever the rule
    this.followAreaLights();
    if (canShadow) this.visibility.setRoot(root, movingMeshes(root, parser));  // the cubes need float targets too
    this.requestVisibility();
  }

  // The area lights' shadow maps, once after the scene changes and each frame while it moves, and
  // the probes' visibility while it is being made (a few batches a frame).
  drawShadows(renderer, scene, moving = false) {
    this.area.drawShadows(renderer, scene, moving);
    this.visibility.draw(renderer, scene, moving);
  }

  // Visibility for the probes the lighting holds, made again when they or the scene change.
  requestVisibility() {
    const g = this.lighting.grid;
    if (g) this.visibility.request(this.lighting.positions, g.dims, g.bounds);
  }

  // The display clock (display_clock.js): the newest lighting's scene time, run on at its rate from
  // the producer's wall clock, the offset between the machines' clocks estimated from the messages.
  displayTime() {
    const c = this.codec;
    if (!c || !c.hasVolume()) return 0;
    return this.clock.at(c.sceneTime(), c.sceneRate(), c.sceneClockUs(), Date.now() * 1000);
  }

  onMessage(bytes) {
    const s = this.status;
    s.messages += 1;
    s.bytes += bytes.length;
    const r = this.codec.message(bytes);
    if (r === 0) {
      s.lastRefusal = this.codec.error();  // refused and counted; what is held stays
      return;
    }
    if (r === 1) {
      s.epochs += 1;
      s.representation = this.codec.representation();
      this.emit('epoch');
    }
    if (r === 2) {
      s.lastBrickAt = performance.now();
      this.clock.sample(Date.now() * 1000, this.codec.sceneClockUs());
      s.clockOffsetMs = this.clock.offsetUs() / 1000;
    }
    this.dirty = true;
  }

  // The emitters the stream's rule leaves to viewers, chosen again when the scene or the rule
  // changes (setScene, each refresh). A rule newer than this module's, or no float targets, is named.
  followAreaLights() {
    const c = this.codec;
    if (!c || !c.hasVolume() || !this.scene) return;
    const rule = c.areaLightRule(), share = c.areaLightShare();
    const key = `${c.sceneHash()}/${rule}/${share}`;
    if (key === this.areaKey) return;
    this.areaKey = key;
    const known = rule === 0 || rule === kAreaLightRuleVersion;
    const s = this.status;
    s.areaLights = this.area.setScene(this.scene.root, this.scene.parser, rule !== 0 && known ? share : null, this.scene.canShadow);
    s.warning = !known ? `this stream's area light rule (version ${rule}) is newer than this page's: their direct light is missing`
      : s.areaLights > 0 && !this.area.shadowed ? 'this browser cannot draw float targets: area lights are drawn without shadows'
      : '';
  }

  // The newest volume into the lighting, at most ten times a second.
  refresh() {
    this.followAreaLights();
    this.status.visibility = { ...this.visibility.status };
    const c = this.codec;
    if (!this.dirty || !c.hasVolume()) return;
    this.dirty = false;
    const s = this.status;
    s.bricks = c.bricks();
    s.bricksHeld = c.bricksHeld();
    s.checksum = c.checksum();
    s.decodeMs = median(c.decodeMs);
    this.lighting.update(c.dims(), c.bounds(), c.probes(), c.active(), c.offsets());
    this.requestVisibility();
  }

  async connectBus() {
    const { servers, token } = this.config;
    const s = this.status;
    for (;;) {
      try {
        s.connection = 'connecting';
        return await connect({ servers, token: token || undefined, reconnect: true, maxReconnectAttempts: -1,
                               reconnectTimeWait: 500, pingInterval: 5000 });
      } catch (e) {
        const text = String(e && (e.code || e.message));
        if (/authorization/i.test(text) || e.code === 'AUTHORIZATION_VIOLATION') {
          s.connection = 'refused';
          this.emit('fatal', 'not authorised: the bus refused the token (give it as #token=… in the address)');
          return null;
        }
        s.connection = 'unreachable';
        this.emit('problem', 'bus', `the bus at ${servers} is unreachable (${text}); trying again`);
        await sleep(1000);
        if (this.stopped) return null;
      }
    }
  }

  watchConnection(nc) {
    (async () => {
      for await (const st of nc.status()) {
        if (st.type === 'disconnect' || st.type === 'reconnecting') {
          this.status.connection = 'reconnecting';
          this.emit('problem', 'bus', `lost the bus at ${this.config.servers}; reconnecting`);
        } else if (st.type === 'reconnect') {
          this.status.connection = 'connected';
          this.emit('problem', 'bus', '');
        }
      }
    })();
  }

  // The newest message of every subject (the volume and each brick), then everything new; the
  // stream missing or stopping is named, and followed again a second later.
  async run() {
    const { stream } = this.config;
    const s = this.status;
    while (!this.stopped) {
      const nc = this.nc = await this.connectBus();
      if (!nc) return;
      this.watchConnection(nc);
      try {
        const consumer = await nc.jetstream().consumers.get(`PROBECAST_${stream}`, {
          filterSubjects: `probecast.${stream}.>`,
          deliver_policy: DeliverPolicy.LastPerSubject,
        });
        s.connection = 'connected';
        this.emit('problem', 'bus', '');
        this.emit('problem', 'stream', '');
        for await (const m of await consumer.consume({ max_messages: 512 })) this.onMessage(m.data);
      } catch (e) {
        s.lastStreamError = String(e && e.message);
        const missing = /stream not found/i.test(s.lastStreamError);
        s.connection = missing ? 'waiting for the producer' : 'reconnecting';
        this.emit('problem', 'bus', '');
        this.emit('problem', 'stream', missing
          ? `no stream "${stream}" on the bus: is a producer publishing it (serve --publish … --stream ${stream})?`
          : `the stream "${stream}" stopped (${s.lastStreamError}); reconnecting`);
      }
      await nc.close().catch(() => {});
      await sleep(1000);
    }
  }
}
