// The path loop shared by the probe tracer and the reference camera: emission, next-event
// estimation to punctual lights, to emissive triangles and to the environment (the last two by
// multiple importance sampling with the BSDF, power heuristic), Lambert + GGX sampling, Russian
// roulette, bounce limit, clamp. Misses return the environment (black when there is none).
// Nothing here divides by a quantity that can reach zero or takes pow/normalize of something that
// can leave its domain: a non-finite sample is a defect (the raygens still drop and count one).
// Cut-outs (alphaMode Mask) are holes to every ray (the any-hit shaders); transmissive surfaces
// (Blend, KHR_materials_transmission; the rule in scene.h) attenuate visibility rays by T = τ·base
// and let a path through with probability τ. The including raygen declares the bindings
// (scene_bindings.glsl) and defines PATH_LIGHT_COUNT, PATH_MAX_BOUNCES, PATH_INDIRECT_CLAMP,
// PATH_EMITTER_COUNT, PATH_EMITTER_POWER and PATH_SKIP_CLIENT_LIT.
#include "material.glsl"

layout(location = 0) rayPayloadEXT HitPayload hit;
layout(location = 1) rayPayloadEXT vec4 shadowRay;  // rgb transmittance so far, a = 1 when it got through

// Straight-through crossings of transmissive surfaces a path may make between two bounces.
const uint PATH_MAX_CROSSINGS = 16u;

// Rays traced by this invocation (for rays-per-second figures).
uint gClosestRays = 0u;
uint gShadowRays = 0u;
const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);

uint pcg(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

float rnd(inout uint s) {
  s = pcg(s);
  return float(s >> 8) * (1.0 / 16777216.0);
}

vec3 vertexPosition(uint i) { return vec3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]); }
vec3 vertexNormal(uint i) { return vec3(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]); }
vec4 vertexTexcoords(uint i) {
  return vec4(texcoords[4 * i], texcoords[4 * i + 1], texcoords[4 * i + 2], texcoords[4 * i + 3]);
}

// Offset of a ray origin from a surface point p, against self-intersection.
float rayOffset(vec3 p) { return 1e-4 * (1.0 + max(abs(p.x), max(abs(p.y), abs(p.z)))); }

void onb(vec3 n, out vec3 t, out vec3 b) {
  float s = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + n.z);
  float c = n.x * n.y * a;
  t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
  b = vec3(c, s + n.y * n.y * a, -n.y);
}

float pdfBsdf(vec3 n, vec3 wo, vec3 wi, float alpha, float specProb) {
  float nl = dot(n, wi);
  if (nl <= 0.0) return 0.0;
  vec3 hv = wo + wi;
  float hl = dot(hv, hv);
  if (hl < 1e-12) return (1.0 - specProb) * nl / PI;  // wi opposite wo: no half vector, no GGX sample
  vec3 h = hv * inversesqrt(hl);
  float nh = clamp(dot(n, h), 0.0, 1.0), vh = clamp(dot(wo, h), 1e-6, 1.0);
  float a2 = alpha * alpha;
  float dd = nh * nh * (a2 - 1.0) + 1.0;
  float d = a2 / (PI * dd * dd);
  return specProb * d * nh / (4.0 * vh) + (1.0 - specProb) * nl / PI;
}

// Samples the one-sample mixture of cosine-weighted diffuse and GGX half-vector lobes.
vec3 sampleBsdf(vec3 n, vec3 wo, float alpha, float specProb, inout uint rng) {
  vec3 t, b;
  onb(n, t, b);
  float u1 = rnd(rng), u2 = rnd(rng), u3 = rnd(rng);
  if (u1 < specProb) {
    float a2 = alpha * alpha;
    float cosT = sqrt((1.0 - u2) / (1.0 + (a2 - 1.0) * u2));
    float sinT = sqrt(max(0.0, 1.0 - cosT * cosT));
    float phi = 2.0 * PI * u3;
    vec3 h = normalize(t * (sinT * cos(phi)) + b * (sinT * sin(phi)) + n * cosT);
    return reflect(-wo, h);
  }
  float r = sqrt(u2), phi = 2.0 * PI * u3;
  return normalize(t * (r * cos(phi)) + b * (r * sin(phi)) + n * sqrt(max(0.0, 1.0 - u2)));
}

