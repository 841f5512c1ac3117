// Materials as every renderer reads them: textures (mip-mapped, bilinear, repeat, sRGB colour
// decoded before filtering, linear alpha) through KHR_texture_transform, coverage and transmission (the rule in
// scene.h: Material::transmissive), the BSDF, and the shading-normal rule. The includer declares
// materials[], textures[] and texels[] (probe_trace_shared.h layouts).
const float PI = 3.14159265358979;

vec3 srgbToLinear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

// The change of TEXCOORD_0 (xy) and TEXCOORD_1 (zw) from one pixel to the next along x and y: the
// raster client sets them from screen derivatives, so textures are read over the pixel's
// footprint (trilinear mip levels, up to materialMaxAnisotropy taps along its long axis). The
// tracers leave them 0 and read the finest level, as a path tracer averages the footprint by
// sampling it.
vec4 materialUvDx = vec4(0.0), materialUvDy = vec4(0.0);
float materialMaxAnisotropy = 1.0;

// `srgb`: colour decoded from sRGB (base colour, emission); false: the stored values (data textures).
vec4 texel(uint offset, uint width, uint height, int x, int y, bool srgb) {
  x = ((x % int(width)) + int(width)) % int(width);  // repeat
  y = ((y % int(height)) + int(height)) % int(height);
  uint v = texels[offset + uint(y) * width + uint(x)];
  vec4 c = vec4(float(v & 255u), float((v >> 8) & 255u), float((v >> 16) & 255u), float(v >> 24)) / 255.0;
  return srgb ? vec4(srgbToLinear(c.rgb), c.a) : c;
}

// Bilinear within one mip level, repeat.
vec4 sampleLevel(PtTexture t, uint level, vec2 uv, bool srgb) {
  uint offset = t.offset, w = t.width, h = t.height;
  for (uint k = 0u; k < level; ++k) {
    offset += w * h;
    w = max(w / 2u, 1u);
    h = max(h / 2u, 1u);
  }
  vec2 p = uv * vec2(w, h) - 0.5;
  ivec2 i = ivec2(floor(p));
  vec2 f = p - vec2(i);
  return mix(mix(texel(offset, w, h, i.x, i.y, srgb), texel(offset, w, h, i.x + 1, i.y, srgb), f.x),
             mix(texel(offset, w, h, i.x, i.y + 1, srgb), texel(offset, w, h, i.x + 1, i.y + 1, srgb), f.x), f.y);
}

// Between the two levels around `lod` (0 = the finest).
vec4 sampleTrilinear(PtTexture t, float lod, vec2 uv, bool srgb) {
  lod = clamp(lod, 0.0, float(max(t.levels, 1u) - 1u));
  uint l0 = uint(floor(lod));
  float f = lod - float(l0);
  vec4 a = sampleLevel(t, l0, uv, srgb);
  return f > 0.0 ? mix(a, sampleLevel(t, l0 + 1u, uv, srgb), f) : a;
}

// The texture over the parallelogram (dx, dy) around uv; 1 without a texture. A footprint under a
// texel reads the finest level bilinearly; a larger one takes up to materialMaxAnisotropy
// trilinear taps spread along its long axis, at the level where each tap covers its share.
vec4 sampleTextureGrad(int index, vec2 uv, vec2 dx, vec2 dy, bool srgb) {
  if (index < 0) return vec4(1.0);
  PtTexture t = textures[index];
  vec2 size = vec2(t.width, t.height);
  float lx = length(dx * size), ly = length(dy * size);
  float major = max(lx, ly), minor = min(lx, ly);
  if (!(major > 1.0) || t.levels <= 1u) return sampleLevel(t, 0u, uv, srgb);
  float taps = clamp(ceil(major / max(minor, 1e-6)), 1.0, max(materialMaxAnisotropy, 1.0));
  float lod = log2(major / taps);
  vec2 axis = lx >= ly ? dx : dy;
  vec4 sum = vec4(0.0);
  for (float i = 0.0; i < taps; i += 1.0) sum += sampleTrilinear(t, lod, uv + axis * ((i + 0.5) / taps - 0.5), srgb);
  return sum / taps;
}

// A material's texture through its KHR_texture_transform (rows row0, row1; row0.w picks
// TEXCOORD_1), over the pixel's footprint.
vec4 sampleMaterialTexture(int index, vec4 row0, vec4 row1, vec4 uvs, bool srgb) {
  vec3 uv = vec3(row0.w > 0.5 ? uvs.zw : uvs.xy, 1.0);
  vec2 dx = row0.w > 0.5 ? materialUvDx.zw : materialUvDx.xy, dy = row0.w > 0.5 ? materialUvDy.zw : materialUvDy.xy;
  return sampleTextureGrad(index, vec2(dot(row0.xyz, uv), dot(row1.xyz, uv)),
                           vec2(dot(row0.xy, dx), dot(row1.xy, dx)), vec2(dot(row0.xy, dy), dot(row1.xy, dy)), srgb);
}

// rgb base colour (factor × texture), a = coverage alpha (factor × texture alpha).
vec4 materialBase(PtMaterial m, vec4 uvs) {
  vec4 t = sampleMaterialTexture(m.textures.x, m.baseTransform0, m.baseTransform1, uvs, true);
  return vec4(m.baseColorMetallic.rgb * t.rgb, m.alpha.x * t.a);
}

