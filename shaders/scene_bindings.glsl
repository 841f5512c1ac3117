// Scene bindings shared by every ray-tracing shader (numbers from probe_trace_shared.h).
layout(binding = PT_BINDING_TLAS) uniform accelerationStructureEXT tlas;
layout(std430, binding = PT_BINDING_POSITIONS) readonly buffer Positions { float positions[]; };
layout(std430, binding = PT_BINDING_INDICES) readonly buffer Indices { uint indices[]; };
layout(std430, binding = PT_BINDING_TRIANGLE_MATERIAL) readonly buffer TriangleMaterial { uint triangleMaterial[]; };
layout(std430, binding = PT_BINDING_MATERIALS) readonly buffer Materials { PtMaterial materials[]; };
layout(std430, binding = PT_BINDING_LIGHTS) readonly buffer Lights { PtLight lights[]; };
layout(std430, binding = PT_BINDING_EMITTERS) readonly buffer Emitters { PtEmitter emitters[]; };
layout(std430, binding = PT_BINDING_NORMALS) readonly buffer Normals { float normals[]; };
layout(std430, binding = PT_BINDING_TEXCOORDS) readonly buffer Texcoords { float texcoords[]; };
layout(std430, binding = PT_BINDING_TEXELS) readonly buffer Texels { uint texels[]; };
layout(std430, binding = PT_BINDING_TEXTURES) readonly buffer Textures { PtTexture textures[]; };
layout(std430, binding = PT_BINDING_ENVIRONMENT) readonly buffer EnvironmentHeader { PtEnvironment environment; };
layout(std430, binding = PT_BINDING_ENV_DATA) readonly buffer EnvironmentData { float envData[]; };
