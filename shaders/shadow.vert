#version 460
// Shadow maps: depth only, world-space positions through one light layer's view-projection.
layout(location = 0) in vec3 inPosition;
layout(push_constant) uniform Push { mat4 viewProj; };

void main() { gl_Position = viewProj * vec4(inPosition, 1.0); }