// What reaches `origin` from `origin + dir · tmax`: 0 behind anything solid, else the product of
// the transmittances of the transmissive surfaces crossed (1 through free space and cut-outs).
vec3 transmittance(vec3 origin, vec3 dir, float tmax) {
  shadowRay = vec4(1.0, 1.0, 1.0, 0.0);
  ++gShadowRays;
  traceRayEXT(tlas, gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsSkipClosestHitShaderEXT, 0xFF,
              PT_HIT_GROUP_SHADOW, 1, PT_MISS_SHADOW, origin, 0.0, dir, tmax, 1);
  return shadowRay.a > 0.0 ? shadowRay.rgb : vec3(0.0);
}

bool anyLight(vec3 c) { return max(c.r, max(c.g, c.b)) > 0.0; }

// Radiance of punctual lights arriving at p along wi, times the cosine, via a shadow ray.
vec3 directLight(vec3 p, vec3 n, vec3 ng, vec3 wo, vec3 base, float metallic, float alpha) {
  vec3 sum = vec3(0.0);
  for (uint i = 0u; i < PATH_LIGHT_COUNT; ++i) {
    PtLight l = lights[i];
    uint type = uint(l.positionType.w);
    vec3 wi;
    float dist;
    vec3 e = l.colorIntensity.rgb * l.colorIntensity.a;
    if (type == PT_LIGHT_DIRECTIONAL) {
      wi = -l.directionRange.xyz;
      dist = 1e30;
    } else {
      vec3 toLight = l.positionType.xyz - p;
      float d2 = max(dot(toLight, toLight), 1e-8);
      dist = sqrt(d2);
      wi = toLight / dist;
      e /= d2;
      float range = l.directionRange.w;
      if (range > 0.0) e *= pow(clamp(1.0 - pow(dist / range, 4.0), 0.0, 1.0), 2.0);
      if (type == PT_LIGHT_SPOT) e *= smoothstep(l.cone.x, l.cone.y, dot(-wi, l.directionRange.xyz));
    }
    float cosine = dot(n, wi);
    if (cosine <= 0.0 || dot(ng, wi) <= 0.0 || max(e.r, max(e.g, e.b)) <= 0.0) continue;
    vec3 origin = p + ng * rayOffset(p);
    vec3 t = transmittance(origin, wi, dist * (1.0 - 1e-4));
    if (anyLight(t)) sum += evalBsdf(n, wo, wi, base, metallic, alpha) * cosine * e * t;
  }
  return sum;
}

float luminance(vec3 c) { return dot(c, LUMA); }

// MIS weight of a sample drawn with pdf `a` against a second strategy of pdf `b` (power
// heuristic a² / (a² + b²)), written as a ratio: no overflow of the squares, no 0/0. a > 0.
float powerHeuristic(float a, float b) {
  float r = b / a;
  return 1.0 / (1.0 + r * r);
}

// The environment (renderer/environment.h): nearest texel of an equirect map, map direction =
// R_y(−rotation) · world direction, top row +Y, centre −Z, u = 0.75 toward +X.
vec3 envTexel(uint x, uint y) {
  uint i = 3u * (y * environment.width + x);
  return vec3(envData[i], envData[i + 1u], envData[i + 2u]);
}

vec3 environmentRadiance(vec3 w) {
  if (environment.mode == PT_ENV_NONE) return vec3(0.0);
  float c = environment.cosRotation, s = environment.sinRotation;
  vec3 m = vec3(c * w.x - s * w.z, w.y, s * w.x + c * w.z);
  float theta = acos(clamp(m.y, -1.0, 1.0));
  float phi = abs(m.x) + abs(m.z) > 0.0 ? atan(m.x, -m.z) : 0.0;  // atan(0, 0) is undefined
  float u = phi / (2.0 * PI) + 0.5, v = theta / PI;
  int x = clamp(int(u * float(environment.width)), 0, int(environment.width) - 1);
  int y = clamp(int(v * float(environment.height)), 0, int(environment.height) - 1);
  return envTexel(uint(x), uint(y));
}

// Solid-angle pdf with which environment sampling draws w (0 when it does not sample).
float environmentPdf(vec3 w) {
  if (environment.sampling == 0u) return 0.0;
  return luminance(environmentRadiance(w)) / environment.total;
}

// First index in CDF envData[offset, offset + count) whose inclusive value exceeds u ∈ [0, 1).
uint envSearch(uint offset, uint count, float u) {
  uint lo = 0u, hi = count - 1u;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (envData[offset + mid] <= u) lo = mid + 1u; else hi = mid;
  }
  return lo;
}

