// Client area lights in the page, as the native raster client draws them (shaders/area_light.glsl):
// per pixel the exact Lambertian irradiance of every emitting triangle (the same GLSL,
// shaders/area_light_math.h), a GGX term by a representative point, and soft shadows from a map
// drawn from each emitter (a blocker search, then a filter whose width grows with the light's size
// and the blocker's distance). The maps hold distance along the light's axis (a float target), so
// the tests compare metres, not depth-buffer values.
import * as THREE from 'three';
import { extractAreaLights, kMaxAreaLights, kMaxAreaTriangles } from './area_lights.js';
import { sceneEmitters } from './scene_emitters.js';
import { drawOffscreen, kMapCutout, kMapHeader, leftOutOfMaps, MapMaterials } from './offscreen.js';
import areaLightMath from '../../shaders/area_light_math.h';
import bsdf from '../../shaders/bsdf.h';

const kShadowSize = 512;       // texels a side of each light's map (RasterOptions::areaShadowMapSize)
const kShadowFovDegrees = 150;  // renderer/src/area_light_shadows.h

// The maps' fragments: distance along the light's axis over its far distance (posed meshes, cut-outs cut).
const kAreaDepthFragment = /* glsl */ `${kMapHeader}
uniform vec3 alOrigin;
uniform vec3 alAxis;
uniform float alFar;
void main() {
${kMapCutout}
  gl_FragColor = vec4(dot(vWorldPosition - alOrigin, alAxis) / alFar, 0.0, 0.0, 1.0);
}`;

export class AreaLighting {
  constructor() {
    this.cornerTexture = new THREE.DataTexture(new Float32Array(3 * kMaxAreaTriangles * 4), 3 * kMaxAreaTriangles, 1,
                                               THREE.RGBAFormat, THREE.FloatType);
    this.uniforms = {
      alCount: { value: 0 },
      alCorners: { value: this.cornerTexture },
      alRadiance: { value: Array.from({ length: kMaxAreaLights }, () => new THREE.Vector3()) },
      alCentroidSize: { value: Array.from({ length: kMaxAreaLights }, () => new THREE.Vector4()) },
      alAxisTanHalf: { value: Array.from({ length: kMaxAreaLights }, () => new THREE.Vector4()) },
      alTriangles: { value: Array.from({ length: kMaxAreaLights }, () => new THREE.Vector2()) },
      alRange: { value: Array.from({ length: kMaxAreaLights }, () => new THREE.Vector3()) },
      alViewProj: { value: Array.from({ length: kMaxAreaLights }, () => new THREE.Matrix4()) },
      alShadow: { value: null },
      alShadowSize: { value: kShadowSize },
    };
    this.declarations = kAreaLightDeclarations;
    this.call = kAreaLightCall;
    this.lights = [];
    this.cameras = [];
    this.target = null;
    this.shadowed = false;
    this.dirty = false;
    this.depthUniforms = { alOrigin: { value: new THREE.Vector3() }, alAxis: { value: new THREE.Vector3() }, alFar: { value: 1 } };
    this.depthMaterials = new MapMaterials(kAreaDepthFragment, this.depthUniforms);
  }

  // The lights of `root` under the stream's rule (share: its threshold; null: no client lights).
  // Returns how many the page draws; shadows need a float render target (`canShadow`).
  setScene(root, parser, share, canShadow) {
    const lights = share === null ? [] : (() => {
      const { materials, corners, triangleMaterial } = sceneEmitters(root, parser);
      return extractAreaLights(materials, corners, triangleMaterial, share).lights;
    })();
    this.lights = lights;
    this.shadowed = canShadow && lights.length > 0;
    this.writeUniforms(root);
    this.dirty = true;
    return lights.length;
  }

