// The probe codec compiled to WebAssembly (web/wasm/probecast_web.cpp): bus messages in, the
// volume the native client would hold out.
// options: the codec module's own (locateFile: where its .wasm is), and moduleUrl: where
// probecast_codec.mjs is served, when not beside this script (an application's bundler moved it).
export async function loadCodec({ moduleUrl, ...options } = {}) {
  // Beside the page's script (build/web): loaded at run time, not bundled.
  const url = moduleUrl ?? new URL('./probecast_codec.mjs', import.meta.url).href;
  const { default: createProbecastCodec } = await import(/* @vite-ignore */ /* webpackIgnore: true */ url);
  const M = await createProbecastCodec(options);
  return new Decoder(M);
}

export class Decoder {
  constructor(M) {
    this.M = M;
    this.handle = M._pc_viewer_new();
    this.buffer = 0;
    this.capacity = 0;
    this.decodeMs = [];  // per message, the newest 256
  }

  // One bus message: 1 volume, 2 brick applied, 3 nothing changed, 0 refused (error() says why).
  message(bytes) {
    const M = this.M;
    if (bytes.length > this.capacity) {
      if (this.buffer) M._pc_free(this.buffer);
      this.capacity = Math.max(bytes.length, 2 * this.capacity, 4096);
      this.buffer = M._pc_alloc(this.capacity);
    }
    M.HEAPU8.set(bytes, this.buffer);
    const t0 = performance.now();
    const r = M._pc_viewer_message(this.handle, this.buffer, bytes.length);
    this.decodeMs.push(performance.now() - t0);
    if (this.decodeMs.length > 256) this.decodeMs.shift();
    return r;
  }

  error() { return this.M.UTF8ToString(this.M._pc_viewer_error(this.handle)); }
  hasVolume() { return this.M._pc_viewer_has_volume(this.handle) !== 0; }
  dims() { return [0, 1, 2].map((a) => this.M._pc_viewer_dim(this.handle, a)); }
  bounds() {
    const b = [0, 1, 2, 3, 4, 5].map((i) => this.M._pc_viewer_bound(this.handle, i));
    return { min: b.slice(0, 3), max: b.slice(3) };
  }
  probeCount() { return this.M._pc_viewer_probe_count(this.handle); }
  bricks() { return this.M._pc_viewer_bricks(this.handle); }
  bricksHeld() { return this.M._pc_viewer_bricks_held(this.handle); }
  // Copies: the module's memory may move when it grows.
  probes() {
    const p = this.M._pc_viewer_probes(this.handle);
    return p ? new Float32Array(this.M.HEAPF32.buffer, p, 27 * this.probeCount()).slice() : null;
  }
  active() {
    const p = this.M._pc_viewer_active(this.handle);
    return p ? new Uint8Array(this.M.HEAPU8.buffer, p, this.probeCount()).slice() : null;
  }
  offsets() {
    const p = this.M._pc_viewer_offsets(this.handle);
    return p ? new Float32Array(this.M.HEAPF32.buffer, p, 3 * this.probeCount()).slice() : null;
  }
  checksum() { return (this.M._pc_viewer_checksum(this.handle) >>> 0).toString(16).padStart(8, '0'); }
  sceneHash() { return this.M.UTF8ToString(this.M._pc_viewer_scene_hash(this.handle)); }
  sceneManifest() { return this.M.UTF8ToString(this.M._pc_viewer_scene_manifest(this.handle)); }
  areaLightRule() { return this.M._pc_viewer_area_light_rule(this.handle); }
  areaLightShare() { return this.M._pc_viewer_area_light_share(this.handle); }
  representation() { return this.M.UTF8ToString(this.M._pc_viewer_representation(this.handle)); }
  sceneTime() { return this.M._pc_viewer_scene_time(this.handle); }
  sceneRate() { return this.M._pc_viewer_scene_rate(this.handle); }
  sceneClockUs() { return this.M._pc_viewer_scene_clock_us(this.handle); }
  publishedUs() { return this.M._pc_viewer_published_us(this.handle); }
  counts() {
    const c = (i) => this.M._pc_viewer_count(this.handle, i);
    return { applied: c(0), stale: c(1), refused: c(2), waiting: c(3) };
  }
}