// Draws a world direction with probability ∝ luminance × solid angle: a row by the marginal CDF,
// a column by that row's conditional CDF, then uniform in solid angle within the texel (φ
// uniform, cos θ uniform over the band). Returns the texel's radiance; pdf = luminance / total.
vec3 sampleEnvironment(inout uint rng, out vec3 wi, out float pdf) {
  uint W = environment.width, H = environment.height;
  uint y = envSearch(environment.rowsOffset, H, rnd(rng));
  uint x = envSearch(environment.columnsOffset + y * W, W, rnd(rng));
  float cos0 = cos(PI * float(y) / float(H)), cos1 = cos(PI * float(y + 1u) / float(H));
  float cosT = mix(cos0, cos1, rnd(rng));
  float sinT = sqrt(max(0.0, 1.0 - cosT * cosT));
  float phi = 2.0 * PI * ((float(x) + rnd(rng)) / float(W) - 0.5);
  vec3 m = vec3(sinT * sin(phi), cosT, -sinT * cos(phi));
  float c = environment.cosRotation, s = environment.sinRotation;
  wi = vec3(c * m.x + s * m.z, m.y, -s * m.x + c * m.z);
  vec3 le = envTexel(x, y);
  pdf = luminance(le) / environment.total;
  return le;
}

// The environment's share through direction wi (radiance le, drawn with pdf `pdf`), times an MIS
// weight: 0 where wi is below either normal, blocked, or had no chance of being drawn.
vec3 environmentAlong(vec3 p, vec3 n, vec3 ng, vec3 wo, vec3 base, float metallic, float alpha, vec3 wi, vec3 le,
                      float pdf, float weight) {
  float cosSurface = dot(n, wi);
  if (!(pdf > 1e-8) || cosSurface <= 0.0 || dot(ng, wi) <= 0.0) return vec3(0.0);
  vec3 t = transmittance(p + ng * rayOffset(p), wi, 1e30);
  if (!anyLight(t)) return vec3(0.0);
  return evalBsdf(n, wo, wi, base, metallic, alpha) * cosSurface * le * t * (weight / pdf);
}

// One environment sample for next-event estimation, MIS-weighted against BSDF sampling.
vec3 environmentLight(vec3 p, vec3 n, vec3 ng, vec3 wo, vec3 base, float metallic, float alpha, float specProb,
                      inout uint rng) {
  if (environment.mode == PT_ENV_NONE || environment.sampling == 0u) return vec3(0.0);
  vec3 wi;
  float pdfLight;
  vec3 le = sampleEnvironment(rng, wi, pdfLight);
  return environmentAlong(p, n, ng, wo, base, metallic, alpha, wi, le, pdfLight,
                          powerHeuristic(pdfLight, pdfBsdf(n, wo, wi, alpha, specProb)));
}

// The environment at a path's last interaction, where no BSDF sample follows to find it on a
// miss, so one sample carries all of it (weight 1): drawn from the map, or with environment
// sampling off from the BSDF, with a visibility ray either way — as punctual lights are lit at
// every interaction, `--bounces 1` included.
vec3 environmentLightLast(vec3 p, vec3 n, vec3 ng, vec3 wo, vec3 base, float metallic, float alpha, float specProb,
                          inout uint rng) {
  if (environment.mode == PT_ENV_NONE) return vec3(0.0);
  vec3 wi;
  float pdf;
  vec3 le;
  if (environment.sampling != 0u) {
    le = sampleEnvironment(rng, wi, pdf);
  } else {
    wi = sampleBsdf(n, wo, alpha, specProb, rng);
    pdf = pdfBsdf(n, wo, wi, alpha, specProb);
    le = environmentRadiance(wi);
  }
  return environmentAlong(p, n, ng, wo, base, metallic, alpha, wi, le, pdf, 1.0);
}

// Solid-angle pdf with which emitter sampling picks a direction that reaches a point of triangle
// `tri` (emission `le`, area `area`) at distance `dist`, seen at cosine `cosLight` from its front.
float emitterPdf(vec3 le, float dist, float cosLight) {
  if (PATH_EMITTER_COUNT == 0u || cosLight <= 0.0) return 0.0;
  return luminance(le) / PATH_EMITTER_POWER * dist * dist / cosLight;  // (power/total) / area · d²/cos
}

