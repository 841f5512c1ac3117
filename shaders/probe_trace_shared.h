// Constants and layouts shared by the probe tracer's C++ and GLSL (one place for both).
#ifndef PROBECAST_PROBE_TRACE_SHARED_H
#define PROBECAST_PROBE_TRACE_SHARED_H

#define PT_LANES_PER_PROBE 32   // invocations per probe; each sums its samples into one partial SH
#define PT_PARTIAL_FLOATS 31    // 27 SH floats, back-face hits, closest-hit rays, shadow rays, dropped samples
#define PT_MAX_BOUNCES_LIMIT 16

#define PT_MODE_TRACE 0u        // full paths, projected to SH
#define PT_MODE_CLASSIFY 1u     // first segment only: count back-face hits
// Classify mode's use of a lane's 27 SH floats: distance then unit direction (4 floats each) of
// the nearest back face and of the nearest front face its rays hit.
#define PT_CLASSIFY_BACK 0
#define PT_CLASSIFY_FRONT 4
#define PT_CLASSIFY_FAR 1e30    // distance when no ray hit a face of that kind

#define PT_BINDING_TLAS 0
#define PT_BINDING_POSITIONS 1  // float[3 * vertices]
#define PT_BINDING_INDICES 2    // uint[3 * triangles]
#define PT_BINDING_TRIANGLE_MATERIAL 3
#define PT_BINDING_MATERIALS 4  // PtMaterial[]
#define PT_BINDING_LIGHTS 5     // PtLight[]
#define PT_BINDING_DIRECTIONS 6 // vec4[samples], unit directions in a coherent order
#define PT_BINDING_PROBES 7     // vec4[active probes]: world position, w = grid index (then perProbeSamples' section)
#define PT_BINDING_PARTIALS 8   // float[active probes * LANES * PARTIAL_FLOATS]
#define PT_BINDING_EMITTERS 9   // PtEmitter[]: emissive triangles for next-event estimation
#define PT_BINDING_NORMALS 10   // float[3 * vertices], shading normals
#define PT_BINDING_TEXCOORDS 11 // float[4 * vertices]: TEXCOORD_0 uv, TEXCOORD_1 uv
#define PT_BINDING_TEXELS 12    // uint[]: every texture's sRGB RGBA8 texels, packed
#define PT_BINDING_TEXTURES 13  // PtTexture[]
#define PT_BINDING_ENVIRONMENT 14 // PtEnvironment (one): how to read PT_BINDING_ENV_DATA
#define PT_BINDING_ENV_DATA 15  // float[]: radiance rgb per texel, then the row CDF, then the column CDFs
#define PT_BINDING_COUNT 16

#define PT_ENV_NONE 0u          // misses are black
#define PT_ENV_MAP 1u           // misses return the equirect map (environment.h's convention)

#define PT_ALPHA_OPAQUE 0       // PtMaterial.textures.z, as scene::AlphaMode
#define PT_ALPHA_MASK 1
#define PT_ALPHA_BLEND 2

// Hit groups (shader binding table records) of the two ray types.
#define PT_HIT_GROUP_CLOSEST 0u // paths: closest hit, any-hit drops cut-away points
#define PT_HIT_GROUP_SHADOW 1u  // visibility: any-hit multiplies the transmittance
#define PT_MISS_CLOSEST 0u
#define PT_MISS_SHADOW 1u

#define PT_LIGHT_POINT 0u
#define PT_LIGHT_SPOT 1u
#define PT_LIGHT_DIRECTIONAL 2u

