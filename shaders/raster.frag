#version 460
// Raster client shading: surface emission + direct light from punctual lights (shadow maps, 3×3
// PCF) and from client area lights (area_light.glsl) + diffuse indirect albedo/π · E(n) and
// split-sum glossy indirect from the probe volume
// (8 probes weighted by visibility from per-probe distance moments, or hardware trilinear in the 3D
// textures with visibility off), linear radiance out. Cut-away points (alphaMode Mask) are discarded;
// transmissive surfaces (scene.h's rule) are drawn after the opaque ones in two blended passes:
// RS_PASS_TRANSMIT multiplies what lies behind by T = τ·base, RS_PASS_REFLECT adds emission +
// (1 − τ)·(direct + indirect). One layer is exact; several are order-independent but approximate
// (a far layer's reflection is not tinted by a nearer one).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_multiview : require
#include "raster_shared.h"

layout(location = 0) in vec3 worldPosition;
layout(location = 1) in vec3 worldNormal;
layout(location = 2) in vec4 texcoord;  // TEXCOORD_0, TEXCOORD_1
layout(location = 0) out vec4 outColor;
layout(push_constant) uniform Push { RsPushConstants pc; };

layout(std430, binding = RS_BINDING_TRIANGLE_MATERIAL) readonly buffer TriangleMaterial { uint triangleMaterial[]; };
layout(std430, binding = RS_BINDING_MATERIALS) readonly buffer Materials { PtMaterial materials[]; };
layout(std430, binding = RS_BINDING_LIGHTS) readonly buffer Lights { PtLight lights[]; };
layout(std430, binding = RS_BINDING_TEXELS) readonly buffer Texels { uint texels[]; };
layout(std430, binding = RS_BINDING_TEXTURES) readonly buffer Textures { PtTexture textures[]; };
layout(binding = RS_BINDING_PROBES) uniform sampler3D probeVolume[RS_PROBE_TEXTURES];
layout(binding = RS_BINDING_ENV_BRDF) uniform sampler2D envBrdf;
layout(std430, binding = RS_BINDING_VIEWS) readonly buffer Views { RsView views[]; };
layout(std430, binding = RS_BINDING_SHADOW_LIGHTS) readonly buffer ShadowLights { RsShadowLight shadowLights[]; };
layout(std430, binding = RS_BINDING_SHADOW_LAYERS) readonly buffer ShadowLayers { RsShadowLayer shadowLayers[]; };
layout(binding = RS_BINDING_SHADOW_MAP) uniform sampler2DArrayShadow shadowMap;
layout(binding = RS_BINDING_SHADOW_TRANSMIT) uniform sampler2DArray shadowTransmit;
layout(std430, binding = RS_BINDING_PROBE_POSITIONS) readonly buffer ProbePositions { vec4 probePositions[]; };
layout(binding = RS_BINDING_PROBE_MOMENTS) uniform sampler2D probeMoments;

#include "material.glsl"
#include "area_light.glsl"

// The probe volume's 27 SH coefficients at p (trilinear over active probes).
bool probeCoefficients(vec3 p, out float c[28]) {
  for (int i = 0; i < 28; ++i) c[i] = 0.0;
  if (pc.volumeMin.w == 0.0) return false;
  vec3 extent = max(pc.volumeMax.xyz - pc.volumeMin.xyz, vec3(1e-6));
  vec3 dims = pc.volumeDims.xyz;
  vec3 uvw = ((p - pc.volumeMin.xyz) / extent * (dims - 1.0) + 0.5) / dims;
  for (int t = 0; t < RS_PROBE_TEXTURES; ++t) {
    vec4 v = texture(probeVolume[t], uvw);
    c[4 * t] = v.x;
    c[4 * t + 1] = v.y;
    c[4 * t + 2] = v.z;
    c[4 * t + 3] = v.w;
  }
  // Weighted by activity (raster_client.cpp): renormalise so inactive probes never darken.
  float weight = c[27];
  if (weight > 0.0)
    for (int i = 0; i < 27; ++i) c[i] /= weight;
  return true;
}

// Octahedral map of unit directions to [-1, 1]² (probe_visibility.cpp's octEncode).
vec2 octEncode(vec3 v) {
  vec2 e = v.xy / (abs(v.x) + abs(v.y) + abs(v.z));
  if (v.z < 0.0) e = (1.0 - abs(e.yx)) * vec2(e.x >= 0.0 ? 1.0 : -1.0, e.y >= 0.0 ? 1.0 : -1.0);
  return e;
}