// One emissive-triangle sample, chosen by power; MIS-weighted against BSDF sampling.
vec3 emitterLight(vec3 p, vec3 n, vec3 ng, vec3 wo, vec3 base, float metallic, float alpha, float specProb,
                  inout uint rng) {
  if (PATH_EMITTER_COUNT == 0u) return vec3(0.0);
  float u = rnd(rng) * PATH_EMITTER_POWER;
  uint lo = 0u, hi = PATH_EMITTER_COUNT - 1u;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (emitters[mid].cdf < u) lo = mid + 1u; else hi = mid;
  }
  uint tri = emitters[lo].triangle;
  vec3 p0 = vertexPosition(indices[3 * tri]), p1 = vertexPosition(indices[3 * tri + 1]),
       p2 = vertexPosition(indices[3 * tri + 2]);
  float su = sqrt(rnd(rng)), v = rnd(rng);
  vec3 x = p0 * (1.0 - su) + p1 * (su * (1.0 - v)) + p2 * (su * v);
  vec3 cr = cross(p1 - p0, p2 - p0);
  vec3 nl = normalize(cr);
  vec3 toLight = x - p;
  float dist = length(toLight);
  if (dist <= 1e-6) return vec3(0.0);
  vec3 wi = toLight / dist;
  float cosLight = dot(nl, -wi);
  float cosSurface = dot(n, wi);
  if (cosLight <= 0.0 || cosSurface <= 0.0 || dot(ng, wi) <= 0.0) return vec3(0.0);
  PtMaterial em = materials[triangleMaterial[tri]];
  vec3 leFactor = em.emissionRoughness.rgb;
  vec3 le = leFactor;
  if (em.textures.y >= 0) {
    uint i0 = indices[3 * tri], i1 = indices[3 * tri + 1], i2 = indices[3 * tri + 2];
    vec4 uvs = vertexTexcoords(i0) * (1.0 - su) + vertexTexcoords(i1) * (su * (1.0 - v)) + vertexTexcoords(i2) * (su * v);
    le = materialEmission(em, uvs);
  }
  float pdfLight = emitterPdf(leFactor, dist, cosLight);
  if (pdfLight <= 0.0) return vec3(0.0);
  vec3 origin = p + ng * rayOffset(p);
  vec3 t = transmittance(origin, wi, dist * (1.0 - 1e-3));
  if (!anyLight(t)) return vec3(0.0);
  float weight = powerHeuristic(pdfLight, pdfBsdf(n, wo, wi, alpha, specProb));
  return evalBsdf(n, wo, wi, base, metallic, alpha) * cosSurface * le * t * (weight / pdfLight);
}

vec3 clampIndirect(vec3 c, uint bounce) {
  if (bounce == 0u || PATH_INDIRECT_CLAMP <= 0.0) return c;
  float lum = dot(c, LUMA);
  return lum > PATH_INDIRECT_CLAMP ? c * (PATH_INDIRECT_CLAMP / lum) : c;
}

// What a probe holds (README): a probe ray that meets a client-lit emitter on its first segment
// (crossings of transmissive surfaces included) gets none of its emission; the viewer adds that
// light itself. Later segments, and next-event estimation toward it, keep it. The reference camera
// defines PATH_SKIP_CLIENT_LIT 0 and sees every emitter.
bool clientLitFirstHit(PtMaterial m) { return PATH_SKIP_CLIENT_LIT != 0 && m.textures.w != 0; }

