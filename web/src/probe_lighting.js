// Indirect light from the probe volume in three.js's physical material, as the native raster
// client computes it (shaders/raster.frag): the 8 probes of a point's cell weighted by trilinear ×
// backface × activity × Chebyshev visibility from each probe's distance moments
// (probeCoefficientsVisible; the moments from probe_visibility.js, the weights without them until
// the first map is made); diffuse base (1 − metallic) / π · E(n) with
// E(n) = Σ Â_l c_lm Y_lm(n) (sh.h: L2 SH of incident radiance), and glossy by the split sum,
// Σ_l g_l(roughness) c_lm Y_lm(R) · (F0·A + B) (glossy_sh.h). Both are added to three's reflected
// light directly, so that three's own energy split does not scale them.
import * as THREE from 'three';
import { kOct, kTile, kTilesPerRow } from './probe_visibility.js';

const kTexels = 7;  // 27 coefficients and a pad per probe: 7 RGBA texels along x

export class ProbeLighting {
  // area: an AreaLighting (area_light_shading.js) whose lights the patched materials draw too, or null;
  // visibility: a ProbeVisibility (probe_visibility.js) whose moments weigh the probes, or null.
  constructor(area = null, visibility = null) {
    this.area = area;
    this.visibility = visibility;
    this.positions = new Float32Array(0);  // xyz a probe: grid point plus offset
    this.uniforms = {
      pcProbes: { value: null },
      pcPositions: { value: null },
      pcMin: { value: new THREE.Vector3() },
      pcMax: { value: new THREE.Vector3() },
      pcDims: { value: new THREE.Vector3(1, 1, 1) },
      pcOn: { value: 0 },
      ...(visibility ? visibility.uniforms : { pcVis: { value: null }, pcVisOn: { value: 0 }, pcReach: { value: 1e30 } }),
    };
    this.dims = null;
  }

  // probes: 27 floats per probe; active: a byte per probe; offsets: 3 floats per probe or null.
  update(dims, bounds, probes, active, offsets) {
    const [nx, ny, nz] = dims;
    const count = nx * ny * nz;
    const same = this.dims && this.dims.every((d, i) => d === dims[i]);
    if (!same) {
      this.uniforms.pcProbes.value?.dispose();
      this.uniforms.pcPositions.value?.dispose();
      const make = (w) => {
        const t = new THREE.Data3DTexture(new Float32Array(w * ny * nz * 4), w, ny, nz);
        t.format = THREE.RGBAFormat;
        t.type = THREE.FloatType;
        t.minFilter = t.magFilter = THREE.NearestFilter;
        t.unpackAlignment = 1;
        return t;
      };
      this.uniforms.pcProbes.value = make(nx * kTexels);
      this.uniforms.pcPositions.value = make(nx);
      this.dims = dims.slice();
    }
    const coef = this.uniforms.pcProbes.value.image.data;
    const pos = this.uniforms.pcPositions.value.image.data;
    if (this.positions.length !== 3 * count) this.positions = new Float32Array(3 * count);
    const step = [0, 1, 2].map((a) => (dims[a] > 1 ? (bounds.max[a] - bounds.min[a]) / (dims[a] - 1) : 0));
    for (let i = 0; i < count; ++i) {
      const x = i % nx, y = Math.floor(i / nx) % ny, z = Math.floor(i / (nx * ny));
      const row = ((z * ny + y) * nx * kTexels + x * kTexels) * 4;
      for (let c = 0; c < 27; ++c) coef[row + c] = probes[27 * i + c];
      coef[row + 27] = 0;
      const g = [x, y, z].map((v, a) => (dims[a] > 1 ? bounds.min[a] + v * step[a] : 0.5 * (bounds.min[a] + bounds.max[a])));
      const o = offsets ? [offsets[3 * i], offsets[3 * i + 1], offsets[3 * i + 2]] : [0, 0, 0];
      const p = 4 * i;
      pos[p] = g[0] + o[0];
      pos[p + 1] = g[1] + o[1];
      pos[p + 2] = g[2] + o[2];
      pos[p + 3] = active[i] ? 1 : 0;
      this.positions.set(pos.subarray(p, p + 3), 3 * i);
    }
    this.uniforms.pcProbes.value.needsUpdate = true;
    this.uniforms.pcPositions.value.needsUpdate = true;
    this.uniforms.pcMin.value.fromArray(bounds.min);
    this.uniforms.pcMax.value.fromArray(bounds.max);
    this.uniforms.pcDims.value.fromArray(dims);
    this.uniforms.pcOn.value = 1;
    this.grid = { dims: dims.slice(), bounds: { min: bounds.min.slice(), max: bounds.max.slice() } };
  }

