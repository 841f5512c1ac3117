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
#define RS_BINDING_VIEWS 7             // RsView[]: the views of the current view set
#define RS_BINDING_SHADOW_LIGHTS 8     // RsShadowLight[], one per light
#define RS_BINDING_SHADOW_LAYERS 9     // RsShadowLayer[], one per shadow-map layer
#define RS_BINDING_SHADOW_MAP 10       // sampler2DArrayShadow: depth of every shadow layer
#define RS_BINDING_SHADOW_TRANSMIT 11  // sampler2DArray: per shadow layer, rgb = transmittance of the
                                       // transmissive casters before the opaque depth, a = the nearest one's depth
#define RS_TRANSMIT_CLEAR_DEPTH 65504.0  // a of a texel no transmissive caster covers (largest half float)
#define RS_BINDING_PROBE_POSITIONS 12  // vec4[] per probe: xyz where it was traced (grid + offset), metres
#define RS_BINDING_PROBE_MOMENTS 13    // sampler2D RG32F atlas of per-probe distance moments (below)

// Probe visibility (probe_visibility.h): per probe an RS_VIS_OCT² octahedral map of (E[r], E[r²]),
// r the distance from the probe to the nearest surface, with a one-texel border so that bilinear
// filtering never reads a neighbour's tile; tiles laid out RS_VIS_TILES_PER_ROW to a row.
#define RS_VIS_OCT 16
#define RS_VIS_TILE (RS_VIS_OCT + 2)
#define RS_VIS_TILES_PER_ROW 256

#define RS_BINDING_AREA_LIGHTS 14       // RsAreaLight[]: client area lights (scene/area_lights.h)
#define RS_BINDING_AREA_CORNERS 15      // vec4[]: 3 corners per area-light triangle, xyz world
#define RS_BINDING_AREA_SHADOW_LAYERS 16 // RsShadowLayer[], one per area-light shadow layer
#define RS_BINDING_AREA_SHADOW_MAP 17   // sampler2DArrayShadow: depth from every area light
#define RS_BINDING_AREA_SHADOW_DEPTH 18 // sampler2DArray: the same depths, raw (PCSS blocker search)
#define RS_BINDING_COUNT 19

#define RS_AREA_UNSHADOWED 0xffffffffu // RsAreaLight.shadowLayer: no layer left for it

#define RS_PASS_OPAQUE 0u              // opaque and cut-out triangles, depth written
#define RS_PASS_TRANSMIT 1u            // transmissive triangles: colour × T (blend: dst · src)
#define RS_PASS_REFLECT 2u             // transmissive triangles: + emission + (1 − τ) · lighting

#define RS_SHADOW_NONE 0u              // unshadowed (no layer left for it)
#define RS_SHADOW_CUBE 1u              // point light: six 90° faces +x −x +y −y +z −z
#define RS_SHADOW_PERSPECTIVE 2u       // spot light: one perspective layer
#define RS_SHADOW_ORTHO 3u             // directional light: 1..RS_MAX_CASCADES orthographic cascades
#define RS_MAX_CASCADES 4u

#ifdef __cplusplus
namespace probecast::shaders {
#endif

struct RsView {
  mat4 viewProj;       // world → Vulkan clip (y down, z in [0, 1])
  vec4 eye;            // xyz eye position, metres
};

struct RsShadowLight {
  uint kind;           // RS_SHADOW_*
  uint firstLayer;     // its first layer in the shadow map
  float texelScale;    // world size of one texel: × distance to the light (perspective); ortho: per layer
  uint cascades;       // layers of a directional light, finest first (1 for the other kinds)
};

struct RsShadowLayer {
  mat4 viewProj;       // world → the layer's clip space (same conventions as a view)
  vec4 texel;          // x: world size of one texel of an orthographic layer (0 for the others);
                       // y: 1 for a perspective layer (point, spot), 0 for an orthographic one
};

struct RsPushConstants {
  vec4 volumeMin;      // xyz position of probe (0,0,0); w = 1 if a probe volume is bound
  vec4 volumeMax;      // xyz position of the last probe; w = smallest probe spacing (metres), for biases
  vec4 volumeDims;     // xyz probes per axis (as floats); w = 1: zh3PerPixel (L1 only, hallucinate ZH3 per pixel)
  vec4 lobeBand1;      // GGX zonal lobe fit of band 1: p1, p2, q1, q2 (glossy_sh.h)
  vec4 lobeBand2;      // band 2
  uint lightCount;
  uint viewBase;       // index of this pass's first view in RsView[] (+ gl_ViewIndex)
  uint shadowMapSize;  // texels per side of each shadow layer
  uint primitiveBase;  // scene triangle index of the draw's first triangle (+ gl_PrimitiveID)
  uint pass;           // RS_PASS_*
  uint visibility;     // 1: interpolate 8 probes weighted by visibility; 0: hardware trilinear
  uint areaLightCount; // client area lights (RS_BINDING_AREA_LIGHTS)
  uint areaShadowMapSize;  // texels per side of each area-light shadow layer
  uint maxAnisotropy;  // texture taps along a pixel footprint's long axis (RasterOptions::anisotropy)
  uint pad0;
  uint pad1;
  uint pad2;
};

struct RsAreaLight {
  vec4 radiance;       // rgb emitted radiance (constant over the light)
  vec4 centroidSize;   // xyz centroid (its shadow map's eye), w = light size √area (PCSS)
  vec4 axisTanHalf;    // xyz unit axis of its shadow map (the light's normal), w = tan(fov / 2)
  uint firstCorner;    // in RS_BINDING_AREA_CORNERS
  uint triangleCount;
  uint shadowLayer;    // layer of the area shadow map, RS_AREA_UNSHADOWED when none
  uint pad;
  float znear;         // the shadow layer's depth range along the axis
  float zfar;
  float pad1;
  float pad2;
};

// Shadow-map passes: one layer's view-projection, and the draw's first triangle.
struct RsShadowPush {
  mat4 viewProj;
  uint primitiveBase;
  uint perspective;    // 1: a perspective layer (transmit depth in metres along the view), 0: ndc z
  uint pad1;
  uint pad2;
};

#ifdef __cplusplus
static_assert(sizeof(RsPushConstants) == 128);  // the least maxPushConstantsSize Vulkan allows
static_assert(sizeof(RsShadowPush) == 80);
static_assert(sizeof(RsView) == 80);
static_assert(sizeof(RsShadowLight) == 16);
static_assert(sizeof(RsShadowLayer) == 80);
static_assert(sizeof(RsAreaLight) == 80);
}  // namespace probecast::shaders
#endif

#endif
