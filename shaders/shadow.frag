#version 460
// Shadow maps of non-opaque triangles: cut-away points (alphaMode Mask) cast no shadow; a
// transmissive point blocks a fraction 1 − luminance(T) of the light, T = τ·base, by an ordered
// screen-door dither that the 3×3 PCF of raster.frag averages. Depth maps carry no colour, so
// shadows through coloured glass are grey here (the tracers tint them).
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"

layout(location = 0) in vec4 texcoord;
layout(push_constant) uniform Push { RsShadowPush pc; };
layout(std430, binding = RS_BINDING_TRIANGLE_MATERIAL) readonly buffer TriangleMaterial { uint triangleMaterial[]; };
layout(std430, binding = RS_BINDING_MATERIALS) readonly buffer Materials { PtMaterial materials[]; };
layout(std430, binding = RS_BINDING_TEXELS) readonly buffer Texels { uint texels[]; };
layout(std430, binding = RS_BINDING_TEXTURES) readonly buffer Textures { PtTexture textures[]; };
#include "material.glsl"

void main() {
  PtMaterial m = materials[triangleMaterial[pc.primitiveBase + uint(gl_PrimitiveID)]];
  vec4 baseAlpha = materialBase(m, texcoord);
  if (materialCutAway(m, baseAlpha.a)) discard;
  float passing = dot(materialTransmission(m, baseAlpha.a) * baseAlpha.rgb, vec3(0.2126, 0.7152, 0.0722));
  // A 4×4 Bayer threshold in (0, 1): the fraction of texels discarded equals `passing` to 1/16.
  const float bayer[16] = float[16](0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5);
  ivec2 q = ivec2(gl_FragCoord.xy) & 3;
  if ((bayer[q.y * 4 + q.x] + 0.5) / 16.0 < passing) discard;
}
