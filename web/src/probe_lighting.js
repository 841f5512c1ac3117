// Diffuse indirect light from the probe volume in three.js's physical material: the 8 probes of a
// point's cell weighted by trilinear × backface × activity, as the native raster client weighs
// them (shaders/raster.frag, probeCoefficientsVisible), without its per-probe depth moments (the
// browser has no visibility maps yet: docs/WEB.md). The probes hold L2 SH of incident radiance
// (sh.h): irradiance E(n) = Σ Â_l c_lm Y_lm(n), which three's Lambert BRDF divides by π.
import * as THREE from 'three';

const kTexels = 7;  // 27 coefficients and a pad per probe: 7 RGBA texels along x

export class ProbeLighting {
  constructor() {
    this.uniforms = {
      pcProbes: { value: null },
      pcPositions: { value: null },
      pcMin: { value: new THREE.Vector3() },
      pcMax: { value: new THREE.Vector3() },
      pcDims: { value: new THREE.Vector3(1, 1, 1) },
      pcOn: { value: 0 },
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
    }
    this.uniforms.pcProbes.value.needsUpdate = true;
    this.uniforms.pcPositions.value.needsUpdate = true;
    this.uniforms.pcMin.value.fromArray(bounds.min);
    this.uniforms.pcMax.value.fromArray(bounds.max);
    this.uniforms.pcDims.value.fromArray(dims);
    this.uniforms.pcOn.value = 1;
  }

  // Patches a MeshStandardMaterial / MeshPhysicalMaterial to add the probes' irradiance.
  apply(material) {
    const uniforms = this.uniforms;
    material.onBeforeCompile = (shader) => {
      Object.assign(shader.uniforms, uniforms);
      shader.vertexShader = shader.vertexShader
        .replace('#include <common>', '#include <common>\nvarying vec3 vPcWorld;\nvarying vec3 vPcNormal;')
        .replace('#include <project_vertex>', `#include <project_vertex>
  vPcWorld = (modelMatrix * vec4(transformed, 1.0)).xyz;
  vPcNormal = mat3(modelMatrix) * objectNormal;`);
      shader.fragmentShader = shader.fragmentShader
        .replace('#include <common>', `#include <common>\n${kIrradianceGlsl}`)
        .replace('#include <lights_fragment_maps>', `#include <lights_fragment_maps>
  if (pcOn > 0.5) irradiance += pcIrradiance(vPcWorld, normalize(vPcNormal) * faceDirection);`);
    };
    material.customProgramCacheKey = () => 'probecast-probes';
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
varying vec3 vPcWorld;
varying vec3 vPcNormal;

vec3 pcIrradiance(vec3 p, vec3 n) {
  vec3 dims = pcDims;
  ivec3 last = ivec3(dims) - 1;
  vec3 extent = max(pcMax - pcMin, vec3(1e-6));
  vec3 g = clamp((p - pcMin) / extent * (dims - 1.0), vec3(0.0), dims - 1.0);
  ivec3 base = ivec3(min(floor(g), max(dims - 2.0, vec3(0.0))));
  vec3 a = clamp(g - vec3(base), vec3(0.0), vec3(1.0));
  float spacing = length(extent / max(dims - 1.0, vec3(1.0)));
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
    float facing = len > 1e-6 ? (dot(toProbe / len, n) + 1.0) * 0.5 : 1.0;
    anyInFront = anyInFront || dot(toProbe, n) > -1e-3 * spacing;
    float w = (facing * facing + 0.2) * trilinear;
    for (int t = 0; t < 7; ++t) c[t] += w * texelFetch(pcProbes, ivec3(idx.x * 7 + t, idx.y, idx.z), 0);
    total += w;
  }
  if (!anyInFront || total <= 1e-10) return vec3(0.0);
  float s[28];
  for (int t = 0; t < 7; ++t) {
    s[4 * t] = c[t].x / total;
    s[4 * t + 1] = c[t].y / total;
    s[4 * t + 2] = c[t].z / total;
    s[4 * t + 3] = c[t].w / total;
  }
  // Basis at n (sh_basis.cpp), times the clamped-cosine band weights (π, 2π/3, π/4).
  float y[9];
  y[0] = 0.282094792 * 3.14159265;
  y[1] = 0.488602512 * n.y * 2.09439510;
  y[2] = 0.488602512 * n.z * 2.09439510;
  y[3] = 0.488602512 * n.x * 2.09439510;
  y[4] = 1.092548431 * n.x * n.y * 0.78539816;
  y[5] = 1.092548431 * n.y * n.z * 0.78539816;
  y[6] = 0.315391565 * (3.0 * n.z * n.z - 1.0) * 0.78539816;
  y[7] = 1.092548431 * n.x * n.z * 0.78539816;
  y[8] = 0.546274215 * (n.x * n.x - n.y * n.y) * 0.78539816;
  vec3 e = vec3(0.0);
  for (int i = 0; i < 9; ++i) e += y[i] * vec3(s[3 * i], s[3 * i + 1], s[3 * i + 2]);
  return max(e, vec3(0.0));
}
`;
