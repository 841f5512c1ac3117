// Client area lights in the raster client (scene/area_lights.h chooses them): per pixel, the exact
// Lambertian irradiance of every triangle (area_light_math.h), a GGX term by a representative
// point with energy normalisation, and soft shadows from a shadow map drawn from the emitter
// (PCSS: a blocker search, then a PCF whose width grows with the light's size and the distance
// from blocker to receiver). The includer (raster.frag) declares the material bindings, envBrdf,
// pc and evalBsdf; this file declares the area-light bindings.
#include "area_light_math.h"

layout(std430, binding = RS_BINDING_AREA_LIGHTS) readonly buffer AreaLights { RsAreaLight areaLights[]; };
layout(std430, binding = RS_BINDING_AREA_CORNERS) readonly buffer AreaCorners { vec4 areaCorners[]; };
layout(std430, binding = RS_BINDING_AREA_SHADOW_LAYERS) readonly buffer AreaLayers { RsShadowLayer areaLayers[]; };
layout(binding = RS_BINDING_AREA_SHADOW_MAP) uniform sampler2DArrayShadow areaShadowMap;
layout(binding = RS_BINDING_AREA_SHADOW_DEPTH) uniform sampler2DArray areaShadowDepth;

const int AREA_SHADOW_TAPS = 5;  // per axis, for the blocker search and for the filter

// Distance along the light's axis of a depth-buffer value of its perspective layer.
float areaLinearDepth(RsAreaLight l, float d) { return l.znear * l.zfar / max(l.zfar - d * (l.zfar - l.znear), 1e-20); }

// The layer's (u, v, depth) of world point q; w ≤ 0 behind the light.
vec4 areaShadowCoord(uint layer, vec3 q) {
  vec4 clip = areaLayers[layer].viewProj * vec4(q, 1.0);
  if (clip.w <= 0.0) return vec4(0.0);
  vec3 ndc = clip.xyz / clip.w;
  return vec4(ndc.xy * 0.5 + 0.5, ndc.z, 1.0);
}

