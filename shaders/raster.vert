#version 460
// Raster client: world-space vertices (scenes are flattened at load) through one view-projection.
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inTexcoord;
layout(location = 0) out vec3 worldPosition;
layout(location = 1) out vec3 worldNormal;
layout(location = 2) out vec2 texcoord;
layout(push_constant) uniform Push { RsPushConstants pc; };

void main() {
  worldPosition = inPosition;
  worldNormal = inNormal;
  texcoord = inTexcoord;
  gl_Position = pc.viewProj * vec4(inPosition, 1.0);
}
