#version 460
// Shadow maps, the colour layer of transmissive casters (the rule of scene.h, as the tracers'
// visibility rays apply it): drawn after the layer's opaque depth, depth-tested against it and not
// writing it, so only casters in front of the nearest opaque one count. The blend multiplies the
// rgb by T = τ·base (several panes: their product) and keeps the smallest a, the depth of the
// nearest pane, so raster.frag tints only receivers behind it. Depth as ndc z for orthographic
// layers and as metres along the view for perspective ones (half floats keep 11 bits of either).
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"

layout(location = 0) in vec4 texcoord;
layout(location = 0) out vec4 outTransmit;
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
  vec3 t = materialTransmission(m, baseAlpha.a) * baseAlpha.rgb;
  outTransmit = vec4(t, pc.perspective != 0u ? 1.0 / gl_FragCoord.w : gl_FragCoord.z);
}