#ifdef __cplusplus
#include <cstdint>
namespace probecast::shaders {
using uint = uint32_t;
struct vec4 {
  float x, y, z, w;
};
struct ivec4 {
  int32_t x, y, z, w;
};
struct mat4 {
  vec4 c[4];
};
#endif

// std430 layouts.
struct PtMaterial {
  vec4 baseColorMetallic;   // rgb base colour, a metallic
  vec4 emissionRoughness;   // rgb emitted radiance, a roughness
  ivec4 textures;           // x base colour texture, y emissive texture (-1 = none), z PT_ALPHA_*,
                            // w 1: a client area light (the probe tracer's first segment skips its emission)
  vec4 alpha;               // x alpha (baseColorFactor.a), y alpha cutoff (Mask), z transmission factor
  // KHR_texture_transform: uv' = (row0.xyz · (u, v, 1), row1.xyz · (u, v, 1)) of TEXCOORD_<row0.w>.
  vec4 baseTransform0;
  vec4 baseTransform1;
  vec4 emissiveTransform0;
  vec4 emissiveTransform1;
  ivec4 dataTextures;       // x metallic-roughness texture (B metallic, G roughness), y occlusion (R), z normal (RGB); -1 = none; read linearly
  vec4 dataFactors;         // x occlusion strength, y normal scale
  vec4 metallicRoughnessTransform0;
  vec4 metallicRoughnessTransform1;
  vec4 occlusionTransform0;
  vec4 occlusionTransform1;
  vec4 normalTransform0;
  vec4 normalTransform1;
};

struct PtTexture {
  uint offset;              // first texel in PT_BINDING_TEXELS
  uint width;
  uint height;
  uint levels;              // mip levels, each after the one before, halving each side (texture_mips.h)
};

struct PtLight {
  vec4 positionType;        // xyz position, w type (as float)
  vec4 directionRange;      // xyz direction the light travels, w range (0 = none)
  vec4 colorIntensity;      // rgb colour, a intensity (cd or lx)
  vec4 cone;                // x cos(outer), y cos(inner)
};

struct PtEmitter {
  uint triangle;            // index into the index buffer / 3
  float cdf;                // inclusive CDF of power (luminance of emission × area)
  float power;              // luminance of emission × area
  float pad;
};

// The environment (renderer/environment.h): a width × height equirect map rotated about +Y; a
// uniform sky is a 1 × 1 map. The pdf of a direction drawn by importance sampling is
// luminance(texel) / total.
struct PtEnvironment {
  uint mode;                // PT_ENV_*
  uint width;
  uint height;
  uint sampling;            // 1: next-event estimation samples it (MIS with the BSDF); 0: BSDF sampling only
  float cosRotation;        // world = R_y(rotation) · map direction
  float sinRotation;
  float total;              // Σ luminance × solid angle over the texels
  uint rowsOffset;          // first float of the row CDF (height floats) in PT_BINDING_ENV_DATA
  uint columnsOffset;       // first float of the column CDFs (height × width floats)
  uint pad0;
  uint pad1;
  uint pad2;
};

struct PtPushConstants {
  mat4 rotation;            // random rotation of the sample set for this update
  uint sampleCount;         // samples per probe (multiple of LANES)
  uint probeCount;          // active probes in this dispatch
  uint lightCount;
  uint maxBounces;
  uint seed;
  uint updateIndex;
  uint mode;                // PT_MODE_*
  float indirectClamp;      // max luminance of one indirect contribution; 0 = off
  uint emitterCount;
  float emitterPower;       // sum of PtEmitter.power
  // 0: every probe traces sampleCount samples of the directions from 0. 1: a ray budget set them per
  // probe: PT_BINDING_PROBES holds a second section after the probeCount positions, per probe
  // x = its samples (multiple of LANES), y = the index of its first direction (as bits).
  uint perProbeSamples;
  uint pad1;
};

// The reference camera (reference_camera.rgen): a pinhole camera, one invocation per pixel,
// adding samplesPerPixel path samples per dispatch into an RGBA float accumulation buffer bound
// at PT_BINDING_PARTIALS.
struct PtCameraPushConstants {
  vec4 position;            // xyz camera position (metres)
  vec4 forward;             // xyz unit view direction, w = tan(yfov / 2)
  vec4 right;               // xyz unit, w = width / height
  vec4 up;                  // xyz unit
  uint width;
  uint height;
  uint samplesPerPixel;     // this dispatch
  uint seed;
  uint dispatchIndex;
  uint lightCount;
  uint maxBounces;
  float indirectClamp;
  uint emitterCount;
  float emitterPower;
  float shiftRight;         // off-axis frustum: centre of the image on the tangent plane (× right)
  float shiftUp;            // (× up); 0, 0 for a centred pinhole
};

#ifdef __cplusplus
static_assert(sizeof(PtCameraPushConstants) == 112);
static_assert(sizeof(PtEmitter) == 16);
static_assert(sizeof(PtMaterial) == 256);
static_assert(sizeof(PtTexture) == 16);
static_assert(sizeof(PtLight) == 64);
static_assert(sizeof(PtPushConstants) == 112);
static_assert(sizeof(PtEnvironment) == 48);
}  // namespace probecast::shaders
#endif

#endif
