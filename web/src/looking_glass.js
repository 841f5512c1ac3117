// Looking Glass panels in the page: the display's calibration (its visual.json), its model's view
// set, the cameras of that view set, and the interleave that turns a quilt of views into the
// panel's subpixel image. The same formula, checks and models as the native viewer
// (renderer/include/probecast/renderer/looking_glass.h; docs/RENDERING.md#looking-glass-panels).
import * as THREE from 'three';

const MAX_SCREEN_SIDE = 16384, MAX_PER_INCH = 1e5, MAX_CELLS = 64, MAX_CELL_OFFSET = 4, MAX_PATTERN = 4;
const CELL_KEYS = ['ROffsetX', 'ROffsetY', 'GOffsetX', 'GOffsetY', 'BOffsetX', 'BOffsetY'];

function refuse(what) { throw new Error('visual.json: ' + what); }

// The field's value, with an optional {"value": ...} wrapper taken off; undefined when absent.
function fieldValue(root, name) {
  if (!Object.hasOwn(root, name)) return undefined;
  const v = root[name];
  if (v !== null && typeof v === 'object' && !Array.isArray(v)) {
    if (!Object.hasOwn(v, 'value')) refuse(`field "${name}" is an object without "value"`);
    return v.value;
  }
  return v;
}

function numberField(root, name, required, fallback) {
  const v = fieldValue(root, name);
  if (v === undefined) {
    if (required) refuse(`missing required field "${name}"`);
    return fallback;
  }
  if (typeof v !== 'number' || !Number.isFinite(v)) refuse(`field "${name}" must be a finite number (got ${JSON.stringify(v)?.slice(0, 40)})`);
  return v;
}

function flagField(root, name, fallback) {
  const v = fieldValue(root, name);
  if (typeof v === 'boolean') return v;
  const d = numberField(root, name, false, fallback ? 1 : 0);
  if (d !== 0 && d !== 1) refuse(`field "${name}" must be 0 or 1 (got ${d})`);
  return d === 1;
}

function wholeField(root, name, required, fallback, low, high, unit) {
  const d = numberField(root, name, required, fallback);
  if (!Number.isInteger(d) || d < low || d > high) refuse(`field "${name}" must be a whole number${unit} in ${low}..${high} (got ${d})`);
  return d;
}

// Informational text (the serial): taken as written, a {"value": ...} wrapper or not; never refused.
function textField(root, name) {
  if (!Object.hasOwn(root, name)) return '';
  let v = root[name];
  if (v !== null && typeof v === 'object' && !Array.isArray(v) && Object.hasOwn(v, 'value')) v = v.value;
  return typeof v === 'string' ? v : JSON.stringify(v);
}

function cellsField(root) {
  const v = fieldValue(root, 'subpixelCells');
  if (v === undefined || v === null) return [];
  if (!Array.isArray(v)) refuse('field "subpixelCells" must be an array');
  if (v.length > MAX_CELLS) refuse(`field "subpixelCells" must hold at most ${MAX_CELLS} cells (got ${v.length})`);
  return v.map((entry, k) => {
    if (entry === null || typeof entry !== 'object' || Array.isArray(entry)) refuse(`subpixelCells[${k}]: expected an object`);
    const o = CELL_KEYS.map((key) => {
      const d = fieldValue(entry, key);
      if (d === undefined) refuse(`subpixelCells[${k}]: missing required field "${key}"`);
      if (typeof d !== 'number' || !Number.isFinite(d) || Math.abs(d) > MAX_CELL_OFFSET)
        refuse(`subpixelCells[${k}]: field "${key}" must be a number within ${MAX_CELL_OFFSET} pixels`);
      return d;
    });
    return { dx: [o[0], o[2], o[4]], dy: [o[1], o[3], o[5]] };
  });
}

// A display model's usual view set by the serial's prefix, as the native viewer's table.
const MODELS = [
  ['LKG-2K', 'Looking Glass 8.9"', 5, 9, 227], ['LKG-4K', 'Looking Glass 15.6"', 5, 9, 455],
  ['LKG-8K', 'Looking Glass 8K', 5, 9, 910], ['LKG-P', 'Looking Glass Portrait', 8, 6, 560],
  ['LKG-A', 'Looking Glass 16" (2nd generation)', 5, 9, 455], ['LKG-B', 'Looking Glass 32" (2nd generation)', 5, 9, 910],
  ['LKG-D', 'Looking Glass 65"', 8, 9, 910], ['LKG-E', 'Looking Glass Go', 11, 6, 682],
  ['LKG-F', 'Looking Glass kiosk', 11, 6, 682], ['LKG-H', 'Looking Glass 16" Spatial (portrait)', 11, 6, 1000],
  ['LKG-J', 'Looking Glass 16" Spatial (landscape)', 7, 7, 857], ['LKG-K', 'Looking Glass 32" Spatial (portrait)', 11, 6, 1364],
  ['LKG-L', 'Looking Glass 32" Spatial (landscape)', 7, 7, 1170],
];

