// Drawing the page's own maps (the area lights' shadows, the probes' depth cubes) between frames:
// into a float target with each mesh's material swapped for the map's (MapMaterials), the objects a
// map leaves out hidden, and the scene's background, the renderer's target, clear colour, tone
// mapping and shadow updates put back afterwards.
import * as THREE from 'three';

// A mesh that lets light through (blending, transmission): the native maps leave these out.
export function isSeeThrough(o) {
  const mats = o.isMesh ? (Array.isArray(o.material) ? o.material : [o.material]) : [];
  return mats.some((m) => m && (m.transparent || m.transmission > 0));
}

// What the maps leave out, as the native ones do: see-through meshes, the page's background, and
// points, lines and sprites; and what the page does not draw (meshes whose materials are hidden).
export function leftOutOfMaps(o) {
  if (!o.isMesh) return !!(o.isPoints || o.isLine || o.isSprite);
  const mats = Array.isArray(o.material) ? o.material : [o.material];
  return isSeeThrough(o) || !!o.userData.probecastBackground || mats.every((m) => m && m.visible === false);
}

// What a map's fragment shader starts with: the world position (three's distance vertex shader
// poses it: skinning, morph targets, instancing, batching) and, for a cut-out material, its base
// colour map and cutoff, so that `kMapCutout` inside main() discards what the material cuts away.
export const kMapHeader = /* glsl */ `
#define DISTANCE
uniform float opacity;
varying vec3 vWorldPosition;
#include <common>
#include <uv_pars_fragment>
#include <map_pars_fragment>
#include <alphatest_pars_fragment>
`;
export const kMapCutout = /* glsl */ `
  vec4 diffuseColor = vec4(1.0, 1.0, 1.0, opacity);
  #include <map_fragment>
  #include <alphatest_fragment>
`;

// The materials a map draws the scene's meshes with: one for every solid mesh and one per cut-out
// (alphaTest with a base colour map) material, all sharing `uniforms` (their value holders).
export class MapMaterials {
  constructor(fragmentShader, uniforms) {
    this.fragmentShader = fragmentShader;
    this.uniforms = uniforms;
    this.made = [];
    this.solid = this.make(null);
    this.cutouts = new WeakMap();
  }

  make(cutout) {
    const m = new THREE.ShaderMaterial({
      uniforms: { ...this.uniforms, opacity: { value: cutout ? cutout.opacity : 1 }, map: { value: cutout?.map ?? null },
                  mapTransform: { value: cutout?.map?.matrix ?? new THREE.Matrix3() }, alphaTest: { value: cutout?.alphaTest ?? 0 } },
      vertexShader: THREE.ShaderLib.distance.vertexShader,
      fragmentShader: this.fragmentShader,
      side: THREE.DoubleSide,
    });
    if (cutout) {
      m.map = cutout.map;  // USE_MAP and its uv channel
      m.userData.channel = cutout.map.channel;
      m.alphaTest = cutout.alphaTest;
      this.made.push(m);
    }
    return m;
  }

  // The map's material for the scene's material `m`, as `m` is now.
  for(m) {
    if (!(m?.alphaTest > 0 && m.map)) return this.solid;
    let d = this.cutouts.get(m);
    if (!d) this.cutouts.set(m, (d = this.make(m)));
    else follow(d, m);
    return d;
  }

  dispose() {
    this.solid.dispose();
    for (const m of this.made) m.dispose();
  }
}

// A cut-out's later edits: its map, cutoff and opacity as the application has them now (a new
// map may read another uv channel, so the shader is made again).
function follow(d, m) {
  const u = d.uniforms;
  u.opacity.value = m.opacity;
  u.alphaTest.value = m.alphaTest;
  d.alphaTest = m.alphaTest;
  if (u.map.value !== m.map || d.userData.channel !== m.map.channel) {
    u.map.value = m.map;
    d.map = m.map;
    d.userData.channel = m.map.channel;
    d.needsUpdate = true;
  }
  u.mapTransform.value = m.map.matrix;
}

// Runs draw() with `target` bound and cleared to (clearColor, clearAlpha), the visible objects for
// which hide(o) is true hidden and every other mesh drawn with its material from `materials`.
export function drawOffscreen(renderer, scene, { target, clearColor, clearAlpha, materials, hide }, draw) {
  const saved = { target: renderer.getRenderTarget(), auto: renderer.shadowMap.autoUpdate, needs: renderer.shadowMap.needsUpdate,
                  background: scene.background, override: scene.overrideMaterial, clear: renderer.getClearColor(new THREE.Color()),
                  alpha: renderer.getClearAlpha(), toneMapping: renderer.toneMapping, xr: renderer.xr.enabled };
  renderer.xr.enabled = false;  // the maps' own cameras, not the headset's eyes
  const hidden = [], swapped = [];
  scene.traverse((o) => {
    if (o.visible && hide(o)) hidden.push(o);
  });
  for (const o of hidden) o.visible = false;
  scene.traverse((o) => {
    if (!o.isMesh || !o.visible) return;
    swapped.push([o, o.material]);
    o.material = Array.isArray(o.material) ? o.material.map((m) => materials.for(m)) : materials.for(o.material);
  });
  renderer.shadowMap.autoUpdate = false;
  renderer.shadowMap.needsUpdate = false;
  scene.background = null;
  scene.overrideMaterial = null;
  renderer.toneMapping = THREE.NoToneMapping;
  renderer.setClearColor(clearColor, clearAlpha);
  target.scissorTest = false;
  target.viewport.set(0, 0, target.width, target.height);
  renderer.setRenderTarget(target);
  renderer.clear();
  target.scissorTest = true;
  try {
    draw();
  } finally {
    target.scissorTest = false;
    for (const [o, m] of swapped) o.material = m;
    for (const o of hidden) o.visible = true;
    scene.overrideMaterial = saved.override;
    scene.background = saved.background;
    renderer.toneMapping = saved.toneMapping;
    renderer.setClearColor(saved.clear, saved.alpha);
    renderer.shadowMap.autoUpdate = saved.auto;
    renderer.shadowMap.needsUpdate = saved.needs;
    renderer.setRenderTarget(saved.target);
    renderer.xr.enabled = saved.xr;
  }
}
