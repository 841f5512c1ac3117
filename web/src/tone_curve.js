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