export function lookingGlassModel(serial, screenW, screenH) {
  for (const [prefix, name, columns, rows, viewHeight] of MODELS)
    if (serial.startsWith(prefix)) return { name, columns, rows, viewHeight };
  return screenH > screenW ? { name: 'portrait display', columns: 8, rows: 6, viewHeight: 560 }
    : { name: 'landscape display', columns: 5, rows: 9, viewHeight: 560 };
}

// The calibration from a visual.json's text; throws an Error naming the field for anything the
// native viewer refuses.
export function parseCalibration(text) {
  let root;
  try { root = JSON.parse(text); } catch { refuse('malformed JSON'); }
  if (root === null || typeof root !== 'object' || Array.isArray(root)) refuse('expected a JSON object');
  const c = {
    pitch: numberField(root, 'pitch', true), slope: numberField(root, 'slope', true),
    center: numberField(root, 'center', true), dpi: numberField(root, 'DPI', true),
    screenW: wholeField(root, 'screenW', true, 0, 1, MAX_SCREEN_SIDE, ' of pixels'),
    screenH: wholeField(root, 'screenH', true, 0, 1, MAX_SCREEN_SIDE, ' of pixels'),
    viewCone: numberField(root, 'viewCone', false, 40), verticalAngle: numberField(root, 'verticalAngle', false, 0),
    invView: flagField(root, 'invView', true),
    flipImageX: flagField(root, 'flipImageX', false), flipImageY: flagField(root, 'flipImageY', false),
    flipSubp: flagField(root, 'flipSubp', false),
    serial: textField(root, 'serial'),
    cells: cellsField(root), cellPatternMode: wholeField(root, 'CellPatternMode', false, 0, 0, MAX_PATTERN, ''),
  };
  if (c.dpi <= 0 || c.dpi > MAX_PER_INCH) refuse(`field "DPI" must be > 0 and at most ${MAX_PER_INCH} (got ${c.dpi})`);
  if (c.pitch <= 0 || c.pitch > MAX_PER_INCH) refuse(`field "pitch" must be > 0 and at most ${MAX_PER_INCH} (got ${c.pitch})`);
  if (Math.abs(c.slope) < 0.01 || Math.abs(c.slope) > 1000) refuse(`field "slope" must have |slope| in [0.01, 1000] (got ${c.slope})`);
  if (c.viewCone <= 0 || c.viewCone >= 180) refuse(`field "viewCone" must be in (0, 180) degrees (got ${c.viewCone})`);
  c.model = lookingGlassModel(c.serial, c.screenW, c.screenH);
  return c;
}

// A phase in lenticules as an unsigned 0.32 fixed-point fraction (its whole part dropped).
function fixedTurns(turns) {
  const scaled = Math.round((turns - Math.floor(turns)) * 4294967296);
  return scaled >= 4294967296 ? 0 : scaled;
}

// The interleave's constants, computed in double precision as the native viewer does: the lens
// phase per pixel right and up, at pixel (0, 0), and per subpixel of each cell (a panel without
// cells is one cell of subpixels a third of a pixel apart).
export function interleaveConstants(c) {
  const w = c.screenW, h = c.screenH;
  const pitchEff = c.pitch * w / c.dpi * Math.cos(Math.atan(1 / c.slope));
  const tilt = h / (w * c.slope);
  const perX = pitchEff / w, perY = pitchEff * tilt / h;
  let cells = c.cells, pattern = c.cellPatternMode;
  if (!cells.length) {
    const s = c.flipSubp ? -1 : 1;
    cells = [{ dx: [0, s / 3, 2 * s / 3], dy: [0, 0, 0] }];
    pattern = 0;
  }
  const count = Math.min(4, cells.length);
  const cellPhase = new Array(12).fill(0);
  for (let k = 0; k < count; ++k)
    for (let i = 0; i < 3; ++i) cellPhase[3 * k + i] = fixedTurns((cells[k].dx[i] / w + cells[k].dy[i] / h * tilt) * pitchEff);
  return {
    perX: fixedTurns(perX), perY: fixedTurns(perY), origin: fixedTurns(0.5 * perX + 0.5 * perY - c.center),
    cellPhase, pattern, count,
  };
}

