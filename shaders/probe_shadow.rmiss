#version 460
#extension GL_EXT_ray_tracing : require

layout(location = 1) rayPayloadInEXT vec4 shadowRay;

void main() { shadowRay.a = 1.0; }
