// The native viewer's picture curve in three.js: linear light times the exposure, the filmic curve
// (imaging/image_io.cpp: x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)), then gamma 2.2. With it a
// page's canvas can be compared with `probecast view` pixel for pixel.
import * as THREE from 'three';

let patched = false;

// Makes three's CustomToneMapping the curve (once), and sets `renderer` to draw through it.
export function useProbecastCurve(renderer, exposure = 1) {
  if (!patched) {
    THREE.ShaderChunk.tonemapping_pars_fragment = THREE.ShaderChunk.tonemapping_pars_fragment.replace(
      'vec3 CustomToneMapping( vec3 color ) { return color; }',
      `vec3 CustomToneMapping( vec3 color ) {
  vec3 v = max( color * toneMappingExposure, vec3( 0.0 ) );
  v = v * ( 2.51 * v + 0.03 ) / ( v * ( 2.43 * v + 0.59 ) + 0.14 );
  return pow( min( v, vec3( 1.0 ) ), vec3( 1.0 / 2.2 ) );
}`);
    patched = true;
  }
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;  // the curve ends in gamma 2.2
  renderer.toneMapping = THREE.CustomToneMapping;
  renderer.toneMappingExposure = exposure;
}

// Draws a view as the native client anti-aliases it: the samples of each pixel are averaged in
// linear light (a multisampled half-float target) and the renderer's tone mapping and output
// colour space are applied to the averaged pixel. three.js's own multisampled canvas averages
// after the curve, which darkens every edge between light and shadow (half of a sunlit pixel
// reads 0.5 there, 0.73 after the curve natively).
export class LinearLightView {
  constructor(samples = 4) {
    this.target = new THREE.WebGLRenderTarget(1, 1, { type: THREE.HalfFloatType, samples, depthBuffer: true,
      minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter });
    this.material = new THREE.ShaderMaterial({
      uniforms: { picture: { value: this.target.texture } },
      vertexShader: 'void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }',
      fragmentShader: `uniform sampler2D picture;
void main() {
  gl_FragColor = vec4(texelFetch(picture, ivec2(gl_FragCoord.xy), 0).rgb, 1.0);
  #include <tonemapping_fragment>
  #include <colorspace_fragment>
}`,
      depthTest: false, depthWrite: false, toneMapped: true,
    });
    this.quad = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), this.material);
    this.quad.frustumCulled = false;
    this.quadScene = new THREE.Scene().add(this.quad);
    this.quadCamera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1);
    this.size = new THREE.Vector2();
  }

  // Draws `scene` from `camera` into the target at the drawing buffer's size, then onto the canvas.
  // In an XR session three.js draws into the headset's framebuffer as it always does.
  render(renderer, scene, camera) {
    if (renderer.xr.isPresenting) return renderer.render(scene, camera);
    renderer.getDrawingBufferSize(this.size);
    if (this.target.width !== this.size.x || this.target.height !== this.size.y) this.target.setSize(this.size.x, this.size.y);
    const saved = renderer.getRenderTarget();
    renderer.setRenderTarget(this.target);
    renderer.render(scene, camera);
    renderer.setRenderTarget(saved);
    renderer.render(this.quadScene, this.quadCamera);
  }

  dispose() {
    this.target.dispose();
    this.material.dispose();
    this.quad.geometry.dispose();
  }
}