// Fraction of light `l` that reaches p (unit shading normal n, geometric normal ngf), 1 where its
// map does not reach. Every tap compares against the receiver's own plane at that tap (depth
// extrapolated along the plane from two nearby points of it), not against p's depth: wide
// filters on receivers seen obliquely by the light would otherwise shadow themselves.
float areaShadow(RsAreaLight l, vec3 p, vec3 n, vec3 ngf) {
  if (l.shadowLayer == RS_AREA_UNSHADOWED) return 1.0;
  vec3 axis = l.axisTanHalf.xyz;
  float tanHalf = l.axisTanHalf.w;
  float z = dot(p - l.centroidSize.xyz, axis);
  if (z <= l.znear) return 1.0;
  float texel = 2.0 * tanHalf * z / float(pc.areaShadowMapSize);  // world size of a texel at p
  vec3 q = p + n * (1.5 * texel);
  vec4 s0 = areaShadowCoord(l.shadowLayer, q);
  if (s0.w == 0.0 || any(greaterThan(abs(s0.xy * 2.0 - 1.0), vec2(1.0))) || s0.z > 1.0) return 1.0;
  // Depth gradient over the receiver's plane, per unit of (u, v).
  vec3 t1 = normalize(abs(ngf.y) < 0.9 ? cross(ngf, vec3(0.0, 1.0, 0.0)) : cross(ngf, vec3(1.0, 0.0, 0.0)));
  vec3 t2 = cross(ngf, t1);
  vec4 s1 = areaShadowCoord(l.shadowLayer, q + t1 * texel), s2 = areaShadowCoord(l.shadowLayer, q + t2 * texel);
  vec2 dzduv = vec2(0.0);
  vec3 a = s1.xyz - s0.xyz, b = s2.xyz - s0.xyz;
  float det = a.x * b.y - a.y * b.x;
  if (s1.w != 0.0 && s2.w != 0.0 && abs(det) > 1e-14)
    dzduv = vec2(b.y * a.z - a.y * b.z, a.x * b.z - b.x * a.z) / det;
  float layer = float(l.shadowLayer);
  float zr = areaLinearDepth(l, s0.z);
  float uvPerMetre = 1.0 / (2.0 * tanHalf * zr);
  float oneTexel = 1.0 / float(pc.areaShadowMapSize);
  float size = l.centroidSize.w;
  const float bias = 2e-4;  // in depth-buffer units, on top of the maps' slope-scaled bias
  // Blockers: whatever lies nearer than the receiver within the light's cone from p (sized here
  // for a blocker half-way, where the cone is half the light wide).
  float search = clamp(0.5 * size * uvPerMetre, 1.5 * oneTexel, 0.1);
  float blockers = 0.0, blockerDepth = 0.0;
  for (int y = 0; y < AREA_SHADOW_TAPS; ++y)
    for (int x = 0; x < AREA_SHADOW_TAPS; ++x) {
      vec2 o = (vec2(x, y) / float(AREA_SHADOW_TAPS - 1) * 2.0 - 1.0) * search;
      float d = texture(areaShadowDepth, vec3(s0.xy + o, layer)).r;
      if (d < s0.z + dot(dzduv, o) - bias) {
        blockers += 1.0;
        blockerDepth += areaLinearDepth(l, d);
      }
    }
  if (blockers == 0.0) return 1.0;
  blockerDepth /= blockers;
  // Penumbra width at the receiver by similar triangles, then a PCF over it.
  float penumbra = size * max(zr - blockerDepth, 0.0) / max(blockerDepth, 1e-6);
  float radius = clamp(0.5 * penumbra * uvPerMetre, oneTexel, 0.1);
  float lit = 0.0;
  for (int y = 0; y < AREA_SHADOW_TAPS; ++y)
    for (int x = 0; x < AREA_SHADOW_TAPS; ++x) {
      vec2 o = (vec2(x, y) / float(AREA_SHADOW_TAPS - 1) * 2.0 - 1.0) * radius;
      lit += texture(areaShadowMap, vec4(s0.xy + o, layer, s0.z + dot(dzduv, o) - bias));
    }
  return lit / float(AREA_SHADOW_TAPS * AREA_SHADOW_TAPS);
}

// Reflected radiance toward wo from every client area light at p (shading normal n, geometric
// normal ngf on the viewer's side), shadowed.
vec3 areaLightsDirect(vec3 p, vec3 n, vec3 ngf, vec3 wo, vec3 base, float metallic, float alpha, float roughness) {
  vec3 sum = vec3(0.0);
  if (pc.areaLightCount == 0u) return sum;  // the table lookup below is not free
  float nv = clamp(dot(n, wo), 0.0, 1.0);
  vec3 r = reflect(-wo, n);
  vec3 f0 = mix(vec3(0.04), base, metallic);
  vec2 ab = texture(envBrdf, vec2(nv, roughness)).xy;
  vec3 specAlbedo = f0 * ab.x + ab.y;  // the lobe's whole reflectance: a bound for any part of it
  for (uint i = 0u; i < pc.areaLightCount; ++i) {
    RsAreaLight l = areaLights[i];
    float irradiance = 0.0;
    vec3 specular = vec3(0.0);
    for (uint t = 0u; t < l.triangleCount; ++t) {
      uint k = l.firstCorner + 3u * t;
      vec4 tl = triangleLight(p, n, ngf, wo, r, areaCorners[k].xyz, areaCorners[k + 1u].xyz, areaCorners[k + 2u].xyz,
                              base, metallic, alpha);
      irradiance += tl.w;
      specular += tl.xyz;
    }
    if (irradiance <= 0.0) continue;
    float visible = areaShadow(l, p, n, ngf);
    vec3 diffuse = base * (1.0 - metallic) / PI * irradiance;
    sum += l.radiance.rgb * visible * (diffuse + min(specular, specAlbedo));
  }
  return sum;
}