vec3 tracePath(vec3 origin, vec3 dir, inout uint rng) {
  vec3 radiance = vec3(0.0), throughput = vec3(1.0);
  float lastBsdfPdf = 0.0;  // pdf of the BSDF sample that started this segment (0: not sampled)
  float segment = 0.0;      // distance from the segment's start to `origin` (crossings move it)
  uint crossings = 0u;
  for (uint bounce = 0u; bounce < PATH_MAX_BOUNCES; ++bounce) {
    traceRayEXT(tlas, gl_RayFlagsNoneEXT, 0xFF, PT_HIT_GROUP_CLOSEST, 1, PT_MISS_CLOSEST, origin, 0.0, dir, 1e30, 0);
    ++gClosestRays;
    if (hit.t < 0.0) {
      // The environment, weighted against environment sampling when a BSDF sample got here
      // (the first segment is no BSDF sample: a probe or camera sees the sky directly).
      if (environment.mode != PT_ENV_NONE) {
        float weight = lastBsdfPdf > 0.0 ? powerHeuristic(lastBsdfPdf, environmentPdf(dir)) : 1.0;
        radiance += clampIndirect(throughput * environmentRadiance(dir) * weight, bounce);
      }
      break;
    }
    uint tri = hit.primitive;
    vec3 p0 = vertexPosition(indices[3 * tri]), p1 = vertexPosition(indices[3 * tri + 1]),
         p2 = vertexPosition(indices[3 * tri + 2]);
    vec3 cr = cross(p1 - p0, p2 - p0);
    float crLen = length(cr);
    vec3 ng = crLen > 0.0 ? cr / crLen : -dir;  // a degenerate (sliver) triangle faces the ray
    PtMaterial m = materials[triangleMaterial[tri]];
    vec3 p = origin + dir * hit.t;
    uint i0 = indices[3 * tri], i1 = indices[3 * tri + 1], i2 = indices[3 * tri + 2];
    vec3 bary = vec3(1.0 - hit.barycentrics.x - hit.barycentrics.y, hit.barycentrics);
    vec4 uvs = vertexTexcoords(i0) * bary.x + vertexTexcoords(i1) * bary.y + vertexTexcoords(i2) * bary.z;
    vec3 leFactor = m.emissionRoughness.rgb;
    vec3 le = materialEmission(m, uvs);
    if (hit.backFace == 0u && anyLight(le) && !(bounce == 0u && clientLitFirstHit(m))) {
      // Emission found by BSDF sampling, weighted against emitter sampling (not on the first
      // segment: probe and camera rays are not BSDF samples).
      float weight = 1.0;
      if (lastBsdfPdf > 0.0) {
        float pdfLight = emitterPdf(leFactor, segment + hit.t, abs(dot(ng, dir)));
        weight = powerHeuristic(lastBsdfPdf, pdfLight);
      }
      radiance += clampIndirect(throughput * le * weight, bounce);
    }
    vec3 ngf = dot(ng, dir) < 0.0 ? ng : -ng;  // geometric normal facing the ray (two-sided)
    vec4 baseAlpha = materialBase(m, uvs);
    vec3 base = baseAlpha.rgb;
    float tau = materialTransmission(m, baseAlpha.a);
    if (tau > 0.0 && crossings < PATH_MAX_CROSSINGS && rnd(rng) < tau) {
      // Straight through (probability τ, weight T / τ = base); not a bounce: same direction, same
      // BSDF sample, so the MIS weights of whatever the segment reaches still hold.
      throughput *= base;
      ++crossings;
      --bounce;
      segment += hit.t;
      origin = p - ngf * rayOffset(p);
      continue;
    }
    // Reflection (probability 1 − τ, weight (1 − τ) / (1 − τ) = 1).
    segment = 0.0;
    vec3 ns = vertexNormal(i0) * bary.x + vertexNormal(i1) * bary.y + vertexNormal(i2) * bary.z;
    ns = materialNormal(m, uvs, ns, p1 - p0, p2 - p0, vertexTexcoords(i1) - vertexTexcoords(i0),
                        vertexTexcoords(i2) - vertexTexcoords(i0));
    vec3 n = shadingNormal(ns, ngf, -dir);
    vec3 wo = -dir;
    vec2 metalRough = materialMetallicRoughness(m, uvs);
    float metallic = metalRough.x;
    float alpha = max(metalRough.y * metalRough.y, 1e-3);
    float specProb = mix(0.2, 0.9, metallic);
    radiance += clampIndirect(throughput * directLight(p, n, ngf, wo, base, metallic, alpha), bounce);
    if (bounce + 1u >= PATH_MAX_BOUNCES) {
      radiance += clampIndirect(throughput * environmentLightLast(p, n, ngf, wo, base, metallic, alpha, specProb, rng), bounce);
      break;
    }
    radiance += clampIndirect(throughput * emitterLight(p, n, ngf, wo, base, metallic, alpha, specProb, rng), bounce);
    radiance += clampIndirect(throughput * environmentLight(p, n, ngf, wo, base, metallic, alpha, specProb, rng), bounce);
    vec3 wi = sampleBsdf(n, wo, alpha, specProb, rng);
    float pdf = pdfBsdf(n, wo, wi, alpha, specProb);
    if (pdf <= 1e-8) break;
    throughput *= evalBsdf(n, wo, wi, base, metallic, alpha) * dot(n, wi) / pdf;
    lastBsdfPdf = pdf;
    if (bounce >= 2u) {  // Russian roulette
      float q = clamp(max(throughput.r, max(throughput.g, throughput.b)), 0.05, 0.95);
      if (rnd(rng) > q) break;
      throughput /= q;
    }
    if (dot(wi, ngf) <= 0.0) break;  // a shading-normal sample that goes below the surface
    origin = p + ngf * rayOffset(p);
    dir = wi;
  }
  return radiance;
}

// A path sample the raygens may add: every component finite (they drop and count any other).
bool finiteRadiance(vec3 c) { return !any(isnan(c)) && !any(isinf(c)); }
