// Drawing the page's own maps (the area lights' shadows, the probes' depth cubes) between frames:
// into a float target with the scene's background, its override material, the renderer's target,
// clear colour, tone mapping and shadow updates put back afterwards, and the objects a map leaves
// out hidden meanwhile.
import * as THREE from 'three';

// A mesh that lets light through (blending, transmission): the native maps leave these out.
export function isSeeThrough(o) {
  const mats = o.isMesh ? (Array.isArray(o.material) ? o.material : [o.material]) : [];
  return mats.some((m) => m && (m.transparent || m.transmission > 0));
}

// Runs draw() with `target` bound and cleared to (clearColor, clearAlpha), `override` as the
// scene's material, and the visible objects for which hide(o) is true hidden.
export function drawOffscreen(renderer, scene, { target, clearColor, clearAlpha, override = null, hide }, draw) {
  const saved = { target: renderer.getRenderTarget(), auto: renderer.shadowMap.autoUpdate, needs: renderer.shadowMap.needsUpdate,
                  background: scene.background, override: scene.overrideMaterial, clear: renderer.getClearColor(new THREE.Color()),
                  alpha: renderer.getClearAlpha(), toneMapping: renderer.toneMapping };
  const hidden = [];
  scene.traverse((o) => {
    if (o.visible && hide(o)) hidden.push(o);
  });
  for (const o of hidden) o.visible = false;
  renderer.shadowMap.autoUpdate = false;
  renderer.shadowMap.needsUpdate = false;
  scene.background = null;
  scene.overrideMaterial = override;
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
    for (const o of hidden) o.visible = true;
    scene.overrideMaterial = saved.override;
    scene.background = saved.background;
    renderer.toneMapping = saved.toneMapping;
    renderer.setClearColor(saved.clear, saved.alpha);
    renderer.shadowMap.autoUpdate = saved.auto;
    renderer.shadowMap.needsUpdate = saved.needs;
    renderer.setRenderTarget(saved.target);
  }
}