// (E[r], E[r²]) of probe `index` toward `dir`, bilinear inside its tile (the border repeats the
// texels across the octahedron's edges).
vec2 probeMomentsToward(uint index, vec3 dir) {
  uvec2 tile = uvec2(index % RS_VIS_TILES_PER_ROW, index / RS_VIS_TILES_PER_ROW) * uint(RS_VIS_TILE);
  vec2 texel = vec2(tile) + 1.0 + (octEncode(dir) * 0.5 + 0.5) * float(RS_VIS_OCT);
  return texture(probeMoments, texel / vec2(textureSize(probeMoments, 0))).xy;
}

// The 27 SH coefficients at p (geometric normal ng, towards the viewer wo) from the 8 probes of
// its cell, each weighted by trilinear × backface × Chebyshev visibility (DDGI's weights): the
// point, moved off the surface along ng and wo by a fraction of the probe spacing, is visible from
// a probe with probability at least σ²/(σ² + (r − μ)²) when farther than the mean distance μ of
// what the probe sees that way (both no farther than the probe's reach). Inactive probes weigh 0;
// where all 8 are inactive, the filled trilinear volume answers (probeCoefficients).
bool probeCoefficientsVisible(vec3 p, vec3 ng, vec3 wo, out float c[28]) {
  for (int i = 0; i < 28; ++i) c[i] = 0.0;
  if (pc.volumeMin.w == 0.0) return false;
  vec3 dims = pc.volumeDims.xyz;
  ivec3 last = ivec3(dims) - 1;
  vec3 extent = max(pc.volumeMax.xyz - pc.volumeMin.xyz, vec3(1e-6));
  vec3 g = clamp((p - pc.volumeMin.xyz) / extent * (dims - 1.0), vec3(0.0), dims - 1.0);
  ivec3 base = ivec3(min(floor(g), max(dims - 2.0, vec3(0.0))));
  vec3 alpha = clamp(g - vec3(base), vec3(0.0), vec3(1.0));
  vec3 q = p + (0.2 * ng + 0.8 * wo) * (0.75 * 0.3 * pc.volumeMax.w);
  float total = 0.0;
  int activeProbes = 0;
  bool anyInFront = false;
  for (int k = 0; k < 8; ++k) {
    ivec3 off = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    vec3 t3 = mix(1.0 - alpha, alpha, vec3(off));
    float trilinear = t3.x * t3.y * t3.z;
    ivec3 idx = min(base + off, last);
    vec4 tail = texelFetch(probeVolume[RS_PROBE_TEXTURES - 1], idx, 0);
    if (trilinear <= 0.0 || tail.w < 0.5) continue;  // tail.w: 1 active, kInactiveWeight inactive
    ++activeProbes;
    uint index = uint(idx.x + int(dims.x) * (idx.y + int(dims.y) * idx.z));
    vec3 probe = probePositions[index].xyz;
    vec3 toProbe = probe - p;
    float len = length(toProbe);
    float facing = len > 1e-6 ? (dot(toProbe / len, ng) + 1.0) * 0.5 : 1.0;
    anyInFront = anyInFront || dot(toProbe, ng) > -1e-3 * pc.volumeMax.w;
    float w = facing * facing + 0.2;
    vec3 fromProbe = q - probe;
    float r = length(fromProbe);
    vec2 m = probeMomentsToward(index, r > 1e-6 ? fromProbe / r : ng);
    // The moments stop at the probe's reach (w): a point beyond it is tested as if at the reach,
    // so that it is hidden by what lies nearer and seen where nothing does.
    r = min(r, probePositions[index].w);
    if (r > m.x) {
      float variance = abs(m.y - m.x * m.x);
      float d = r - m.x;
      float chebyshev = variance / (variance + d * d);
      w *= chebyshev * chebyshev * chebyshev;
    }
    if (w < 0.2) w *= w * w / (0.2 * 0.2);  // crush small weights: a mostly hidden probe adds nothing
    w *= trilinear;
    if (w <= 0.0) continue;
    for (int t = 0; t < RS_PROBE_TEXTURES; ++t) {
      vec4 v = t == RS_PROBE_TEXTURES - 1 ? tail : texelFetch(probeVolume[t], idx, 0);
      c[4 * t] += w * v.x / tail.w;
      c[4 * t + 1] += w * v.y / tail.w;
      c[4 * t + 2] += w * v.z / tail.w;
      c[4 * t + 3] += w * v.w / tail.w;
    }
    total += w;
  }
  if (activeProbes == 0) return probeCoefficients(p, c);
  // Every active probe behind the surface's plane (the outer face of a wall or ceiling, probes all
  // inside) or hidden: no probe sees the point, so none lights it. Renormalising the backface
  // floor's small weights would light it fully from the far side.
  float scale = anyInFront && total > 1e-10 ? 1.0 / total : 0.0;
  for (int i = 0; i < 27; ++i) c[i] *= scale;
  return true;
}

