// Geometry of client area lights, in the subset of GLSL that is also C++ with glm, so the raster
// shader, the browser page (which includes it as text) and the tests run the same code: the
// cosine-weighted solid angle of a triangle (exact: the triangle is clipped to the receiver's
// horizon, then the edge integral of Lambert's formula), its solid angle, the representative point
// for the GGX term, and a triangle's light by both.
#ifndef PROBECAST_AREA_LIGHT_MATH_H
#define PROBECAST_AREA_LIGHT_MATH_H

#ifdef __cplusplus
#include <glm/glm.hpp>

#include "bsdf.h"
namespace probecast::arealight {
using namespace glm;
using probecast::bsdf::evalBsdf;
#define AL_FN inline
#else
#include "bsdf.h"
#define AL_FN
#endif

// The edge term of Lambert's formula for an edge from a to b (directions from the receiver, any
// length): the angle between them times the receiver normal's component along the normal of their
// great circle. atan2 of |a × b| and a · b keeps it accurate for short and for wide edges.
AL_FN float edgeIntegral(vec3 a, vec3 b, vec3 n) {
  vec3 c = cross(a, b);
  float s = length(c);
  float angle = atan(s, dot(a, b));
  return s > 1e-20f ? angle * dot(c, n) / s : 0.0f;
}

// ∫ cos θ dω over the triangle (a, b, c) seen from p with unit normal n: the irradiance a unit
// radiance emitter gives p (π × the form factor). Only the triangle's front face emits (normal
// (b − a) × (c − a)); p behind its plane or the triangle below p's horizon gives 0.
AL_FN float triangleCosineSolidAngle(vec3 p, vec3 n, vec3 a, vec3 b, vec3 c) {
  vec3 v[3];
  v[0] = a - p;
  v[1] = b - p;
  v[2] = c - p;
  if (dot(cross(b - a, c - a), v[0]) >= 0.0f) return 0.0f;  // p on the back side (or in the plane)
  // Clip against the horizon plane dot(x, n) = 0 (Sutherland-Hodgman: at most 4 corners).
  vec3 q[4];
  int count = 0;
  for (int i = 0; i < 3; ++i) {
    vec3 cur = v[i], nxt = v[(i + 1) % 3];
    float hc = dot(cur, n), hn = dot(nxt, n);
    if (hc >= 0.0f) {
      q[count] = cur;
      count += 1;
    }
    if ((hc >= 0.0f) != (hn >= 0.0f)) {
      q[count] = cur + (nxt - cur) * (hc / (hc - hn));
      count += 1;
    }
  }
  if (count < 3) return 0.0f;
  float sum = 0.0f;
  for (int i = 0; i < count; ++i) sum += edgeIntegral(q[i], q[(i + 1) % count], n);
  return 0.5f * abs(sum);
}

// Solid angle of triangle (a, b, c) seen from p (Van Oosterom and Strackee's formula).
AL_FN float triangleSolidAngle(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 x = a - p, y = b - p, z = c - p;
  float lx = length(x), ly = length(y), lz = length(z);
  float num = abs(dot(x, cross(y, z)));
  float den = lx * ly * lz + dot(x, y) * lz + dot(x, z) * ly + dot(y, z) * lx;
  return 2.0f * atan(num, den);
}

// The closest point to q of segment (a, b).
AL_FN vec3 closestOnSegment(vec3 q, vec3 a, vec3 b) {
  vec3 e = b - a;
  float ee = dot(e, e);
  float t = ee > 0.0f ? clamp(dot(q - a, e) / ee, 0.0f, 1.0f) : 0.0f;
  return a + e * t;
}

// The closest point to q of triangle (a, b, c): q's projection when it falls inside, else the
// nearest of the three edges' closest points.
AL_FN vec3 closestOnTriangle(vec3 q, vec3 a, vec3 b, vec3 c) {
  vec3 cr = cross(b - a, c - a);
  float cc = dot(cr, cr);
  if (cc > 0.0f) {
    vec3 proj = q - cr * (dot(q - a, cr) / cc);
    float wa = dot(cross(c - b, proj - b), cr), wb = dot(cross(a - c, proj - c), cr),
          wc = dot(cross(b - a, proj - a), cr);
    if (wa >= 0.0f && wb >= 0.0f && wc >= 0.0f) return proj;
  }
  vec3 best = closestOnSegment(q, a, b);
  vec3 other = closestOnSegment(q, b, c);
  if (dot(other - q, other - q) < dot(best - q, best - q)) best = other;
  other = closestOnSegment(q, c, a);
  if (dot(other - q, other - q) < dot(best - q, best - q)) best = other;
  return best;
}

// The representative point of triangle (a, b, c) for a glossy lobe around the unit mirror
// direction r at p: where r meets the triangle's plane, clamped into the triangle; when r runs
// parallel to or away from the plane, the point of the plane under p + r · reach instead.
AL_FN vec3 representativePoint(vec3 p, vec3 r, vec3 a, vec3 b, vec3 c) {
  vec3 nl = cross(b - a, c - a);
  float along = dot(r, nl);
  float height = dot(a - p, nl);
  vec3 q;
  if (along * height > 0.0f && abs(along) > 1e-20f) {
    q = p + r * (height / along);
  } else {
    float reach = length(a - p) + length(b - a) + length(c - a);
    vec3 far = p + r * reach;
    float nn = dot(nl, nl);
    q = nn > 0.0f ? far - nl * (dot(far - a, nl) / nn) : a;
  }
  return closestOnTriangle(q, a, b, c);
}

// Light of a unit-radiance triangle (a, b, c) reflected toward wo at p (unit shading normal n,
// geometric normal ngf on the viewer's side, r: wo's mirror direction about n). w: the
// cosine-weighted solid angle (the diffuse term's irradiance); xyz: the GGX term, the BSDF at the
// representative point × the triangle's solid angle, with the lobe widened by the light's angular
// radius and renormalised by (α/α')², so a sharp lobe under a large light reflects at most what
// it holds.
AL_FN vec4 triangleLight(vec3 p, vec3 n, vec3 ngf, vec3 wo, vec3 r, vec3 a, vec3 b, vec3 c, vec3 base, float metallic,
                         float alpha) {
  const float pi = 3.14159265358979f;
  float e = triangleCosineSolidAngle(p, n, a, b, c);
  if (e <= 0.0f) return vec4(0.0f);
  vec3 q = representativePoint(p, r, a, b, c);
  vec3 toQ = q - p;
  float dq = length(toQ);
  if (dq <= 1e-6f) return vec4(vec3(0.0f), e);
  vec3 wi = toQ / dq;
  float nl = dot(n, wi);
  if (nl <= 0.0f || dot(ngf, wi) <= 0.0f) return vec4(vec3(0.0f), e);
  float omega = triangleSolidAngle(p, a, b, c);
  float widened = min(1.0f, alpha + 0.5f * sqrt(omega / pi));
  vec3 f = evalBsdf(n, wo, wi, base, metallic, alpha) - base * (1.0f - metallic) / pi;
  return vec4(max(f, vec3(0.0f)) * nl * omega * (alpha * alpha) / (widened * widened), e);
}

#ifdef __cplusplus
}  // namespace probecast::arealight
#endif
#undef AL_FN

#endif