vec3 materialEmission(PtMaterial m, vec4 uvs) {
  if (m.textures.y < 0) return m.emissionRoughness.rgb;
  return m.emissionRoughness.rgb * sampleMaterialTexture(m.textures.y, m.emissiveTransform0, m.emissiveTransform1, uvs, true).rgb;
}

// (metallic, roughness): the factors times the metallic-roughness texture's blue and green.
vec2 materialMetallicRoughness(PtMaterial m, vec4 uvs) {
  vec2 f = vec2(m.baseColorMetallic.a, m.emissionRoughness.a);
  if (m.dataTextures.x < 0) return f;
  vec4 t = sampleMaterialTexture(m.dataTextures.x, m.metallicRoughnessTransform0, m.metallicRoughnessTransform1, uvs, false);
  return clamp(f * t.bg, 0.0, 1.0);
}

// The share of indirect light that reaches the point (occlusion texture; 1 without one).
float materialOcclusion(PtMaterial m, vec4 uvs) {
  if (m.dataTextures.y < 0) return 1.0;
  float r = sampleMaterialTexture(m.dataTextures.y, m.occlusionTransform0, m.occlusionTransform1, uvs, false).r;
  return 1.0 + m.dataFactors.x * (r - 1.0);
}

// The normal texture applied to `n`, the interpolated normal (any length, its file's side; 0 when
// absent): the tangent frame is the triangle's, ∂p/∂u and ∂p/∂v solved from two position
// differences across it (e1, e2) and the texture coordinates' differences over them (d1, d2:
// TEXCOORD_0 in xy, TEXCOORD_1 in zw) through the texture's transform — a triangle's edges in the
// tracers, a pixel's screen derivatives in the raster client, the same frame. +X follows +u, +Y
// goes up the image (glTF's v runs down it), +Z along n. Returns n unchanged without a texture
// or a usable frame; the shading-normal rule comes after.
vec3 materialNormal(PtMaterial m, vec4 uvs, vec3 n, vec3 e1, vec3 e2, vec4 d1, vec4 d2) {
  float len = length(n);
  if (m.dataTextures.z < 0 || !(len > 1e-6)) return n;
  n /= len;
  vec4 r0 = m.normalTransform0, r1 = m.normalTransform1;
  vec2 a = r0.w > 0.5 ? d1.zw : d1.xy, b = r0.w > 0.5 ? d2.zw : d2.xy;
  a = vec2(dot(r0.xy, a), dot(r1.xy, a));
  b = vec2(dot(r0.xy, b), dot(r1.xy, b));
  float det = a.x * b.y - b.x * a.y;
  if (!(abs(det) > 1e-30)) return n;
  vec3 dpdu = (e1 * b.y - e2 * a.y) / det, dpdv = (e2 * a.x - e1 * b.x) / det;
  vec3 t = dpdu - n * dot(n, dpdu);
  if (!(dot(t, t) > 1e-30)) return n;
  t = normalize(t);
  vec3 up = -(dpdv - n * dot(n, dpdv) - t * dot(t, dpdv));
  if (!(dot(up, up) > 1e-30)) return n;
  up = normalize(up);
  vec3 c = sampleMaterialTexture(m.dataTextures.z, r0, r1, uvs, false).xyz * 2.0 - 1.0;
  c.xy *= m.dataFactors.y;
  vec3 p = t * c.x + up * c.y + n * c.z;
  float pl = length(p);
  return pl > 1e-6 ? p / pl : n;
}

// Mask: the point is not there (rays pass, raster discards).
bool materialCutAway(PtMaterial m, float coverage) {
  return m.textures.z == PT_ALPHA_MASK && coverage < m.alpha.y;
}

// τ: the fraction of light that passes straight through, tinted by the base colour.
float materialTransmission(PtMaterial m, float coverage) {
  float blend = m.textures.z == PT_ALPHA_BLEND ? 1.0 - clamp(coverage, 0.0, 1.0) : 0.0;
  return 1.0 - (1.0 - blend) * (1.0 - m.alpha.z);
}

// What a visibility ray keeps after crossing this surface point (0 where it is solid).
vec3 surfaceTransmittance(PtMaterial m, vec4 uvs) {
  vec4 base = materialBase(m, uvs);
  if (materialCutAway(m, base.a)) return vec3(1.0);
  return materialTransmission(m, base.a) * base.rgb;
}

#include "bsdf.h"  // evalBsdf

const float SHADING_NORMAL_MIN_COSINE = 0.01;

// The shading-normal rule of every renderer. `ns`: the interpolated normal (any length, 0 when
// absent), `ngf`: the unit geometric normal on the viewer's side, `wo`: unit, toward the viewer.
// The shading normal is taken on the viewer's side of the surface; where the view still falls
// below it (a normal bent away at a silhouette) it is bent toward the viewer, just enough that
// n·wo = SHADING_NORMAL_MIN_COSINE: shading stays continuous with the neighbouring points
// instead of jumping to the geometric normal.
vec3 shadingNormal(vec3 ns, vec3 ngf, vec3 wo) {
  float len = length(ns);
  if (!(len > 1e-6)) return ngf;
  vec3 n = ns / len;
  if (dot(n, ngf) < 0.0) n = -n;
  float c = dot(n, wo);
  if (c < SHADING_NORMAL_MIN_COSINE) {
    vec3 bent = n + wo * (SHADING_NORMAL_MIN_COSINE - c);  // bent · wo = the minimum, before normalising
    float bl = length(bent);
    n = bl > 1e-6 ? bent / bl : ngf;
  }
  return n;
}