// The view set's cameras: `base` moved sideways across the calibration's view cone, each looking
// through the same display rectangle `distance` ahead (a sheared frustum), view 0 the leftmost —
// as the native viewer's lfh view sets (renderer/src/view_sets.cpp).
export function viewCameras(base, views, aspect, distance, coneDeg, near = 0.01, far = 200) {
  base.updateMatrixWorld(true);
  const halfH = distance * Math.tan(THREE.MathUtils.degToRad(base.fov) / 2), halfW = halfH * aspect;
  const span = 2 * distance * Math.tan(THREE.MathUtils.degToRad(coneDeg) / 2);
  const step = views > 1 ? span / (views - 1) : 0;
  const right = new THREE.Vector3().setFromMatrixColumn(base.matrixWorld, 0).normalize();
  const scale = near / distance;
  const cameras = [];
  for (let k = 0; k < views; ++k) {
    const s = (k - 0.5 * (views - 1)) * step;
    const cam = new THREE.PerspectiveCamera(base.fov, aspect, near, far);
    cam.position.copy(base.getWorldPosition(new THREE.Vector3())).addScaledVector(right, s);
    cam.quaternion.copy(base.getWorldQuaternion(new THREE.Quaternion()));
    cam.updateMatrixWorld(true);
    cam.projectionMatrix.makePerspective((-halfW - s) * scale, (halfW - s) * scale, halfH * scale, -halfH * scale, near, far);
    cam.projectionMatrixInverse.copy(cam.projectionMatrix).invert();
    cameras.push(cam);
  }
  return cameras;
}

// The interleave as a full-screen pass: each panel pixel's red, green and blue subpixels take the
// matching channel of the view their lens phase falls in (fixed-point phase, as the native
// compute shader), sampled bilinearly inside that view's tile of the quilt, then the native
// viewer's filmic curve and gamma.
const FRAGMENT = /* glsl */ `
precision highp float;
precision highp int;
uniform sampler2D quilt;
uniform ivec2 screen;
uniform ivec2 tile;
uniform int columns;
uniform int views;
uniform uint perX, perY, origin;
uniform uint cellPhase[12];
uniform int pattern, cellCount;
uniform bool invView, flipX, flipY;
uniform float exposure;
out vec4 color;

int cellOf(int x, int y) {
  int cell = 0;
  if (pattern == 1) cell = (x + y) % 2;
  else if (pattern == 2) cell = y % 4;
  else if (pattern == 3) cell = (y + 2 * (x % 2)) % 4;
  else if (pattern == 4) cell = x % 2;
  return cell % max(cellCount, 1);
}

// floor(a · n / 2^32) without a 64-bit product: a split in 16-bit halves.
int viewOf(uint a, int n) {
  uint hi = a >> 16u, lo = a & 0xFFFFu;
  return int((hi * uint(n) + ((lo * uint(n)) >> 16u)) >> 16u);
}

float sampleView(int view, vec2 uv, int channel) {
  ivec2 origin0 = ivec2((view % columns) * tile.x, (view / columns) * tile.y);  // tile rows from the bottom
  vec2 p = clamp(uv * vec2(tile) - 0.5, vec2(0.0), vec2(tile - 1));
  ivec2 t0 = ivec2(p);
  ivec2 t1 = min(t0 + 1, tile - 1);
  vec2 f = p - vec2(t0);
  float c00 = texelFetch(quilt, origin0 + t0, 0)[channel];
  float c10 = texelFetch(quilt, origin0 + ivec2(t1.x, t0.y), 0)[channel];
  float c01 = texelFetch(quilt, origin0 + ivec2(t0.x, t1.y), 0)[channel];
  float c11 = texelFetch(quilt, origin0 + t1, 0)[channel];
  float bottom = c00 + (c10 - c00) * f.x, top = c01 + (c11 - c01) * f.x;
  return bottom + (top - bottom) * f.y;
}

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);  // y from the bottom, as the formula has it
  vec2 uv = (vec2(pixel) + 0.5) / vec2(screen);
  if (flipX) uv.x = 1.0 - uv.x;
  if (flipY) uv.y = 1.0 - uv.y;
  uint base = uint(pixel.x) * perX + uint(pixel.y) * perY + origin;
  int cell = cellOf(pixel.x, pixel.y);
  vec3 rgb;
  for (int i = 0; i < 3; ++i) {
    uint a = base + cellPhase[cell * 3 + i];
    if (invView) a = ~a;
    rgb[i] = sampleView(min(viewOf(a, views), views - 1), uv, i);
  }
  vec3 v = max(rgb * exposure, vec3(0.0));
  v = v * (2.51 * v + 0.03) / (v * (2.43 * v + 0.59) + 0.14);
  color = vec4(pow(min(v, vec3(1.0)), vec3(1.0 / 2.2)), 1.0);
}`;

