#version 460
// Shadow maps of cut-out triangles (alphaMode Mask): cut-away points cast no shadow. Transmissive
// triangles are drawn into the colour layer instead (shadow_transmit.frag).
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
  if (materialCutAway(m, materialBase(m, texcoord).a)) discard;
}
