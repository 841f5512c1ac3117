#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include "probe_trace_payload.glsl"

layout(location = 0) rayPayloadInEXT HitPayload hit;
hitAttributeEXT vec2 attribs;

void main() {
  hit.t = gl_HitTEXT;
  hit.primitive = uint(gl_InstanceCustomIndexEXT) + uint(gl_PrimitiveID);  // the scene's triangle index
  hit.barycentrics = attribs;
  hit.backFace = gl_HitKindEXT == gl_HitKindBackFacingTriangleEXT ? 1u : 0u;
}