// zh3PerPixel (zh3h, interpolate then hallucinate): adds the L2 band hallucinated from the
// interpolated L1 alone, as zh3HallucinateInPlace in codec/zh3.h (same axis, curve and expansion),
// to the interpolated band (0 at probes that hallucinate, minus their own band at probes the
// encoder kept at plain L1: ProbeVolume::zh3PerPixel).
void hallucinateZh3(inout float c[28]) {
  const vec3 luma = vec3(0.2126, 0.7152, 0.0722);
  vec3 d[3];
  vec3 a = vec3(0.0);
  for (int k = 0; k < 3; ++k) {
    d[k] = vec3(c[9 + k], c[3 + k], c[6 + k]);  // (c3, c1, c2) = (x, y, z)
    a += luma[k] * d[k];
  }
  a = dot(a, a) > 1e-24 ? normalize(a) : vec3(0.0, 0.0, 1.0);
  float y2[5] = float[5](1.092548431 * a.x * a.y, 1.092548431 * a.y * a.z, 0.315391565 * (3.0 * a.z * a.z - 1.0),
                         1.092548431 * a.x * a.z, 0.546274215 * (a.x * a.x - a.y * a.y));
  for (int k = 0; k < 3; ++k) {
    float c00 = c[k];
    float zonal = 0.0;
    if (c00 > 0.0) {
      float r = abs(dot(d[k], a)) / c00;
      zonal = c00 * (0.08 * r + 0.6 * r * r) * sqrt(4.0 * PI / 5.0);
    }
    for (int m = 0; m < 5; ++m) c[(4 + m) * 3 + k] += zonal * y2[m];
  }
}

// Light reaching world point q through `layer`: 3×3 PCF of hardware 2×2 comparisons against the
// opaque depth, times the transmittance of the transmissive casters when q lies behind the
// nearest of them (shadow_transmit.frag; depth as ndc z, or metres along a perspective layer's
// view); 1 outside the layer.
vec3 layerVisibility(uint layer, vec3 q) {
  vec4 clip = shadowLayers[layer].viewProj * vec4(q, 1.0);
  if (clip.w <= 0.0) return vec3(1.0);
  vec3 ndc = clip.xyz / clip.w;
  if (any(greaterThan(abs(ndc.xy), vec2(1.0))) || ndc.z > 1.0) return vec3(1.0);
  vec2 uv = ndc.xy * 0.5 + 0.5;
  float step = 1.0 / float(pc.shadowMapSize);
  float lit = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) lit += texture(shadowMap, vec4(uv + vec2(x, y) * step, float(layer), ndc.z));
  vec4 t = texture(shadowTransmit, vec3(uv, float(layer)));
  bool perspective = shadowLayers[layer].texel.y != 0.0;
  float depth = perspective ? clip.w : ndc.z;
  bool behind = t.a < RS_TRANSMIT_CLEAR_DEPTH * 0.5 && depth > t.a * 1.001 + (perspective ? 1e-3 : 2e-4);
  return lit / 9.0 * (behind ? clamp(t.rgb, 0.0, 1.0) : vec3(1.0));
}

