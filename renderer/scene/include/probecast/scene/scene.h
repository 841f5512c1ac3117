// Scenes in probecast's own types: world-space triangles, materials, punctual lights, cameras.
// Loaded from glTF 2.0 (tinygltf stays inside the loader) or generated in code (`builtin:NAME`).
//
// Units and conventions: metres, Y up (glTF), right-handed. Material emission is radiance
// (emissiveFactor × KHR_materials_emissive_strength). Point and spot intensity in candela
// (W/sr in our radiometric use), directional in lux (W/m²), as KHR_lights_punctual.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace probecast::scene {

// glTF alphaMode. Opaque ignores alpha; Mask keeps a surface point where alpha >= alphaCutoff and
// removes it elsewhere; Blend makes the surface a thin partial cover (see Material::transmittance).
enum class AlphaMode : uint32_t { Opaque = 0, Mask = 1, Blend = 2 };

// Where a texture is read: uv' = (row0 · (u, v, 1), row1 · (u, v, 1)) of TEXCOORD_<texCoord>, the
// 2×3 matrix of KHR_texture_transform (translation × rotation × scale); identity without it.
struct TextureTransform {
  glm::vec3 row0{1.0f, 0.0f, 0.0f};
  glm::vec3 row1{0.0f, 1.0f, 0.0f};
  uint32_t texCoord = 0;  // 0 or 1
  bool operator==(const TextureTransform&) const = default;
};

struct Material {
  std::string name;
  glm::vec3 baseColor{0.8f};
  float metallic = 0.0f;
  float roughness = 1.0f;
  glm::vec3 emission{0.0f};
  int32_t baseColorTexture = -1;  // index into Scene::textures, multiplies baseColor (and alpha)
  int32_t emissiveTexture = -1;   // index into Scene::textures, multiplies emission
  TextureTransform baseColorTransform;
  TextureTransform emissiveTransform;
  // Data textures, read linearly (no sRGB decoding): metallicRoughnessTexture's blue channel
  // multiplies `metallic` and its green `roughness` (every renderer); occlusionTexture's red is the
  // share of indirect light that reaches the point, 1 + occlusionStrength × (r − 1), which only
  // the raster client applies to its probe light (the tracers find occlusion by tracing).
  int32_t metallicRoughnessTexture = -1;
  int32_t occlusionTexture = -1;
  float occlusionStrength = 1.0f;
  TextureTransform metallicRoughnessTransform;
  TextureTransform occlusionTransform;
  // Tangent-space normal texture (linear; RGB = XYZ in [−1, 1], +X along +u, +Y up the image,
  // i.e. along −v, +Z out of the surface), its XY scaled by normalScale. Every renderer takes the
  // tangent frame of each triangle from its positions and texture coordinates (the file's
  // TANGENT attribute is not read).
  int32_t normalTexture = -1;
  float normalScale = 1.0f;
  TextureTransform normalTransform;
  // Coverage: a = alpha (baseColorFactor.a) × the base colour texture's alpha.
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alpha = 1.0f;
  float alphaCutoff = 0.5f;  // Mask only
  // KHR_materials_transmission's transmissionFactor t, as a thin surface (no refraction).
  float transmission = 0.0f;

  // The transmission rule, one for every renderer: a surface point lets a fraction
  //   τ = 1 − (1 − b)(1 − t),  b = 1 − a for Blend (else 0),
  // of the light that reaches it pass straight through, tinted by the base colour (T = τ · base,
  // coloured glass), and reflects with its BSDF scaled by 1 − τ; emission is added in full.
  bool transmissive() const { return alphaMode == AlphaMode::Blend || transmission > 0.0f; }
  // Rays must look at the material per hit (cut-outs or transmission).
  bool opaqueToRays() const { return alphaMode == AlphaMode::Opaque && !(transmission > 0.0f); }
  bool operator==(const Material&) const = default;
};

// An sRGB-encoded RGBA8 image (glTF base colour and emissive textures are sRGB; alpha is linear),
// sampled with repeat wrapping and bilinear filtering. 16-bit PNGs are rounded to 8 bits of their
// encoded (sRGB) values at load.
struct Texture {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> rgba;
  bool operator==(const Texture&) const = default;
};

enum class LightType : uint32_t { Point = 0, Spot = 1, Directional = 2 };

struct Light {
  LightType type = LightType::Point;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  // the way the light travels (spot, directional)
  glm::vec3 color{1.0f};
  float intensity = 1.0f;
  float range = 0.0f;  // 0 = unlimited
  float innerConeAngle = 0.0f;
  float outerConeAngle = 0.7853982f;
  bool operator==(const Light&) const = default;
};