  // Patches a MeshStandardMaterial / MeshPhysicalMaterial to add the probes' irradiance.
  apply(material) {
    const uniforms = this.uniforms, area = this.area;
    material.onBeforeCompile = (shader) => {
      Object.assign(shader.uniforms, uniforms, area ? area.uniforms : {});
      shader.vertexShader = shader.vertexShader
        .replace('#include <common>', '#include <common>\nvarying vec3 vPcWorld;\nvarying vec3 vPcNormal;')
        .replace('#include <project_vertex>', `#include <project_vertex>
  vPcWorld = (modelMatrix * vec4(transformed, 1.0)).xyz;
  vPcNormal = mat3(modelMatrix) * objectNormal;`);
      shader.fragmentShader = shader.fragmentShader
        .replace('#include <common>', `#include <common>\n${kIrradianceGlsl}${area ? area.declarations : ''}`)
        .replace('#include <lights_fragment_end>', `#include <lights_fragment_end>
  if (pcOn > 0.5) {
    vec3 pcN = normalize(vPcNormal) * faceDirection;
    vec3 pcV = normalize(cameraPosition - vPcWorld);
    // The geometric normal on the viewer's side, from the position's screen derivatives (raster.frag).
    vec3 pcNg = cross(dFdx(vPcWorld), dFdy(vPcWorld));
    pcNg = length(pcNg) > 1e-20 ? normalize(pcNg) : pcV;
    if (dot(pcNg, pcV) < 0.0) pcNg = -pcNg;
    float pcC[28];
    if (pcCoefficients(vPcWorld, pcNg, pcV, pcC)) {
      reflectedLight.indirectDiffuse += diffuseColor.rgb * (1.0 - metalnessFactor) * RECIPROCAL_PI * pcIrradiance(pcC, pcN);
      vec3 pcF0 = mix(vec3(0.04), diffuseColor.rgb, metalnessFactor);
      vec2 pcAB = texture2D(dfgLUT, vec2(roughnessFactor, saturate(dot(pcN, pcV)))).rg;
      reflectedLight.indirectSpecular += pcGlossy(pcC, reflect(-pcV, pcN), roughnessFactor) * (pcF0 * pcAB.x + pcAB.y);
    }
  }${area ? area.call : ''}`);
    };
    material.customProgramCacheKey = () => (area ? 'probecast-probes-area' : 'probecast-probes');
    material.needsUpdate = true;
  }
}