  writeUniforms(root) {
    const u = this.uniforms, data = this.cornerTexture.image.data;
    const box = new THREE.Box3().setFromObject(root, true);  // the vertices' bounds, as the native scene's
    const center = box.getCenter(new THREE.Vector3());
    const radius = Math.max(0.5 * box.getSize(new THREE.Vector3()).length(), 1e-3);
    const fov = THREE.MathUtils.degToRad(kShadowFovDegrees);
    let first = 0;
    this.cameras = this.lights.map((l, i) => {
      l.corners.forEach((c, k) => data.set([c[0], c[1], c[2], 1], 4 * (first + k)));
      const centroid = new THREE.Vector3(...l.centroid), axis = new THREE.Vector3(...l.normal);
      // Near plane just in front of the emitter's own corners, as the native client's.
      const front = Math.max(0, ...l.corners.map((c) => new THREE.Vector3(...c).sub(centroid).dot(axis)));
      const near = front + Math.max(1e-3 * radius, 1e-4);
      const far = Math.max(2 * radius + centroid.distanceTo(center), 2 * near);
      u.alRadiance.value[i].fromArray(l.radiance);
      u.alCentroidSize.value[i].set(centroid.x, centroid.y, centroid.z, Math.sqrt(l.area));
      u.alAxisTanHalf.value[i].set(axis.x, axis.y, axis.z, Math.tan(0.5 * fov));
      u.alTriangles.value[i].set(first, l.corners.length / 3);
      u.alRange.value[i].set(near, far, this.shadowed ? 1 : 0);
      first += l.corners.length;
      const cam = new THREE.PerspectiveCamera(kShadowFovDegrees, 1, near, far);
      cam.up.set(...(Math.abs(axis.y) > 0.9 ? [1, 0, 0] : [0, 1, 0]));
      cam.position.copy(centroid);
      cam.lookAt(centroid.clone().add(axis));
      cam.updateMatrixWorld(true);
      u.alViewProj.value[i].multiplyMatrices(cam.projectionMatrix, cam.matrixWorldInverse);
      return { cam, centroid, axis, far };
    });
    u.alCount.value = this.lights.length;
    this.cornerTexture.needsUpdate = true;
    if (this.shadowed && (!this.target || this.target.width !== kShadowSize * this.lights.length)) {
      this.target?.dispose();
      this.target = new THREE.WebGLRenderTarget(kShadowSize * this.lights.length, kShadowSize, {
        type: THREE.FloatType, format: THREE.RedFormat, minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
        depthBuffer: true, generateMipmaps: false,
      });
    }
    u.alShadow.value = this.shadowed ? this.target.texture : null;
  }

  // The maps, once after a scene loads and every frame while it moves (`moving`). Casters that
  // let light through (transmission, blending) are left out, as the native maps leave them, and
  // so is the background.
  drawShadows(renderer, scene, moving) {
    if (!this.shadowed || (!this.dirty && !moving)) return;
    this.dirty = false;
    // 1: the far plane.
    drawOffscreen(renderer, scene, { target: this.target, clearColor: 0xffffff, clearAlpha: 1, materials: this.depthMaterials, hide: leftOutOfMaps }, () => {
      this.cameras.forEach(({ cam, centroid, axis, far }, i) => {
        this.depthUniforms.alOrigin.value.copy(centroid);
        this.depthUniforms.alAxis.value.copy(axis);
        this.depthUniforms.alFar.value = far;
        this.target.viewport.set(i * kShadowSize, 0, kShadowSize, kShadowSize);
        this.target.scissor.set(i * kShadowSize, 0, kShadowSize, kShadowSize);
        renderer.setRenderTarget(this.target);
        renderer.render(scene, cam);
      });
    });
  }
}

// A header written in the subset of GLSL that is also C++ (shaders/*.h), as GLSL: its C++-only
// blocks (#ifdef __cplusplus … #else or #endif) and its comments left out, the headers it
// includes (`includes`: name → text) put in their place.
function glslOf(header, includes = {}) {
  const out = [];
  let skipping = false, inElse = false;
  for (const line of header.split('\n')) {
    const t = line.trim();
    if (t === '#ifdef __cplusplus') { skipping = true; continue; }
    if (skipping && t === '#else') { skipping = false; inElse = true; continue; }
    if ((skipping || inElse) && t === '#endif') { skipping = inElse = false; continue; }
    const included = /^#include "([\w.]+)"/.exec(t);
    if (!skipping && included) {
      if (!(included[1] in includes)) throw new Error(`area lights: no text for #include "${included[1]}"`);
      out.push(glslOf(includes[included[1]]));
    } else if (!skipping) {
      out.push(line.replace(/\/\/.*$/, ''));
    }
  }
  return out.join('\n');
}