struct Camera {
  std::string name;
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float yfov = 0.6911f;  // radians
  float aspect = 0.0f;   // 0 = the viewport's
  float znear = 0.01f;
  float zfar = 100.0f;
};

struct Rig;  // animation.h

struct Scene {
  std::string name;
  std::vector<glm::vec3> positions;  // world space
  std::vector<glm::vec3> normals;    // per vertex, unit length (shading normals)
  std::vector<glm::vec2> texcoords;  // per vertex, TEXCOORD_0 (0 when absent)
  std::vector<glm::vec2> texcoords1; // per vertex, TEXCOORD_1 (empty or 0 when absent)
  std::vector<uint32_t> indices;     // 3 per triangle
  std::vector<uint32_t> triangleMaterial;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Light> lights;
  std::vector<Camera> cameras;
  glm::vec3 boundsMin{0.0f};
  glm::vec3 boundsMax{0.0f};
  // What moves with the scene clock (glTF animation, skins, morph targets; animation.h), shared by
  // copies; null when nothing does. The bounds hold every pose of it.
  std::shared_ptr<const Rig> rig;

  uint32_t triangleCount() const { return static_cast<uint32_t>(indices.size() / 3); }
};

// Material class of a triangle in finalizeScene's order: 0 opaque to rays, 1 cut-out, 2 transmissive.
uint32_t triangleClass(const Scene& scene, uint32_t triangle);
// Per vertex / per triangle: 1 where it moves with the scene clock (a primitive of the rig of a
// scene that animates, animation.h), 0 elsewhere. finalizeScene puts the moving triangles of each
// class after the still ones, so each is one run.
std::vector<uint8_t> movingVertices(const Scene& scene);
std::vector<uint8_t> movingTriangles(const Scene& scene);
// Length of the leading run of triangles of class < `cls` (the whole scene when not finalized).
uint32_t leadingTrianglesBelowClass(const Scene& scene, uint32_t cls);

// The files a glTF from a scene package may read besides itself: the package's files, as paths
// relative to the glTF's folder ('/'-separated, no '.' or '..' parts). A package's folder holds
// nothing else a server could name, and nothing in it may be a symbolic link.
struct PackagedFiles {
  std::vector<std::string> listed;
};

// Loads a .gltf or .glb file posed at scene time `seconds` (animation.h). On failure returns false
// and `error` names the file and the problem. Buffers and images are read only from inside the
// glTF's own folder: a URI that is absolute, has a scheme other than data:, or climbs out with '..'
// (percent-encoded or not) is refused, and nothing is looked up in the working folder. With
// `packaged`, a URI must also name one of its files, reached without a symbolic link.
bool loadGltf(const std::string& path, Scene& scene, std::string& error, double seconds = 0.0,
              const PackagedFiles* packaged = nullptr);

// Built-in scenes, generated in code. `t` in [0, 1) is the animation parameter.
//   cornell     Cornell box (open front), ceiling panel + a point light circling under the ceiling
//   closed-box  a closed 2 m box lit by a point light, for inside/outside tests
//   hall        a closed 20 m hall with 4,600 blocks, ≈100k triangles, for performance figures
std::vector<std::string> builtinSceneNames();
bool makeBuiltinScene(const std::string& name, float t, Scene& scene, std::string& error);

// "builtin:NAME" or a glTF path, at scene time `seconds` (built-ins: t = seconds mod 1); a glTF
// from a scene package with `packaged` (loadGltf).
bool loadScene(const std::string& spec, double seconds, Scene& scene, std::string& error,
               const PackagedFiles* packaged = nullptr);

// Recomputes the bounds and reorders triangles by the Morton code of their centroids, so BVH
// builders that split at the index midpoint get spatially coherent halves. Triangles come in three
// runs, each in Morton order: opaque to rays, then cut-out (Mask without transmission), then
// transmissive (trianglesOpaqueToRays, trianglesDrawnOpaque give the run ends); within each, the
// triangles that never move first, then those that move.
void finalizeScene(Scene& scene);

// Appends a quad (two triangles, counter-clockwise seen from the side `normal` points to).
void addQuad(Scene& scene, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d,
             uint32_t material);
// Appends an axis-aligned box (outward faces) rotated about +Y by `angle` around its centre.
void addBox(Scene& scene, const glm::vec3& center, const glm::vec3& halfSize, float angle, uint32_t material);

}  // namespace probecast::scene
