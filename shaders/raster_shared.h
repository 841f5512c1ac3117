// Bindings and push constants of the raster client, shared by C++ and GLSL.
#ifndef PROBECAST_RASTER_SHARED_H
#define PROBECAST_RASTER_SHARED_H

#include "probe_trace_shared.h"

#define RS_PROBE_TEXTURES 7            // 27 SH floats in 7 RGBA 3D textures (the last w unused)
#define RS_BINDING_TRIANGLE_MATERIAL 0
#define RS_BINDING_MATERIALS 1
#define RS_BINDING_LIGHTS 2
#define RS_BINDING_TEXELS 3
#define RS_BINDING_TEXTURES 4
#define RS_BINDING_PROBES 5            // sampler3D[RS_PROBE_TEXTURES], trilinear, clamp
#define RS_BINDING_ENV_BRDF 6          // sampler2D: (A, B) over (n·v, roughness), glossy_sh.h
#define RS_BINDING_COUNT 7

#ifdef __cplusplus
namespace probecast::shaders {
#endif

struct RsPushConstants {
  mat4 viewProj;       // world → Vulkan clip
  vec4 eye;            // xyz camera position
  vec4 volumeMin;      // xyz position of probe (0,0,0); w = 1 if a probe volume is bound
  vec4 volumeMax;      // xyz position of the last probe
  vec4 volumeDims;     // xyz probes per axis (as floats)
  vec4 lobeBand1;      // GGX zonal lobe fit of band 1: p1, p2, q1, q2 (glossy_sh.h)
  vec4 lobeBand2;      // band 2
  uint lightCount;
  uint pad0;
  uint pad1;
  uint pad2;
};

#ifdef __cplusplus
static_assert(sizeof(RsPushConstants) == 176);
}  // namespace probecast::shaders
#endif

#endif
