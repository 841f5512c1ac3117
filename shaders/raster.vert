#version 460
// Raster client: world-space vertices (scenes are flattened at load) through the view-projection
// of this pass's view; with multiview, gl_ViewIndex picks one of several views per pass.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_multiview : require
#include "raster_shared.h"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTexcoord;  // TEXCOORD_0, TEXCOORD_1
layout(location = 0) out vec3 worldPosition;
layout(location = 1) out vec3 worldNormal;
layout(location = 2) out vec4 texcoord;
layout(push_constant) uniform Push { RsPushConstants pc; };
layout(std430, binding = RS_BINDING_VIEWS) readonly buffer Views { RsView views[]; };

void main() {
  worldPosition = inPosition;
  worldNormal = inNormal;
  texcoord = inTexcoord;
  gl_Position = views[pc.viewBase + gl_ViewIndex].viewProj * vec4(inPosition, 1.0);
}
