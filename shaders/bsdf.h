// The BSDF every renderer shades with, in the subset of GLSL that is also C++ with glm, so that the
// shaders, the browser page (which includes this file as text) and C++ code run the same code:
// Lambert + GGX (Cook-Torrance, Smith-Schlick G, Schlick F), metallic-roughness as glTF.
#ifndef PROBECAST_BSDF_H
#define PROBECAST_BSDF_H

#ifdef __cplusplus
#include <glm/glm.hpp>
namespace probecast::bsdf {
using namespace glm;
#define BSDF_FN inline
#else
#define BSDF_FN
#endif

// Reflected radiance per unit irradiance from wi toward wo (unit vectors) at a surface of unit
// normal n, base colour, metallic and GGX alpha (roughness squared); 0 where either lies below n.
BSDF_FN vec3 evalBsdf(vec3 n, vec3 wo, vec3 wi, vec3 base, float metallic, float alpha) {
  const float pi = 3.14159265358979f;
  float nl = dot(n, wi), nv = dot(n, wo);
  if (nl <= 0.0f || nv <= 0.0f) return vec3(0.0f);
  vec3 h = normalize(wo + wi);  // nonzero: wo and wi lie on the same side of n
  // Dot products of unit vectors can round past 1; pow() of the negative 1 − v·h that follows is
  // undefined (NaN on llvmpipe), so clamp both into [0, 1] and expand the powers as products.
  float nh = clamp(dot(n, h), 0.0f, 1.0f), vh = clamp(dot(wo, h), 0.0f, 1.0f);
  float a2 = alpha * alpha;
  float dd = nh * nh * (a2 - 1.0f) + 1.0f;
  float d = a2 / (pi * dd * dd);
  float k = alpha * 0.5f;
  float g = (nl / (nl * (1.0f - k) + k)) * (nv / (nv * (1.0f - k) + k));
  vec3 f0 = mix(vec3(0.04f), base, metallic);
  float x = 1.0f - vh, x2 = x * x;
  vec3 f = f0 + (vec3(1.0f) - f0) * (x2 * x2 * x);
  vec3 spec = d * g * f / max(4.0f * nl * nv, 1e-6f);
  vec3 diffuse = base * (1.0f - metallic) / pi;
  return diffuse + spec;
}

#ifdef __cplusplus
}  // namespace probecast::bsdf
#endif
#undef BSDF_FN

#endif