export class LookingGlassOutput {
  // `maxSide`: the largest texture and render buffer side the browser allows; a quilt larger than
  // that is refused by name (smaller views, lkgview=, fit it).
  constructor(calibration, viewSize, maxSide) {
    this.cal = calibration;
    const m = calibration.model;
    this.columns = m.columns;
    this.rows = m.rows;
    this.views = m.columns * m.rows;
    const [w, h] = viewSize || [Math.max(1, Math.round(m.viewHeight * calibration.screenW / calibration.screenH)), m.viewHeight];
    this.tile = [w, h];
    if (w * m.columns > maxSide || h * m.rows > maxSide) {
      const fit = Math.floor(Math.min(maxSide / (w * m.columns), maxSide / (h * m.rows)) * h);
      throw new Error(`the Looking Glass quilt of ${this.views} views of ${w}x${h} (${w * m.columns}x${h * m.rows}) is ` +
                      `larger than this browser allows (${maxSide} a side): give lkgview= smaller views, at most ` +
                      `${Math.max(1, Math.floor(fit * w / h))}x${Math.max(1, fit)}`);
    }
    this.target = new THREE.WebGLRenderTarget(w * m.columns, h * m.rows, { type: THREE.HalfFloatType, samples: 4,
      minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter, depthBuffer: true });
    this.target.scissorTest = true;
    const k = interleaveConstants(calibration);
    this.material = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3,
      vertexShader: 'in vec3 position; void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }',
      fragmentShader: FRAGMENT,
      uniforms: {
        quilt: { value: this.target.texture }, screen: { value: new THREE.Vector2(calibration.screenW, calibration.screenH) },
        tile: { value: new THREE.Vector2(w, h) }, columns: { value: m.columns }, views: { value: this.views },
        perX: { value: k.perX }, perY: { value: k.perY }, origin: { value: k.origin }, cellPhase: { value: k.cellPhase },
        pattern: { value: k.pattern }, cellCount: { value: k.count }, invView: { value: calibration.invView },
        flipX: { value: calibration.flipImageX }, flipY: { value: calibration.flipImageY }, exposure: { value: 1 },
      },
      depthTest: false, depthWrite: false,
    });
    this.quad = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), this.material);
    this.quad.frustumCulled = false;
    this.quadScene = new THREE.Scene().add(this.quad);
    this.quadCamera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1);
  }

  // Renders the view set around `base` into the quilt, then the panel image onto the canvas.
  render(renderer, scene, base, distance, exposure) {
    // The panel's aspect whatever size the views are drawn at (narrow views have wide pixels), as natively.
    const cameras = viewCameras(base, this.views, this.cal.screenW / this.cal.screenH, distance, this.cal.viewCone);
    const toneMapping = renderer.toneMapping;
    renderer.toneMapping = THREE.NoToneMapping;  // the quilt holds linear light; the pass applies the curve
    // three.js takes a target's viewport and scissor when the target is set: set again per view.
    this.target.viewport.set(0, 0, this.target.width, this.target.height);
    this.target.scissor.set(0, 0, this.target.width, this.target.height);
    renderer.setRenderTarget(this.target);
    renderer.setClearColor(0x000000, 1);
    renderer.clear();
    // The shadow maps do not depend on the view: drawn once a frame, not once a view.
    const autoShadows = renderer.shadowMap.autoUpdate;
    renderer.shadowMap.autoUpdate = false;
    renderer.shadowMap.needsUpdate = true;
    const [w, h] = this.tile;
    for (let k = 0; k < this.views; ++k) {
      const x = (k % this.columns) * w, y = Math.floor(k / this.columns) * h;  // view 0 at the bottom left
      this.target.viewport.set(x, y, w, h);
      this.target.scissor.set(x, y, w, h);
      renderer.setRenderTarget(this.target);
      renderer.render(scene, cameras[k]);
    }
    renderer.shadowMap.autoUpdate = autoShadows;
    renderer.setRenderTarget(null);
    renderer.toneMapping = toneMapping;
    this.material.uniforms.exposure.value = exposure;
    renderer.render(this.quadScene, this.quadCamera);
  }
}
