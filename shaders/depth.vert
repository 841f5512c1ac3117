#version 460
// Depth only, for opaque geometry: positions through one view-projection and nothing else, so
// the rasteriser has no attribute to fetch or interpolate. The same transform as shadow.vert,
// so both write the same depths.
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"

layout(location = 0) in vec3 inPosition;
layout(push_constant) uniform Push { RsShadowPush pc; };

void main() { gl_Position = pc.viewProj * vec4(inPosition, 1.0); }