// The fragment code: declarations (after three's <common>) and the call (after its lights). It
// uses the probe patch's world position and normal (probe_lighting.js).
export const kAreaLightDeclarations = `
${glslOf(areaLightMath, { 'bsdf.h': bsdf })}
precision highp sampler2D;
uniform int alCount;
uniform sampler2D alCorners;
uniform vec3 alRadiance[${kMaxAreaLights}];
uniform vec4 alCentroidSize[${kMaxAreaLights}];
uniform vec4 alAxisTanHalf[${kMaxAreaLights}];
uniform vec2 alTriangles[${kMaxAreaLights}];
uniform vec3 alRange[${kMaxAreaLights}];
uniform mat4 alViewProj[${kMaxAreaLights}];
uniform sampler2D alShadow;
uniform float alShadowSize;

vec3 alCorner(int k) { return texelFetch(alCorners, ivec2(k, 0), 0).xyz; }

// Light i's map at world point q: (u, v) in its square, the distance along its axis over its far
// plane, and 1 where q is in front of the light (else 0).
vec4 alShadowCoord(int i, vec3 q) {
  vec4 clip = alViewProj[i] * vec4(q, 1.0);
  if (clip.w <= 0.0) return vec4(0.0);
  return vec4(clip.xy / clip.w * 0.5 + 0.5, dot(q - alCentroidSize[i].xyz, alAxisTanHalf[i].xyz) / alRange[i].y, 1.0);
}
float alMapDepth(int i, vec2 uv) {
  ivec2 t = clamp(ivec2(uv * alShadowSize), ivec2(0), ivec2(int(alShadowSize) - 1));
  return texelFetch(alShadow, ivec2(t.x + i * int(alShadowSize), t.y), 0).r;
}
// The share of the four texels around uv nearer than z is not, bilinearly weighted (a comparison
// sampler's filter).
float alLit(int i, vec2 uv, float z) {
  vec2 t = uv * alShadowSize - 0.5;
  vec2 f = fract(t);
  vec2 b = (floor(t) + 0.5) / alShadowSize;
  float o = 1.0 / alShadowSize;
  float c00 = step(z, alMapDepth(i, b)), c10 = step(z, alMapDepth(i, b + vec2(o, 0.0)));
  float c01 = step(z, alMapDepth(i, b + vec2(0.0, o))), c11 = step(z, alMapDepth(i, b + vec2(o, o)));
  return mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y);
}

const int AL_TAPS = 5;

// Fraction of light i reaching p (shading normal n, geometric normal ngf), 1 where its map does
// not reach: each tap is compared against the receiver's own plane at that tap.
float alVisibility(int i, vec3 p, vec3 n, vec3 ngf) {
  if (alRange[i].z < 0.5) return 1.0;
  float tanHalf = alAxisTanHalf[i].w, far = alRange[i].y;
  float z = dot(p - alCentroidSize[i].xyz, alAxisTanHalf[i].xyz);
  if (z <= alRange[i].x) return 1.0;
  float texel = 2.0 * tanHalf * z / alShadowSize;
  vec3 q = p + n * (1.5 * texel);
  vec4 s0 = alShadowCoord(i, q);
  if (s0.w == 0.0 || any(greaterThan(abs(s0.xy * 2.0 - 1.0), vec2(1.0))) || s0.z > 1.0) return 1.0;
  vec3 t1 = normalize(abs(ngf.y) < 0.9 ? cross(ngf, vec3(0.0, 1.0, 0.0)) : cross(ngf, vec3(1.0, 0.0, 0.0)));
  vec3 t2 = cross(ngf, t1);
  vec4 s1 = alShadowCoord(i, q + t1 * texel), s2 = alShadowCoord(i, q + t2 * texel);
  vec2 dzduv = vec2(0.0);
  vec3 a = s1.xyz - s0.xyz, b = s2.xyz - s0.xyz;
  float det = a.x * b.y - a.y * b.x;
  if (s1.w != 0.0 && s2.w != 0.0 && abs(det) > 1e-14) dzduv = vec2(b.y * a.z - a.y * b.z, a.x * b.z - b.x * a.z) / det;
  float zr = s0.z * far;
  float uvPerMetre = 1.0 / (2.0 * tanHalf * zr);
  float oneTexel = 1.0 / alShadowSize;
  float size = alCentroidSize[i].w;
  float bias = 0.5 * texel / far;
  float search = clamp(0.5 * size * uvPerMetre, 1.5 * oneTexel, 0.1);
  float blockers = 0.0, blockerDepth = 0.0;
  for (int y = 0; y < AL_TAPS; ++y)
    for (int x = 0; x < AL_TAPS; ++x) {
      vec2 o = (vec2(x, y) / float(AL_TAPS - 1) * 2.0 - 1.0) * search;
      float d = alMapDepth(i, s0.xy + o);
      if (d < s0.z + dot(dzduv, o) - bias) {
        blockers += 1.0;
        blockerDepth += d * far;
      }
    }
  if (blockers == 0.0) return 1.0;
  blockerDepth /= blockers;
  float penumbra = size * max(zr - blockerDepth, 0.0) / max(blockerDepth, 1e-6);
  float radius = clamp(0.5 * penumbra * uvPerMetre, oneTexel, 0.1);
  float lit = 0.0;
  for (int y = 0; y < AL_TAPS; ++y)
    for (int x = 0; x < AL_TAPS; ++x) {
      vec2 o = (vec2(x, y) / float(AL_TAPS - 1) * 2.0 - 1.0) * radius;
      lit += alLit(i, s0.xy + o, s0.z + dot(dzduv, o) - bias);
    }
  return lit / float(AL_TAPS * AL_TAPS);
}

// Diffuse and specular light from every client area light at p, shadowed (area_light.glsl's sum).
// ab: the split-sum table at (n·wo, roughness).
void alAreaLights(vec3 p, vec3 n, vec3 ngf, vec3 wo, vec3 base, float metallic, float roughness, vec2 ab,
                  out vec3 diffuseOut, out vec3 specularOut) {
  diffuseOut = vec3(0.0);
  specularOut = vec3(0.0);
  float alpha = max(roughness * roughness, 1e-3);
  vec3 r = reflect(-wo, n);
  vec3 f0 = mix(vec3(0.04), base, metallic);
  vec3 specAlbedo = f0 * ab.x + ab.y;
  // Loops bounded by the counts, not by the caps: a compiler that unrolls constant bounds would
  // otherwise make the shader hundreds of copies of the body.
  for (int i = 0; i < alCount; ++i) {
    float irradiance = 0.0;
    vec3 specular = vec3(0.0);
    int firstCorner = int(alTriangles[i].x), triangles = int(alTriangles[i].y);
    for (int t = 0; t < triangles; ++t) {
      int k = firstCorner + 3 * t;
      vec4 tl = triangleLight(p, n, ngf, wo, r, alCorner(k), alCorner(k + 1), alCorner(k + 2), base, metallic, alpha);
      irradiance += tl.w;
      specular += tl.xyz;
    }
    if (irradiance <= 0.0) continue;
    vec3 light = alRadiance[i] * alVisibility(i, p, n, ngf);
    diffuseOut += light * base * (1.0 - metallic) / PI * irradiance;
    specularOut += light * min(specular, specAlbedo);
  }
}
`;

export const kAreaLightCall = `
  if (alCount > 0) {
    vec3 alWo = normalize(cameraPosition - vPcWorld);
    vec3 alNg = normalize(cross(dFdx(vPcWorld), dFdy(vPcWorld)));
    if (dot(alNg, alWo) < 0.0) alNg = -alNg;
    vec3 alN = normalize(inverseTransformDirection(normal, viewMatrix));
    vec2 alAB = texture2D(dfgLUT, vec2(roughnessFactor, clamp(dot(alN, alWo), 0.0, 1.0))).rg;
    vec3 alDiffuse, alSpecular;
    alAreaLights(vPcWorld, alN, alNg, alWo, diffuseColor.rgb, metalnessFactor, roughnessFactor, alAB, alDiffuse, alSpecular);
    reflectedLight.directDiffuse += alDiffuse;
    reflectedLight.directSpecular += alSpecular;
  }`;
