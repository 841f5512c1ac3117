#version 460
// Shadow maps: world-space positions through one light layer's view-projection; texture
// coordinates for the cut-out pass (shadow.frag).
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTexcoord;
layout(location = 0) out vec4 texcoord;
layout(push_constant) uniform Push { RsShadowPush pc; };

void main() {
  texcoord = inTexcoord;
  gl_Position = pc.viewProj * vec4(inPosition, 1.0);
}
