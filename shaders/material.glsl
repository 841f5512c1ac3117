// Materials as every renderer reads them: textures (bilinear, repeat, sRGB colour decoded before
// filtering, linear alpha) through KHR_texture_transform, coverage and transmission (the rule in
// scene.h: Material::transmissive), the BSDF, and the shading-normal rule. The includer declares
// materials[], textures[] and texels[] (probe_trace_shared.h layouts).
const float PI = 3.14159265358979;

vec3 srgbToLinear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

// `srgb`: colour decoded from sRGB (base colour, emission); false: the stored values (data textures).
vec4 texel(PtTexture t, int x, int y, bool srgb) {
  x = ((x % int(t.width)) + int(t.width)) % int(t.width);  // repeat
  y = ((y % int(t.height)) + int(t.height)) % int(t.height);
  uint v = texels[t.offset + uint(y) * t.width + uint(x)];
  vec4 c = vec4(float(v & 255u), float((v >> 8) & 255u), float((v >> 16) & 255u), float(v >> 24)) / 255.0;
  return srgb ? vec4(srgbToLinear(c.rgb), c.a) : c;
}

// Bilinear, repeat; 1 without a texture.
vec4 sampleTextureAs(int index, vec2 uv, bool srgb) {
  if (index < 0) return vec4(1.0);
  PtTexture t = textures[index];
  vec2 p = uv * vec2(t.width, t.height) - 0.5;
  ivec2 i = ivec2(floor(p));
  vec2 f = p - vec2(i);
  return mix(mix(texel(t, i.x, i.y, srgb), texel(t, i.x + 1, i.y, srgb), f.x),
             mix(texel(t, i.x, i.y + 1, srgb), texel(t, i.x + 1, i.y + 1, srgb), f.x), f.y);
}

vec4 sampleTexture(int index, vec2 uv) { return sampleTextureAs(index, uv, true); }

// `uvs`: TEXCOORD_0 in xy, TEXCOORD_1 in zw.
vec2 transformedUv(vec4 row0, vec4 row1, vec4 uvs) {
  vec3 uv = vec3(row0.w > 0.5 ? uvs.zw : uvs.xy, 1.0);
  return vec2(dot(row0.xyz, uv), dot(row1.xyz, uv));
}

// rgb base colour (factor × texture), a = coverage alpha (factor × texture alpha).
vec4 materialBase(PtMaterial m, vec4 uvs) {
  vec4 t = sampleTexture(m.textures.x, transformedUv(m.baseTransform0, m.baseTransform1, uvs));
  return vec4(m.baseColorMetallic.rgb * t.rgb, m.alpha.x * t.a);
}

vec3 materialEmission(PtMaterial m, vec4 uvs) {
  if (m.textures.y < 0) return m.emissionRoughness.rgb;
  vec2 uv = transformedUv(m.emissiveTransform0, m.emissiveTransform1, uvs);
  return m.emissionRoughness.rgb * sampleTexture(m.textures.y, uv).rgb;
}

// (metallic, roughness): the factors times the metallic-roughness texture's blue and green.
vec2 materialMetallicRoughness(PtMaterial m, vec4 uvs) {
  vec2 f = vec2(m.baseColorMetallic.a, m.emissionRoughness.a);
  if (m.dataTextures.x < 0) return f;
  vec2 uv = transformedUv(m.metallicRoughnessTransform0, m.metallicRoughnessTransform1, uvs);
  vec4 t = sampleTextureAs(m.dataTextures.x, uv, false);
  return clamp(f * t.bg, 0.0, 1.0);
}

// The share of indirect light that reaches the point (occlusion texture; 1 without one).
float materialOcclusion(PtMaterial m, vec4 uvs) {
  if (m.dataTextures.y < 0) return 1.0;
  vec2 uv = transformedUv(m.occlusionTransform0, m.occlusionTransform1, uvs);
  float r = sampleTextureAs(m.dataTextures.y, uv, false).r;
  return 1.0 + m.dataFactors.x * (r - 1.0);
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

// Lambert + GGX (Cook-Torrance, Smith-Schlick G, Schlick F), metallic-roughness as glTF.
vec3 evalBsdf(vec3 n, vec3 wo, vec3 wi, vec3 base, float metallic, float alpha) {
  float nl = dot(n, wi), nv = dot(n, wo);
  if (nl <= 0.0 || nv <= 0.0) return vec3(0.0);
  vec3 h = normalize(wo + wi);  // nonzero: wo and wi lie on the same side of n
  // Dot products of unit vectors can round past 1; pow() of the negative 1 − v·h that follows is
  // undefined (NaN on llvmpipe), so clamp both into [0, 1] and expand the powers as products.
  float nh = clamp(dot(n, h), 0.0, 1.0), vh = clamp(dot(wo, h), 0.0, 1.0);
  float a2 = alpha * alpha;
  float dd = nh * nh * (a2 - 1.0) + 1.0;
  float d = a2 / (PI * dd * dd);
  float k = alpha * 0.5;
  float g = (nl / (nl * (1.0 - k) + k)) * (nv / (nv * (1.0 - k) + k));
  vec3 f0 = mix(vec3(0.04), base, metallic);
  float x = 1.0 - vh, x2 = x * x;
  vec3 f = f0 + (1.0 - f0) * (x2 * x2 * x);
  vec3 spec = d * g * f / max(4.0 * nl * nv, 1e-6);
  vec3 diffuse = base * (1.0 - metallic) / PI;
  return diffuse + spec;
}

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
