#include "gpu_scene.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "probe_trace_shared.h"
#include "texture_mips.h"

namespace probecast::renderer {

void uploadGpuShading(VulkanDevice& d, const scene::Scene& s, GpuScene& g) {
  constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  destroyBuffer(d, g.triangleMaterial);
  destroyBuffer(d, g.materials);
  destroyBuffer(d, g.lights);
  g.triangleMaterial = createBufferWithData(d, s.triangleMaterial.data(), s.triangleMaterial.size() * 4, kStorage);
  std::vector<shaders::PtMaterial> mats;
  // Against the textures on the device: a scene whose textures changed without uploadGpuSurfaces
  // must not send a shader past them.
  const auto textureIndex = [&](int32_t t) {
    return t >= 0 && t < static_cast<int32_t>(std::min<size_t>(s.textures.size(), g.textureCount)) ? t : -1;
  };
  const auto rows = [](const scene::TextureTransform& t, shaders::vec4& row0, shaders::vec4& row1) {
    row0 = {t.row0.x, t.row0.y, t.row0.z, static_cast<float>(t.texCoord)};
    row1 = {t.row1.x, t.row1.y, t.row1.z, 0.0f};
  };
  for (const scene::Material& m : s.materials) {
    shaders::PtMaterial pm{};
    pm.baseColorMetallic = {m.baseColor.r, m.baseColor.g, m.baseColor.b, m.metallic};
    pm.emissionRoughness = {m.emission.r, m.emission.g, m.emission.b, m.roughness};
    pm.textures = {textureIndex(m.baseColorTexture), textureIndex(m.emissiveTexture),
                  static_cast<int32_t>(m.alphaMode), 0};
    pm.alpha = {m.alpha, m.alphaCutoff, m.transmission, 0.0f};
    rows(m.baseColorTransform, pm.baseTransform0, pm.baseTransform1);
    rows(m.emissiveTransform, pm.emissiveTransform0, pm.emissiveTransform1);
    pm.dataTextures = {textureIndex(m.metallicRoughnessTexture), textureIndex(m.occlusionTexture),
                       textureIndex(m.normalTexture), 0};
    pm.dataFactors = {m.occlusionStrength, m.normalScale, 0.0f, 0.0f};
    rows(m.metallicRoughnessTransform, pm.metallicRoughnessTransform0, pm.metallicRoughnessTransform1);
    rows(m.occlusionTransform, pm.occlusionTransform0, pm.occlusionTransform1);
    rows(m.normalTransform, pm.normalTransform0, pm.normalTransform1);
    mats.push_back(pm);
  }
  static_assert(PT_ALPHA_OPAQUE == static_cast<int>(scene::AlphaMode::Opaque) &&
                PT_ALPHA_MASK == static_cast<int>(scene::AlphaMode::Mask) &&
                PT_ALPHA_BLEND == static_cast<int>(scene::AlphaMode::Blend));
  g.materials = createBufferWithData(d, mats.data(), mats.size() * sizeof(shaders::PtMaterial), kStorage);
  std::vector<shaders::PtLight> ls;
  for (const scene::Light& l : s.lights) {
    const glm::vec3 dir = glm::length(l.direction) > 0 ? glm::normalize(l.direction) : glm::vec3(0, -1, 0);
    ls.push_back({{l.position.x, l.position.y, l.position.z, static_cast<float>(static_cast<uint32_t>(l.type))},
                  {dir.x, dir.y, dir.z, l.range},
                  {l.color.r, l.color.g, l.color.b, l.intensity},
                  {std::cos(l.outerConeAngle), std::cos(l.innerConeAngle), 0.0f, 0.0f}});
  }
  g.lights = createBufferWithData(d, ls.data(), ls.size() * sizeof(shaders::PtLight), kStorage);
  g.lightCount = static_cast<uint32_t>(ls.size());

  // Emissive triangles, chosen for next-event estimation in proportion to luminance × area.
  destroyBuffer(d, g.emitters);
  std::vector<shaders::PtEmitter> emitters;
  double total = 0.0;
  for (uint32_t t = 0; t < s.triangleCount(); ++t) {
    const glm::vec3 e = s.materials[s.triangleMaterial[t]].emission;
    const float luma = 0.2126f * e.r + 0.7152f * e.g + 0.0722f * e.b;
    const glm::vec3 p0 = s.positions[s.indices[3 * t]], p1 = s.positions[s.indices[3 * t + 1]],
                    p2 = s.positions[s.indices[3 * t + 2]];
    const float area = 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
    const float power = luma * area;
    if (!(power > 0.0f) || !std::isfinite(power)) continue;
    total += power;
    emitters.push_back({t, static_cast<float>(total), power, 0.0f});
  }
  g.emitters = createBufferWithData(d, emitters.data(), emitters.size() * sizeof(shaders::PtEmitter), kStorage);
  g.emitterCount = static_cast<uint32_t>(emitters.size());
  g.emitterPower = static_cast<float>(total);
  if (!emitters.empty()) {  // the last CDF entry equals the total exactly, so a draw never runs past it
    static_cast<shaders::PtEmitter*>(g.emitters.mapped)[emitters.size() - 1].cdf = g.emitterPower;
  }
}

void markClientLitMaterials(const std::vector<uint8_t>& clientLit, GpuScene& g) {
  auto* mats = static_cast<shaders::PtMaterial*>(g.materials.mapped);
  const size_t count = g.materials.size / sizeof(shaders::PtMaterial);
  for (size_t m = 0; m < count; ++m) mats[m].textures.w = m < clientLit.size() && clientLit[m] ? 1 : 0;
}

void uploadGpuEnvironment(VulkanDevice& d, const Environment* env, bool sampling, GpuScene& g) {
  constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  destroyBuffer(d, g.environment);
  destroyBuffer(d, g.environmentData);
  shaders::PtEnvironment header{};
  std::vector<float> data;
  if (env && !env->empty()) {
    const EnvironmentDistribution dist = buildEnvironmentDistribution(*env);
    header.mode = PT_ENV_MAP;
    header.width = static_cast<uint32_t>(env->width);
    header.height = static_cast<uint32_t>(env->height);
    header.sampling = sampling && dist.total > 0.0 ? 1u : 0u;
    header.cosRotation = std::cos(env->rotation);
    header.sinRotation = std::sin(env->rotation);
    header.total = static_cast<float>(dist.total);
    data = env->rgb;
    header.rowsOffset = static_cast<uint32_t>(data.size());
    data.insert(data.end(), dist.rows.begin(), dist.rows.end());
    header.columnsOffset = static_cast<uint32_t>(data.size());
    data.insert(data.end(), dist.columns.begin(), dist.columns.end());
  }
  if (data.empty()) data.assign(4, 0.0f);  // a valid binding for PT_ENV_NONE
  g.environment = createBufferWithData(d, &header, sizeof header, kStorage);
  g.environmentData = createBufferWithData(d, data.data(), data.size() * sizeof(float), kStorage);
}

bool SurfaceRecord::changedBy(const scene::Scene& s) {
  if (s.normals == normals && s.texcoords == texcoords && s.texcoords1 == texcoords1 && s.textures == textures)
    return false;
  normals = s.normals;
  texcoords = s.texcoords;
  texcoords1 = s.texcoords1;
  textures = s.textures;
  return true;
}

void uploadGpuScene(VulkanDevice& d, const scene::Scene& s, GpuScene& g) {
  if (g.accel.positions.buffer) destroySceneAccel(d, g.accel);
  buildSceneAccel(d, s, g.accel);
  uploadGpuSurfaces(d, s, g);
  if (!g.environment.buffer) uploadGpuEnvironment(d, nullptr, false, g);
}

void uploadGpuSurfaces(VulkanDevice& d, const scene::Scene& s, GpuScene& g) {
  constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  for (Buffer* b : {&g.normals, &g.texcoords, &g.texels, &g.textures}) destroyBuffer(d, *b);
  std::vector<glm::vec3> normals = s.normals;
  normals.resize(s.positions.size(), glm::vec3(0.0f));  // 0: the shader uses the geometric normal
  constexpr VkBufferUsageFlags kVertex = kStorage | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
  g.normals = createBufferWithData(d, normals.data(), normals.size() * sizeof(glm::vec3), kVertex);
  std::vector<glm::vec4> uvs(s.positions.size(), glm::vec4(0.0f));  // TEXCOORD_0, TEXCOORD_1
  for (size_t i = 0; i < uvs.size(); ++i) {
    if (i < s.texcoords.size()) uvs[i].x = s.texcoords[i].x, uvs[i].y = s.texcoords[i].y;
    if (i < s.texcoords1.size()) uvs[i].z = s.texcoords1[i].x, uvs[i].w = s.texcoords1[i].y;
  }
  g.texcoords = createBufferWithData(d, uvs.data(), uvs.size() * sizeof(glm::vec4), kVertex);
  std::vector<uint32_t> texels;
  std::vector<shaders::PtTexture> infos;
  const std::vector<bool> colour = colourTextures(s);
  for (size_t k = 0; k < s.textures.size(); ++k) {
    const scene::Texture& t = s.textures[k];
    const auto offset = static_cast<uint32_t>(texels.size());
    const uint32_t levels = appendMipChain(t, colour[k], texels);
    if (texels.size() > UINT32_MAX) throw std::runtime_error("the scene's textures exceed 2^32 texels");
    infos.push_back({offset, t.width, t.height, levels});
  }
  g.texels = createBufferWithData(d, texels.data(), texels.size() * 4, kStorage);
  g.textures = createBufferWithData(d, infos.data(), infos.size() * sizeof(shaders::PtTexture), kStorage);
  g.textureCount = static_cast<uint32_t>(infos.size());
  uploadGpuShading(d, s, g);
}

void destroyGpuScene(VulkanDevice& d, GpuScene& g) {
  destroySceneAccel(d, g.accel);
  destroyBuffer(d, g.triangleMaterial);
  destroyBuffer(d, g.materials);
  destroyBuffer(d, g.lights);
  destroyBuffer(d, g.emitters);
  for (Buffer* b : {&g.normals, &g.texcoords, &g.texels, &g.textures, &g.environment, &g.environmentData})
    destroyBuffer(d, *b);
  g.lightCount = 0;
  g.emitterCount = 0;
}

}  // namespace probecast::renderer