const kIrradianceGlsl = /* glsl */ `
precision highp sampler3D;
uniform sampler3D pcProbes;
uniform sampler3D pcPositions;
uniform vec3 pcMin;
uniform vec3 pcMax;
uniform vec3 pcDims;
uniform float pcOn;
precision highp sampler2D;
uniform sampler2D pcVis;
uniform float pcVisOn;
uniform float pcReach;
varying vec3 vPcWorld;
varying vec3 vPcNormal;

// Octahedral map of unit directions to [-1, 1]² (probe_visibility.js's octEncode).
vec2 pcOctEncode(vec3 v) {
  vec2 e = v.xy / (abs(v.x) + abs(v.y) + abs(v.z));
  if (v.z < 0.0) e = (1.0 - abs(e.yx)) * vec2(e.x >= 0.0 ? 1.0 : -1.0, e.y >= 0.0 ? 1.0 : -1.0);
  return e;
}

// (E[r], E[r²]) of probe index toward dir, bilinear inside its tile (the border repeats the
// texels across the octahedron's edges), as the native sampler filters the atlas.
vec2 pcMomentsToward(int index, vec3 dir) {
  ivec2 tile = ivec2(index % ${kTilesPerRow}, index / ${kTilesPerRow}) * ${kTile};
  vec2 t = vec2(tile) + 1.0 + (pcOctEncode(dir) * 0.5 + 0.5) * ${kOct}.0 - 0.5;
  ivec2 i = ivec2(floor(t));
  vec2 f = t - vec2(i);
  vec2 a = mix(texelFetch(pcVis, i, 0).xy, texelFetch(pcVis, i + ivec2(1, 0), 0).xy, f.x);
  vec2 b = mix(texelFetch(pcVis, i + ivec2(0, 1), 0).xy, texelFetch(pcVis, i + ivec2(1, 1), 0).xy, f.x);
  return mix(a, b, f.y);
}

// The 27 coefficients at p (geometric normal ng on the viewer's side, towards the viewer wo) from
// the 8 probes of its cell, each weighted by trilinear × backface × Chebyshev visibility: the
// point, moved off the surface along ng and wo by a fraction of the probe spacing, is visible from
// a probe with probability at least σ²/(σ² + (r − μ)²) when farther than the mean distance μ of
// what the probe sees that way (both no farther than the probe's reach). False where no probe
// lights it.
bool pcCoefficients(vec3 p, vec3 ng, vec3 wo, out float s[28]) {
  for (int i = 0; i < 28; ++i) s[i] = 0.0;
  vec3 dims = pcDims;
  ivec3 last = ivec3(dims) - 1;
  vec3 extent = max(pcMax - pcMin, vec3(1e-6));
  vec3 g = clamp((p - pcMin) / extent * (dims - 1.0), vec3(0.0), dims - 1.0);
  ivec3 base = ivec3(min(floor(g), max(dims - 2.0, vec3(0.0))));
  vec3 a = clamp(g - vec3(base), vec3(0.0), vec3(1.0));
  vec3 cell = extent / max(dims - 1.0, vec3(1.0));
  float spacing = min(dims.x > 1.0 ? cell.x : 1e9, min(dims.y > 1.0 ? cell.y : 1e9, dims.z > 1.0 ? cell.z : 1e9));
  spacing = spacing < 1e9 ? spacing : 1.0;
  vec3 q = p + (0.2 * ng + 0.8 * wo) * (0.75 * 0.3 * spacing);
  vec4 c[7];
  for (int t = 0; t < 7; ++t) c[t] = vec4(0.0);
  float total = 0.0;
  bool anyInFront = false;
  for (int k = 0; k < 8; ++k) {
    ivec3 off = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    vec3 t3 = mix(1.0 - a, a, vec3(off));
    float trilinear = t3.x * t3.y * t3.z;
    ivec3 idx = min(base + off, last);
    vec4 probe = texelFetch(pcPositions, idx, 0);
    if (trilinear <= 0.0 || probe.w < 0.5) continue;
    vec3 toProbe = probe.xyz - p;
    float len = length(toProbe);
    float facing = len > 1e-6 ? (dot(toProbe / len, ng) + 1.0) * 0.5 : 1.0;
    anyInFront = anyInFront || dot(toProbe, ng) > -1e-3 * spacing;
    float w = facing * facing + 0.2;
    if (pcVisOn > 0.5) {
      vec3 fromProbe = q - probe.xyz;
      float r = length(fromProbe);
      vec2 m = pcMomentsToward(idx.x + int(dims.x) * (idx.y + int(dims.y) * idx.z), r > 1e-6 ? fromProbe / r : ng);
      r = min(r, pcReach);  // beyond its reach a point is tested as if at it
      if (r > m.x) {
        float variance = abs(m.y - m.x * m.x);
        float d = r - m.x;
        float chebyshev = variance / (variance + d * d);
        w *= chebyshev * chebyshev * chebyshev;
      }
      if (w < 0.2) w *= w * w / (0.2 * 0.2);  // a mostly hidden probe adds nothing
    }
    w *= trilinear;
    if (w <= 0.0) continue;
    for (int t = 0; t < 7; ++t) c[t] += w * texelFetch(pcProbes, ivec3(idx.x * 7 + t, idx.y, idx.z), 0);
    total += w;
  }
  if (!anyInFront || total <= 1e-10) return false;
  for (int t = 0; t < 7; ++t) {
    s[4 * t] = c[t].x / total;
    s[4 * t + 1] = c[t].y / total;
    s[4 * t + 2] = c[t].z / total;
    s[4 * t + 3] = c[t].w / total;
  }
  return true;
}

// Σ_i k_i Y_i(d) c_i with band weights k (sh_basis.cpp's basis).
vec3 pcEval(float s[28], vec3 d, float k0, float k1, float k2) {
  float y[9];
  y[0] = 0.282094792 * k0;
  y[1] = 0.488602512 * d.y * k1;
  y[2] = 0.488602512 * d.z * k1;
  y[3] = 0.488602512 * d.x * k1;
  y[4] = 1.092548431 * d.x * d.y * k2;
  y[5] = 1.092548431 * d.y * d.z * k2;
  y[6] = 0.315391565 * (3.0 * d.z * d.z - 1.0) * k2;
  y[7] = 1.092548431 * d.x * d.z * k2;
  y[8] = 0.546274215 * (d.x * d.x - d.y * d.y) * k2;
  vec3 e = vec3(0.0);
  for (int i = 0; i < 9; ++i) e += y[i] * vec3(s[3 * i], s[3 * i + 1], s[3 * i + 2]);
  return max(e, vec3(0.0));
}

// Irradiance: the clamped-cosine band weights (π, 2π/3, π/4).
vec3 pcIrradiance(float s[28], vec3 n) { return pcEval(s, n, 3.14159265, 2.09439510, 0.78539816); }

// The GGX lobe's zonal scales g_l, rational in α = roughness² (glossy_sh.h; the coefficients are
// ggxLobeFit()'s).
float pcLobe(float a, vec4 f) { return (1.0 + f.x * a + f.y * a * a) / (1.0 + f.z * a + f.w * a * a); }
vec3 pcGlossy(float s[28], vec3 r, float roughness) {
  float a = roughness * roughness;
  return pcEval(s, r, 1.0, pcLobe(a, vec4(2.1795214, 3.78937271, 2.46112562, 6.99579005)),
                pcLobe(a, vec4(1.79515323, 0.378824571, 2.5905287, 9.12932987)));
}
`;