// A directional light's cascades (finest first): the finest layer whose square holds p, blended
// into the next one over the outer 10 % of its square so that no seam shows where they meet. The
// normal offset grows with the layer's texel size and with the slope to the light (grazing light
// stretches a texel over more of the surface).
vec3 cascadeVisibility(RsShadowLight s, vec3 p, vec3 n, vec3 wi) {
  const float band = 0.1;
  float cosine = clamp(dot(n, wi), 0.0, 1.0);
  float offset = 1.0 + 0.5 * min(sqrt(1.0 - cosine * cosine) / max(cosine, 0.05), 2.0);  // texels
  for (uint k = 0u; k < s.cascades; ++k) {
    uint layer = s.firstLayer + k;
    vec4 clip = shadowLayers[layer].viewProj * vec4(p, 1.0);
    float edge = max(abs(clip.x), abs(clip.y));
    if (edge >= 1.0 && k + 1u < s.cascades) continue;
    vec3 v = layerVisibility(layer, p + n * (offset * shadowLayers[layer].texel.x));
    float w = k + 1u < s.cascades ? clamp((edge - (1.0 - band)) / band, 0.0, 1.0) : 0.0;
    if (w > 0.0) {
      float next = shadowLayers[layer + 1u].texel.x;
      v = mix(v, layerVisibility(layer + 1u, p + n * (offset * next)), w);
    }
    return v;
  }
  return vec3(1.0);
}

// Light of light `i` reaching p (normal n) by its shadow map: 3×3 PCF of hardware 2×2
// comparisons, normal offset of 1.5 texels against acne, tinted by transmissive casters.
vec3 shadowVisibility(uint i, vec3 p, vec3 n) {
  RsShadowLight s = shadowLights[i];
  if (s.kind == RS_SHADOW_NONE) return vec3(1.0);
  if (s.kind == RS_SHADOW_ORTHO && s.cascades > 1u) return cascadeVisibility(s, p, n, -lights[i].directionRange.xyz);
  uint layer = s.firstLayer;
  float texel = s.texelScale;
  if (s.kind != RS_SHADOW_ORTHO) {
    vec3 d = p - lights[i].positionType.xyz;
    vec3 ad = abs(d);
    if (s.kind == RS_SHADOW_CUBE)
      layer += ad.x >= ad.y && ad.x >= ad.z ? (d.x > 0.0 ? 0u : 1u) : ad.y >= ad.z ? (d.y > 0.0 ? 2u : 3u) : (d.z > 0.0 ? 4u : 5u);
    texel *= length(d);
  }
  return layerVisibility(layer, p + n * (1.5 * texel));
}

// L2 SH irradiance E(n) = Σ Â_l c_lm Y_lm(n) (docs/CODEC.md §1), clamped ≥ 0.
vec3 probeIrradiance(float c[28], vec3 n) {
  float x = n.x, y = n.y, z = n.z;
  float basis[9] = float[9](0.282094792 * PI, 0.488602512 * y * (2.0 * PI / 3.0), 0.488602512 * z * (2.0 * PI / 3.0),
                            0.488602512 * x * (2.0 * PI / 3.0), 1.092548431 * x * y * (PI / 4.0),
                            1.092548431 * y * z * (PI / 4.0), 0.315391565 * (3.0 * z * z - 1.0) * (PI / 4.0),
                            1.092548431 * x * z * (PI / 4.0), 0.546274215 * (x * x - y * y) * (PI / 4.0));
  vec3 e = vec3(0.0);
  for (int i = 0; i < 9; ++i) e += basis[i] * vec3(c[3 * i], c[3 * i + 1], c[3 * i + 2]);
  return max(e, vec3(0.0));
}

float lobeScale(vec4 fit, float roughness) {
  float a = roughness * roughness;
  return (1.0 + fit.x * a + fit.y * a * a) / (1.0 + fit.z * a + fit.w * a * a);
}

// Split-sum glossy: Σ_l g_l(roughness) Σ_m c_lm Y_lm(R) times (F0·A + B) (glossy_sh.h).
vec3 probeGlossy(float c[28], vec3 r, float roughness, float nv, vec3 f0) {
  float g1 = lobeScale(pc.lobeBand1, roughness), g2 = lobeScale(pc.lobeBand2, roughness);
  float x = r.x, y = r.y, z = r.z;
  float basis[9] = float[9](0.282094792, 0.488602512 * y * g1, 0.488602512 * z * g1, 0.488602512 * x * g1,
                            1.092548431 * x * y * g2, 1.092548431 * y * z * g2, 0.315391565 * (3.0 * z * z - 1.0) * g2,
                            1.092548431 * x * z * g2, 0.546274215 * (x * x - y * y) * g2);
  vec3 prefiltered = vec3(0.0);
  for (int i = 0; i < 9; ++i) prefiltered += basis[i] * vec3(c[3 * i], c[3 * i + 1], c[3 * i + 2]);
  vec2 ab = texture(envBrdf, vec2(nv, roughness)).xy;
  return max(prefiltered, vec3(0.0)) * (f0 * ab.x + ab.y);
}

void main() {
  // Texture footprints from the screen derivatives, taken before any discard (material.glsl).
  materialUvDx = dFdx(texcoord);
  materialUvDy = dFdy(texcoord);
  vec3 positionDx = dFdx(worldPosition), positionDy = dFdy(worldPosition);
  materialMaxAnisotropy = float(pc.maxAnisotropy);
  vec3 wo = normalize(views[pc.viewBase + gl_ViewIndex].eye.xyz - worldPosition);
  // The geometric normal from the position's screen derivatives (before any discard), on the
  // viewer's side; the shading normal then follows the rule of material.glsl, as in the tracers.
  vec3 ng = cross(positionDx, positionDy);
  float ngLen = length(ng);
  vec3 ngf = ngLen > 1e-20 ? ng / ngLen : wo;
  if (dot(ngf, wo) < 0.0) ngf = -ngf;
  PtMaterial m = materials[triangleMaterial[pc.primitiveBase + uint(gl_PrimitiveID)]];
  vec4 baseAlpha = materialBase(m, texcoord);
  if (materialCutAway(m, baseAlpha.a)) discard;
  vec3 base = baseAlpha.rgb;
  float tau = pc.pass == RS_PASS_OPAQUE ? 0.0 : materialTransmission(m, baseAlpha.a);
  if (pc.pass == RS_PASS_TRANSMIT) {
    outColor = vec4(tau * base, 1.0);
    return;
  }
  vec2 metalRough = materialMetallicRoughness(m, texcoord);
  float metallic = metalRough.x, roughness = metalRough.y;
  float alpha = max(roughness * roughness, 1e-3);
  vec3 emission = materialEmission(m, texcoord);
  vec3 n = shadingNormal(materialNormal(m, texcoord, worldNormal, positionDx, positionDy, materialUvDx, materialUvDy),
                         ngf, wo);
  vec3 direct = vec3(0.0);
  for (uint i = 0u; i < pc.lightCount; ++i) {
    PtLight l = lights[i];
    uint type = uint(l.positionType.w);
    vec3 wi;
    vec3 e = l.colorIntensity.rgb * l.colorIntensity.a;
    if (type == PT_LIGHT_DIRECTIONAL) {
      wi = -l.directionRange.xyz;
    } else {
      vec3 toLight = l.positionType.xyz - worldPosition;
      float d2 = max(dot(toLight, toLight), 1e-8);
      float dist = sqrt(d2);
      wi = toLight / dist;
      e /= d2;
      float range = l.directionRange.w;
      if (range > 0.0) e *= pow(clamp(1.0 - pow(dist / range, 4.0), 0.0, 1.0), 2.0);
      if (type == PT_LIGHT_SPOT) e *= smoothstep(l.cone.x, l.cone.y, dot(-wi, l.directionRange.xyz));
    }
    float cosine = dot(n, wi);
    if (cosine > 0.0 && dot(ngf, wi) > 0.0) direct += evalBsdf(n, wo, wi, base, metallic, alpha) * cosine * e * shadowVisibility(i, worldPosition, n);
  }
  direct += areaLightsDirect(worldPosition, n, ngf, wo, base, metallic, alpha, roughness);
  float c[28];
  vec3 indirect = vec3(0.0);
  if (pc.visibility != 0u ? probeCoefficientsVisible(worldPosition, ngf, wo, c) : probeCoefficients(worldPosition, c)) {
    if (pc.volumeDims.w != 0.0) hallucinateZh3(c);
    vec3 f0 = mix(vec3(0.04), base, metallic);
    indirect = materialOcclusion(m, texcoord) *
               (base * (1.0 - metallic) / PI * probeIrradiance(c, n) +
                probeGlossy(c, reflect(-wo, n), roughness, clamp(dot(n, wo), 0.0, 1.0), f0));
  }
  outColor = vec4(emission + (1.0 - tau) * (direct + indirect), 1.0);
}
