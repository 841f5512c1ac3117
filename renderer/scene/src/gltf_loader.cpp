// glTF 2.0 → Scene. The only file that sees tinygltf.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <set>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <tiny_gltf.h>

#include "probecast/scene/animation.h"
#include "probecast/scene/scene.h"

namespace probecast::scene {
namespace {

// Extensions a file may require: ones we implement, or that cannot change what we render.
const std::set<std::string> kSupportedRequired = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                                  "KHR_texture_transform", "KHR_materials_transmission"};

glm::mat4 nodeMatrix(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = static_cast<float>(node.matrix[i]);
    return m;
  }
  glm::mat4 m(1.0f);
  if (node.translation.size() == 3)
    m = glm::translate(m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) {
    const glm::quat q(static_cast<float>(node.rotation[3]), static_cast<float>(node.rotation[0]),
                      static_cast<float>(node.rotation[1]), static_cast<float>(node.rotation[2]));
    m = m * glm::mat4_cast(q);
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

// Reads element i of an accessor as `components` floats or an index; checks every bound.
class AccessorReader {
 public:
  AccessorReader(const tinygltf::Model& model, int index, std::string& error) {
    if (index < 0 || index >= static_cast<int>(model.accessors.size())) {
      error = "accessor " + std::to_string(index) + " does not exist";
      return;
    }
    acc_ = &model.accessors[index];
    if (acc_->sparse.isSparse) {
      error = "sparse accessors are not supported";
      return;
    }
    if (acc_->bufferView < 0 || acc_->bufferView >= static_cast<int>(model.bufferViews.size())) {
      error = "accessor " + std::to_string(index) + " has no buffer view";
      return;
    }
    const tinygltf::BufferView& view = model.bufferViews[acc_->bufferView];
    if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size())) {
      error = "buffer view of accessor " + std::to_string(index) + " has no buffer";
      return;
    }
    const tinygltf::Buffer& buffer = model.buffers[view.buffer];
    components_ = tinygltf::GetNumComponentsInType(static_cast<uint32_t>(acc_->type));
    componentSize_ = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(acc_->componentType));
    if (components_ <= 0 || componentSize_ <= 0) {
      error = "accessor " + std::to_string(index) + " has an invalid type";
      return;
    }
    stride_ = view.byteStride ? view.byteStride : static_cast<size_t>(components_ * componentSize_);
    const size_t elementBytes = static_cast<size_t>(components_ * componentSize_);
    // Every product and sum checked against the buffer before it is formed (a huge count must not wrap).
    const size_t size = buffer.data.size();
    const bool offsetsFit = view.byteOffset <= size && acc_->byteOffset <= size - view.byteOffset;
    const size_t begin = offsetsFit ? view.byteOffset + acc_->byteOffset : 0;
    const size_t room = offsetsFit ? size - begin : 0;
    const bool countFits = acc_->count == 0 || (elementBytes <= room && stride_ > 0 &&
                                                acc_->count - 1 <= (room - elementBytes) / stride_);
    const size_t need = countFits && acc_->count ? (acc_->count - 1) * stride_ + elementBytes : 0;
    if (!offsetsFit || !countFits || acc_->byteOffset > view.byteLength || need > view.byteLength - acc_->byteOffset) {
      error = "accessor " + std::to_string(index) + " reads past the end of its buffer";
      return;
    }
    data_ = buffer.data.data() + begin;
    ok_ = true;
  }
  bool ok() const { return ok_; }
  size_t count() const { return acc_->count; }
  int components() const { return components_; }
  int componentType() const { return acc_->componentType; }

  float component(size_t i, int c) const {
    const unsigned char* p = data_ + i * stride_ + static_cast<size_t>(c * componentSize_);
    switch (acc_->componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v;
        std::memcpy(&v, p, 4);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return acc_->normalized ? *p / 255.0f : *p;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return acc_->normalized ? v / 65535.0f : v;
      }
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const auto v = static_cast<int8_t>(*p);
        return acc_->normalized ? std::max(v / 127.0f, -1.0f) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return acc_->normalized ? std::max(v / 32767.0f, -1.0f) : v;
      }
      default: return 0.0f;
    }
  }
  uint32_t index(size_t i) const {
    const unsigned char* p = data_ + i * stride_;
    switch (acc_->componentType) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
      }
      default: return UINT32_MAX;
    }
  }

 private:
  const tinygltf::Accessor* acc_ = nullptr;
  const unsigned char* data_ = nullptr;
  size_t stride_ = 0;
  int components_ = 0;
  int componentSize_ = 0;
  bool ok_ = false;
};

glm::vec3 vec3Of(const std::vector<double>& v, glm::vec3 fallback) {
  return v.size() >= 3 ? glm::vec3(v[0], v[1], v[2]) : fallback;
}

// glTF texture index → Scene::textures index (images converted to RGBA8 once each). 16-bit
// images keep their top 8 bits, rounded: the encoded value, so sRGB colour stays sRGB.
int32_t convertTexture(const tinygltf::Model& model, int textureIndex, std::vector<int32_t>& imageToTexture,
                       Scene& scene) {
  if (textureIndex < 0 || textureIndex >= static_cast<int>(model.textures.size())) return -1;
  const int source = model.textures[textureIndex].source;
  if (source < 0 || source >= static_cast<int>(model.images.size())) return -1;
  if (imageToTexture[source] >= 0) return imageToTexture[source];
  const tinygltf::Image& img = model.images[source];
  const int comps = img.component;
  const int bytes = img.bits == 16 ? 2 : 1;
  if (img.width <= 0 || img.height <= 0 || (img.bits != 8 && img.bits != 16) || comps < 1 || comps > 4 ||
      img.image.size() < static_cast<size_t>(img.width) * img.height * comps * bytes)
    return -1;  // undecodable images: the factor alone is used
  const auto channel = [&](size_t i, int c) -> uint8_t {
    if (bytes == 1) return img.image[i * comps + c];
    uint16_t v;  // tinygltf hands 16-bit samples over in host order
    std::memcpy(&v, &img.image[(i * comps + c) * 2], 2);
    return static_cast<uint8_t>((v * 255u + 32767u) / 65535u);
  };
  Texture t;
  t.width = static_cast<uint32_t>(img.width);
  t.height = static_cast<uint32_t>(img.height);
  t.rgba.resize(static_cast<size_t>(t.width) * t.height * 4);
  for (size_t i = 0; i < static_cast<size_t>(t.width) * t.height; ++i) {
    t.rgba[i * 4 + 0] = channel(i, 0);
    t.rgba[i * 4 + 1] = comps >= 3 ? channel(i, 1) : channel(i, 0);
    t.rgba[i * 4 + 2] = comps >= 3 ? channel(i, 2) : channel(i, 0);
    t.rgba[i * 4 + 3] = comps == 4 ? channel(i, 3) : (comps == 2 ? channel(i, 1) : 255);
  }
  scene.textures.push_back(std::move(t));
  imageToTexture[source] = static_cast<int32_t>(scene.textures.size() - 1);
  return imageToTexture[source];
}

double numberOr(const tinygltf::Value& object, const char* key, double fallback) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

// KHR_texture_transform of a texture reference (identity and `texCoord` without it): the matrix
// translation(offset) × rotation(r) × scale, rotation as the extension defines it (counter-clockwise
// in uv with v down: [cos r, sin r; −sin r, cos r]).
TextureTransform textureTransform(const tinygltf::ExtensionMap& extensions, int texCoord) {
  TextureTransform t;
  t.texCoord = texCoord == 1 ? 1u : 0u;
  auto it = extensions.find("KHR_texture_transform");
  if (it == extensions.end() || !it->second.IsObject()) return t;
  const tinygltf::Value& x = it->second;
  glm::vec2 offset(0.0f), scale(1.0f);
  if (x.Has("offset") && x.Get("offset").IsArray() && x.Get("offset").ArrayLen() == 2)
    offset = {x.Get("offset").Get(0).GetNumberAsDouble(), x.Get("offset").Get(1).GetNumberAsDouble()};
  if (x.Has("scale") && x.Get("scale").IsArray() && x.Get("scale").ArrayLen() == 2)
    scale = {x.Get("scale").Get(0).GetNumberAsDouble(), x.Get("scale").Get(1).GetNumberAsDouble()};
  const float r = static_cast<float>(numberOr(x, "rotation", 0.0));
  const float c = std::cos(r), s = std::sin(r);
  t.row0 = {c * scale.x, s * scale.y, offset.x};
  t.row1 = {-s * scale.x, c * scale.y, offset.y};
  if (x.Has("texCoord") && x.Get("texCoord").IsInt()) t.texCoord = x.Get("texCoord").GetNumberAsInt() == 1 ? 1u : 0u;
  const bool finite = std::isfinite(t.row0.x + t.row0.y + t.row0.z + t.row1.x + t.row1.y + t.row1.z);
  return finite ? t : TextureTransform{};
}

void convertMaterials(const tinygltf::Model& model, Scene& scene) {
  std::vector<int32_t> imageToTexture(model.images.size(), -1);
  for (const tinygltf::Material& m : model.materials) {
    Material out;
    out.name = m.name;
    const auto& pbr = m.pbrMetallicRoughness;
    out.baseColor = vec3Of(pbr.baseColorFactor, glm::vec3(1.0f));
    out.metallic = static_cast<float>(pbr.metallicFactor);
    out.roughness = static_cast<float>(pbr.roughnessFactor);
    float strength = 1.0f;
    auto it = m.extensions.find("KHR_materials_emissive_strength");
    if (it != m.extensions.end() && it->second.Has("emissiveStrength"))
      strength = static_cast<float>(it->second.Get("emissiveStrength").GetNumberAsDouble());
    out.emission = vec3Of(m.emissiveFactor, glm::vec3(0.0f)) * strength;
    out.baseColorTexture = convertTexture(model, pbr.baseColorTexture.index, imageToTexture, scene);
    out.emissiveTexture = convertTexture(model, m.emissiveTexture.index, imageToTexture, scene);
    out.baseColorTransform = textureTransform(pbr.baseColorTexture.extensions, pbr.baseColorTexture.texCoord);
    out.emissiveTransform = textureTransform(m.emissiveTexture.extensions, m.emissiveTexture.texCoord);
    out.metallicRoughnessTexture = convertTexture(model, pbr.metallicRoughnessTexture.index, imageToTexture, scene);
    out.metallicRoughnessTransform =
        textureTransform(pbr.metallicRoughnessTexture.extensions, pbr.metallicRoughnessTexture.texCoord);
    out.occlusionTexture = convertTexture(model, m.occlusionTexture.index, imageToTexture, scene);
    out.occlusionTransform = textureTransform(m.occlusionTexture.extensions, m.occlusionTexture.texCoord);
    out.normalTexture = convertTexture(model, m.normalTexture.index, imageToTexture, scene);
    out.normalTransform = textureTransform(m.normalTexture.extensions, m.normalTexture.texCoord);
    out.normalScale = std::isfinite(m.normalTexture.scale)
                          ? std::clamp(static_cast<float>(m.normalTexture.scale), -16.0f, 16.0f)
                          : 1.0f;
    out.occlusionStrength = std::isfinite(m.occlusionTexture.strength)
                                ? std::clamp(static_cast<float>(m.occlusionTexture.strength), 0.0f, 1.0f)
                                : 1.0f;
    out.alpha = pbr.baseColorFactor.size() == 4 ? std::clamp(static_cast<float>(pbr.baseColorFactor[3]), 0.0f, 1.0f)
                                                : 1.0f;
    out.alphaMode = m.alphaMode == "MASK"    ? AlphaMode::Mask
                    : m.alphaMode == "BLEND" ? AlphaMode::Blend
                                             : AlphaMode::Opaque;
    out.alphaCutoff = std::isfinite(m.alphaCutoff) ? static_cast<float>(m.alphaCutoff) : 0.5f;
    it = m.extensions.find("KHR_materials_transmission");
    if (it != m.extensions.end() && it->second.IsObject())
      out.transmission = std::clamp(static_cast<float>(numberOr(it->second, "transmissionFactor", 0.0)), 0.0f, 1.0f);
    if (!std::isfinite(out.transmission)) out.transmission = 0.0f;
    scene.materials.push_back(out);
  }
  // Primitives without a material use glTF's default (white, metallic 1 roughness 1 per spec;
  // we use a plain diffuse white as most viewers do).
  Material fallback;
  fallback.name = "default";
  fallback.baseColor = glm::vec3(1.0f);
  scene.materials.push_back(fallback);
}

// Reads `accessorIndex` as `count` vectors of `n` floats (n ≤ 4) into out.
bool readVectors(const tinygltf::Model& model, int accessorIndex, size_t count, int n, const char* what,
                 std::vector<glm::vec4>& out, std::string& error) {
  AccessorReader r(model, accessorIndex, error);
  if (!r.ok()) return false;
  if (r.count() != count || r.components() != n) {
    error = std::string(what) + " must hold " + std::to_string(count) + " elements of " + std::to_string(n) +
            " components";
    return false;
  }
  out.assign(count, glm::vec4(0.0f));
  for (size_t i = 0; i < count; ++i)
    for (int c = 0; c < n; ++c) {
      const float v = r.component(i, c);
      if (!std::isfinite(v)) {
        error = std::string(what) + " holds NaN or Inf";
        return false;
      }
      out[i][c] = v;
    }
  return true;
}

// The skin, morph targets and rest data of a primitive that moves (`rig` filled; `skin` the
// node's skin or -1, `jointCount` its joints).
bool rigPrimitive(const tinygltf::Model& model, const tinygltf::Primitive& prim, size_t count, int skin,
                  size_t jointCount, RigPrimitive& rig, std::string& error) {
  rig.skin = skin;
  if (skin >= 0) {
    for (int set = 0; set < 2; ++set) {
      auto j = prim.attributes.find(set == 0 ? "JOINTS_0" : "JOINTS_1");
      auto w = prim.attributes.find(set == 0 ? "WEIGHTS_0" : "WEIGHTS_1");
      if (j == prim.attributes.end() && w == prim.attributes.end()) continue;
      if (j == prim.attributes.end() || w == prim.attributes.end()) {
        error = "a skinned primitive has JOINTS_" + std::to_string(set) + " without WEIGHTS_" + std::to_string(set) +
                " or the other way round";
        return false;
      }
      std::vector<glm::vec4> joints, weights;
      if (!readVectors(model, j->second, count, 4, "JOINTS", joints, error) ||
          !readVectors(model, w->second, count, 4, "WEIGHTS", weights, error))
        return false;
      rig.joints[set].resize(count);
      rig.weights[set] = weights;
      for (size_t i = 0; i < count; ++i)
        for (int c = 0; c < 4; ++c) {
          const float v = joints[i][c];
          if (v < 0.0f || v >= static_cast<float>(jointCount) || v != std::floor(v)) {
            error = "JOINTS names joint " + std::to_string(static_cast<long long>(v)) + " of a skin with " +
                    std::to_string(jointCount);
            return false;
          }
          rig.joints[set][i][c] = static_cast<uint32_t>(v);
        }
    }
    if (rig.joints[0].empty() && rig.joints[1].empty()) {
      error = "a skinned primitive has no JOINTS_0/WEIGHTS_0";
      return false;
    }
  }
  for (const auto& target : prim.targets) {
    std::vector<glm::vec3> dp, dn;
    std::vector<glm::vec4> v;
    auto p = target.find("POSITION");
    if (p != target.end()) {
      if (!readVectors(model, p->second, count, 3, "a morph target's POSITION", v, error)) return false;
      for (const glm::vec4& x : v) dp.emplace_back(x);
    }
    auto n = target.find("NORMAL");
    if (n != target.end()) {
      if (!readVectors(model, n->second, count, 3, "a morph target's NORMAL", v, error)) return false;
      for (const glm::vec4& x : v) dn.emplace_back(x);
    }
    rig.targetPositions.push_back(std::move(dp));
    rig.targetNormals.push_back(std::move(dn));
  }
  return true;
}

// `rig`: null for a primitive that never moves; otherwise filled with what poseScene needs.
bool addPrimitive(const tinygltf::Model& model, const tinygltf::Primitive& prim, const glm::mat4& world, Scene& scene,
                  std::string& error, RigPrimitive* rig = nullptr, int skin = -1, size_t jointCount = 0) {
  if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) return true;  // points and lines carry no surface
  auto pos = prim.attributes.find("POSITION");
  if (pos == prim.attributes.end()) {
    error = "a primitive has no POSITION";
    return false;
  }
  AccessorReader positions(model, pos->second, error);
  if (!positions.ok()) return false;
  if (positions.components() != 3 || positions.componentType() != TINYGLTF_COMPONENT_TYPE_FLOAT) {
    error = "POSITION must be float VEC3";
    return false;
  }
  const glm::mat3 normalMatrix = glm::transpose(glm::inverse(glm::mat3(world)));
  const uint32_t base = static_cast<uint32_t>(scene.positions.size());
  for (size_t i = 0; i < positions.count(); ++i) {
    const glm::vec3 p(positions.component(i, 0), positions.component(i, 1), positions.component(i, 2));
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      error = "POSITION holds NaN or Inf";
      return false;
    }
    scene.positions.push_back(glm::vec3(world * glm::vec4(p, 1.0f)));
  }
  std::vector<uint32_t> idx;
  if (prim.indices >= 0) {
    AccessorReader indices(model, prim.indices, error);
    if (!indices.ok()) return false;
    for (size_t i = 0; i < indices.count(); ++i) {
      const uint32_t v = indices.index(i);
      if (v >= positions.count()) {
        error = "index " + std::to_string(v) + " past the vertex count " + std::to_string(positions.count());
        return false;
      }
      idx.push_back(v);
    }
  } else {
    for (size_t i = 0; i < positions.count(); ++i) idx.push_back(static_cast<uint32_t>(i));
  }
  idx.resize(idx.size() / 3 * 3);
  const bool flip = glm::determinant(glm::mat3(world)) < 0.0f;  // mirrored nodes reverse winding
  auto nrm = prim.attributes.find("NORMAL");
  std::vector<glm::vec3> normals(positions.count(), glm::vec3(0.0f));
  bool haveNormals = false;
  if (rig) {
    rig->firstVertex = base;
    rig->vertexCount = static_cast<uint32_t>(positions.count());
    rig->flip = flip;
    rig->positions.resize(positions.count());
    for (size_t i = 0; i < positions.count(); ++i)
      rig->positions[i] = {positions.component(i, 0), positions.component(i, 1), positions.component(i, 2)};
    rig->normals.assign(positions.count(), glm::vec3(0.0f));
    rig->triangles = idx;
    if (!rigPrimitive(model, prim, positions.count(), skin, jointCount, *rig, error)) return false;
  }
  if (nrm != prim.attributes.end()) {
    AccessorReader n(model, nrm->second, error);
    if (!n.ok()) return false;
    if (n.count() == positions.count() && n.components() == 3) {
      for (size_t i = 0; i < n.count(); ++i) {
        const glm::vec3 raw(n.component(i, 0), n.component(i, 1), n.component(i, 2));
        const glm::vec3 v = normalMatrix * raw;
        const float len = glm::length(v);
        normals[i] = len > 0.0f && std::isfinite(len) ? v / len : glm::vec3(0.0f);
        if (rig) {
          const float rl = glm::length(raw);
          rig->normals[i] = rl > 0.0f && std::isfinite(rl) ? raw / rl : glm::vec3(0.0f);
        }
      }
      haveNormals = true;
    }
  }
  if (rig) rig->normalsGiven = haveNormals;
  if (!haveNormals) {  // flat normals accumulated per vertex
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {
      const glm::vec3 a = scene.positions[base + idx[t]], b = scene.positions[base + idx[t + 1]],
                      c = scene.positions[base + idx[t + 2]];
      const glm::vec3 fn = glm::cross(b - a, c - a) * (flip ? -1.0f : 1.0f);
      for (int k = 0; k < 3; ++k) normals[idx[t + k]] += fn;
    }
    for (glm::vec3& v : normals) {
      const float len = glm::length(v);
      v = len > 0.0f ? v / len : glm::vec3(0.0f, 1.0f, 0.0f);
    }
  }
  scene.normals.insert(scene.normals.end(), normals.begin(), normals.end());
  for (int set = 0; set < 2; ++set) {
    std::vector<glm::vec2> uvs(positions.count(), glm::vec2(0.0f));
    auto uv = prim.attributes.find(set == 0 ? "TEXCOORD_0" : "TEXCOORD_1");
    if (uv != prim.attributes.end()) {
      AccessorReader t(model, uv->second, error);
      if (!t.ok()) return false;
      if (t.count() == positions.count() && t.components() == 2)
        for (size_t i = 0; i < t.count(); ++i) {
          const glm::vec2 v(t.component(i, 0), t.component(i, 1));
          uvs[i] = std::isfinite(v.x) && std::isfinite(v.y) ? v : glm::vec2(0.0f);
        }
    }
    std::vector<glm::vec2>& out = set == 0 ? scene.texcoords : scene.texcoords1;
    out.insert(out.end(), uvs.begin(), uvs.end());
  }
  const uint32_t material =
      prim.material >= 0 && prim.material < static_cast<int>(model.materials.size())
          ? static_cast<uint32_t>(prim.material)
          : static_cast<uint32_t>(model.materials.size());  // the fallback appended last
  for (size_t t = 0; t + 2 < idx.size(); t += 3) {
    scene.indices.push_back(base + idx[t]);
    scene.indices.push_back(base + idx[flip ? t + 2 : t + 1]);
    scene.indices.push_back(base + idx[flip ? t + 1 : t + 2]);
    scene.triangleMaterial.push_back(material);
  }
  return true;
}

void addLight(const tinygltf::Model& model, const tinygltf::Node& node, const glm::mat4& world, Scene& scene) {
  auto ext = node.extensions.find("KHR_lights_punctual");
  if (ext == node.extensions.end() || !ext->second.Has("light")) return;
  const int index = ext->second.Get("light").GetNumberAsInt();
  if (index < 0 || index >= static_cast<int>(model.lights.size())) return;
  const tinygltf::Light& l = model.lights[index];
  Light out;
  out.type = l.type == "directional" ? LightType::Directional : (l.type == "spot" ? LightType::Spot : LightType::Point);
  out.position = glm::vec3(world[3]);
  out.direction = glm::normalize(glm::vec3(world * glm::vec4(0, 0, -1, 0)));
  out.color = vec3Of(l.color, glm::vec3(1.0f));
  out.intensity = static_cast<float>(l.intensity);
  out.range = static_cast<float>(l.range);
  out.innerConeAngle = static_cast<float>(l.spot.innerConeAngle);
  out.outerConeAngle = static_cast<float>(l.spot.outerConeAngle);
  scene.lights.push_back(out);
}

void addCamera(const tinygltf::Model& model, const tinygltf::Node& node, const glm::mat4& world, Scene& scene) {
  if (node.camera < 0 || node.camera >= static_cast<int>(model.cameras.size())) return;
  const tinygltf::Camera& c = model.cameras[node.camera];
  if (c.type != "perspective") return;
  Camera out;
  out.name = c.name;
  out.position = glm::vec3(world[3]);
  out.forward = glm::normalize(glm::vec3(world * glm::vec4(0, 0, -1, 0)));
  out.up = glm::normalize(glm::vec3(world * glm::vec4(0, 1, 0, 0)));
  out.yfov = static_cast<float>(c.perspective.yfov);
  out.aspect = static_cast<float>(c.perspective.aspectRatio);
  out.znear = static_cast<float>(c.perspective.znear);
  out.zfar = c.perspective.zfar > 0 ? static_cast<float>(c.perspective.zfar) : 1000.0f;
  scene.cameras.push_back(out);
}

// Every node's rest transform and morph weights, its parent, and an order with parents first.
bool rigNodes(const tinygltf::Model& model, Rig& rig, std::string& error) {
  const size_t n = model.nodes.size();
  rig.nodes.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const tinygltf::Node& node = model.nodes[i];
    RigNode& r = rig.nodes[i];
    if (node.matrix.size() == 16) {
      r.hasMatrix = true;
      r.matrix = nodeMatrix(node);
    }
    if (node.translation.size() == 3) r.translation = vec3Of(node.translation, glm::vec3(0.0f));
    if (node.rotation.size() == 4)
      r.rotation = glm::quat(static_cast<float>(node.rotation[3]), static_cast<float>(node.rotation[0]),
                             static_cast<float>(node.rotation[1]), static_cast<float>(node.rotation[2]));
    if (node.scale.size() == 3) r.scale = vec3Of(node.scale, glm::vec3(1.0f));
    if (node.mesh >= 0 && node.mesh < static_cast<int>(model.meshes.size()))
      for (double w : model.meshes[node.mesh].weights) r.weights.push_back(static_cast<float>(w));
    if (!node.weights.empty()) {
      r.weights.clear();
      for (double w : node.weights) r.weights.push_back(static_cast<float>(w));
    }
  }
  for (size_t i = 0; i < n; ++i)
    for (int c : model.nodes[i].children) {
      if (c < 0 || static_cast<size_t>(c) >= n || rig.nodes[c].parent >= 0 || static_cast<size_t>(c) == i) {
        error = "bad node hierarchy at node " + std::to_string(c);
        return false;
      }
      rig.nodes[c].parent = static_cast<int32_t>(i);
    }
  for (size_t i = 0; i < n; ++i)
    if (rig.nodes[i].parent < 0) rig.order.push_back(static_cast<uint32_t>(i));
  for (size_t k = 0; k < rig.order.size(); ++k)
    for (int c : model.nodes[rig.order[k]].children) rig.order.push_back(static_cast<uint32_t>(c));
  if (rig.order.size() != n) {
    error = "bad node hierarchy: a cycle of nodes";
    return false;
  }
  return true;
}

bool rigSkins(const tinygltf::Model& model, Rig& rig, std::string& error) {
  for (size_t k = 0; k < model.skins.size(); ++k) {
    const tinygltf::Skin& skin = model.skins[k];
    RigSkin out;
    const std::string name = "skin " + std::to_string(k);
    for (int j : skin.joints) {
      if (j < 0 || j >= static_cast<int>(model.nodes.size())) {
        error = name + " names a missing joint node " + std::to_string(j);
        return false;
      }
      out.joints.push_back(static_cast<uint32_t>(j));
    }
    out.inverseBind.assign(out.joints.size(), glm::mat4(1.0f));
    if (skin.inverseBindMatrices >= 0) {
      AccessorReader r(model, skin.inverseBindMatrices, error);
      if (!r.ok()) return false;
      if (r.components() != 16 || r.count() < out.joints.size()) {
        error = name + ": inverseBindMatrices must hold a MAT4 per joint";
        return false;
      }
      for (size_t j = 0; j < out.joints.size(); ++j)
        for (int c = 0; c < 16; ++c) {
          const float v = r.component(j, c);
          if (!std::isfinite(v)) {
            error = name + ": inverseBindMatrices hold NaN or Inf";
            return false;
          }
          glm::value_ptr(out.inverseBind[j])[c] = v;
        }
    }
    rig.skins.push_back(std::move(out));
  }
  return true;
}

bool rigClips(const tinygltf::Model& model, Rig& rig, std::string& error) {
  for (size_t a = 0; a < model.animations.size(); ++a) {
    const tinygltf::Animation& anim = model.animations[a];
    const std::string name = "animation " + std::to_string(a) + (anim.name.empty() ? "" : " (" + anim.name + ")");
    AnimationClip clip;
    clip.name = anim.name;
    std::vector<int> samplerPath(anim.samplers.size(), -1);  // the path each sampler animates
    for (const tinygltf::AnimationChannel& c : anim.channels) {
      if (c.target_node < 0) continue;  // no target: ignored, as glTF allows
      if (c.target_node >= static_cast<int>(model.nodes.size()) || c.sampler < 0 ||
          c.sampler >= static_cast<int>(anim.samplers.size())) {
        error = name + ": a channel names a missing node or sampler";
        return false;
      }
      AnimationChannel ch;
      ch.node = static_cast<uint32_t>(c.target_node);
      ch.sampler = static_cast<uint32_t>(c.sampler);
      if (c.target_path == "translation") ch.path = AnimatedPath::Translation;
      else if (c.target_path == "rotation") ch.path = AnimatedPath::Rotation;
      else if (c.target_path == "scale") ch.path = AnimatedPath::Scale;
      else if (c.target_path == "weights") ch.path = AnimatedPath::Weights;
      else continue;  // "pointer" and other paths this renderer does not animate
      if (ch.path != AnimatedPath::Weights && rig.nodes[ch.node].hasMatrix) {
        error = name + ": node " + std::to_string(ch.node) + " has a matrix and cannot be animated";
        return false;
      }
      if (samplerPath[ch.sampler] >= 0 && samplerPath[ch.sampler] != static_cast<int>(ch.path)) {
        error = name + ": sampler " + std::to_string(ch.sampler) + " drives paths of different sizes";
        return false;
      }
      samplerPath[ch.sampler] = static_cast<int>(ch.path);
      clip.channels.push_back(ch);
    }
    for (size_t k = 0; k < anim.samplers.size(); ++k) {
      const tinygltf::AnimationSampler& in = anim.samplers[k];
      const std::string sname = name + " sampler " + std::to_string(k);
      AnimationSampler out;
      out.interpolation = in.interpolation == "STEP"          ? Interpolation::Step
                          : in.interpolation == "CUBICSPLINE" ? Interpolation::CubicSpline
                                                              : Interpolation::Linear;
      if (!in.interpolation.empty() && in.interpolation != "LINEAR" && in.interpolation != "STEP" &&
          in.interpolation != "CUBICSPLINE") {
        error = sname + ": unknown interpolation " + in.interpolation;
        return false;
      }
      AccessorReader times(model, in.input, error);
      if (!times.ok()) return false;
      AccessorReader values(model, in.output, error);
      if (!values.ok()) return false;
      if (times.components() != 1 || times.count() == 0) {
        error = sname + ": input must be SCALAR key times";
        return false;
      }
      for (size_t i = 0; i < times.count(); ++i) {
        const float t = times.component(i, 0);
        if (!std::isfinite(t) || t < 0.0f || (i > 0 && !(t > out.input.back()))) {
          error = sname + ": key times must be finite, not negative and increasing";
          return false;
        }
        out.input.push_back(t);
      }
      const size_t keys = out.input.size();
      const size_t perKey = out.interpolation == Interpolation::CubicSpline ? 3 : 1;
      const size_t total = values.count() * static_cast<size_t>(values.components());
      if (total % (keys * perKey) != 0 || total == 0) {
        error = sname + ": output does not hold a value per key";
        return false;
      }
      out.width = static_cast<uint32_t>(total / (keys * perKey));
      const int path = samplerPath[k];
      const uint32_t want = path == static_cast<int>(AnimatedPath::Rotation) ? 4u
                            : path == static_cast<int>(AnimatedPath::Weights) || path < 0 ? out.width
                                                                                         : 3u;
      if (out.width != want || out.width > 4096) {
        error = sname + ": output has " + std::to_string(out.width) + " components per key, the path needs " +
                std::to_string(want);
        return false;
      }
      out.output.reserve(total);
      for (size_t i = 0; i < values.count(); ++i)
        for (int c = 0; c < values.components(); ++c) {
          const float v = values.component(i, c);
          if (!std::isfinite(v)) {
            error = sname + ": output holds NaN or Inf";
            return false;
          }
          out.output.push_back(v);
        }
      clip.end = std::max(clip.end, out.input.back());
      clip.samplers.push_back(std::move(out));
    }
    for (const AnimationChannel& ch : clip.channels) {
      if (ch.path != AnimatedPath::Weights) continue;
      const size_t targets = rig.nodes[ch.node].weights.size();
      const tinygltf::Node& node = model.nodes[ch.node];
      const size_t meshTargets = node.mesh >= 0 && node.mesh < static_cast<int>(model.meshes.size()) &&
                                         !model.meshes[node.mesh].primitives.empty()
                                     ? model.meshes[node.mesh].primitives[0].targets.size()
                                     : targets;
      if (clip.samplers[ch.sampler].width != std::max(targets, meshTargets)) {
        error = name + ": a weights channel of node " + std::to_string(ch.node) + " has " +
                std::to_string(clip.samplers[ch.sampler].width) + " weights for " +
                std::to_string(std::max(targets, meshTargets)) + " morph targets";
        return false;
      }
    }
    rig.duration = std::max(rig.duration, clip.end);
    rig.clips.push_back(std::move(clip));
  }
  return true;
}

// Every key time of the clips, and `uniform` times between 0 and the duration (at most 1024 in all):
// the poses whose vertices the bounds must hold.
std::vector<double> poseTimes(const Rig& rig, int uniform) {
  std::set<double> times;
  for (int i = 0; i <= uniform; ++i) times.insert(static_cast<double>(rig.duration) * i / uniform);
  for (const AnimationClip& c : rig.clips)
    for (const AnimationSampler& s : c.samplers)
      for (float t : s.input)
        if (times.size() < 1024) times.insert(t);
  return {times.begin(), times.end()};
}

// What a glTF may read: itself, and files inside its folder (PackagedFiles: only those listed, and
// no symbolic link on the way). tinygltf joins each URI, already percent-decoded, to the glTF's
// folder and then to "." (the working folder); every path is judged here before it is opened.
struct FileRules {
  std::filesystem::path gltf;  // absolute, lexically normal
  std::string folder;          // the glTF's folder with a trailing '/'
  const PackagedFiles* packaged = nullptr;
  std::string refused;         // the first path refused, with the reason

  // The path inside the folder `file` names, or why it may not be read.
  bool inside(const std::string& file, std::string& relative, std::string& why) const {
    if (file.rfind(folder, 0) != 0) return why = "is not inside the glTF's folder", false;
    relative = file.substr(folder.size());
    const size_t slash = relative.find('/');
    if (relative.substr(0, slash).find(':') != std::string::npos) return why = "names a URI scheme", false;
    if (relative.empty() || relative.front() == '/') return why = "is absolute", false;
    for (size_t start = 0; start <= relative.size();) {
      const size_t end = std::min(relative.find('/', start), relative.size());
      const std::string part = relative.substr(start, end - start);
      if (part.empty() || part == "." || part == "..") return why = "leaves the glTF's folder", false;
      for (char c : part)
        if (c == '\\' || static_cast<unsigned char>(c) < 0x20) return why = "holds a backslash or a control character", false;
      start = end + 1;
    }
    if (!packaged) return true;
    if (std::find(packaged->listed.begin(), packaged->listed.end(), relative) == packaged->listed.end())
      return why = "is not a file of the scene's package", false;
    std::filesystem::path at = std::filesystem::path(folder);
    std::error_code ec;
    for (const auto& part : std::filesystem::path(relative)) {
      at /= part;
      if (std::filesystem::is_symlink(std::filesystem::symlink_status(at, ec))) return why = "is a symbolic link", false;
    }
    return true;
  }

  bool allowed(const std::string& file) {
    if (file == gltf.string()) return true;
    if (file.rfind("./", 0) == 0) return false;  // the working folder: never searched
    std::string relative, why;
    if (inside(file, relative, why)) return true;
    if (refused.empty()) refused = "'" + file + "' " + why;
    return false;
  }
};

tinygltf::FsCallbacks fileCallbacks(FileRules& rules) {
  tinygltf::FsCallbacks fs;
  fs.FileExists = [](const std::string& file, void* user) {
    return static_cast<FileRules*>(user)->allowed(file) && tinygltf::FileExists(file, nullptr);
  };
  fs.ExpandFilePath = [](const std::string& file, void*) { return file; };  // no ~ or $VARIABLE expansion
  fs.ReadWholeFile = [](std::vector<unsigned char>* out, std::string* err, const std::string& file, void* user) {
    if (!static_cast<FileRules*>(user)->allowed(file)) return *err = "refused: " + file, false;
    return tinygltf::ReadWholeFile(out, err, file, nullptr);
  };
  fs.WriteWholeFile = [](std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    return *err = "writing is not allowed", false;
  };
  fs.user_data = &rules;
  return fs;
}

}  // namespace

bool loadGltf(const std::string& path, Scene& scene, std::string& error, double seconds,
              const PackagedFiles* packaged) {
  scene = Scene{};
  scene.name = std::filesystem::path(path).filename().string();
  const auto fail = [&](const std::string& why) {
    error = path + ": " + why;
    return false;
  };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail("no such file");
  FileRules rules;
  rules.gltf = std::filesystem::absolute(path, ec).lexically_normal();
  rules.folder = rules.gltf.parent_path().string();
  if (rules.folder.empty() || rules.folder.back() != '/') rules.folder += '/';
  rules.packaged = packaged;
  if (packaged && std::filesystem::is_symlink(std::filesystem::symlink_status(rules.gltf, ec)))
    return fail("a scene package's glTF may not be a symbolic link");
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(fileCallbacks(rules));
  tinygltf::Model model;
  std::string err, warn;
  const bool binary = rules.gltf.extension() == ".glb";
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, rules.gltf.string())
                         : loader.LoadASCIIFromFile(&model, &err, &warn, rules.gltf.string());
  // A refused image is only a warning to tinygltf: it is an error here, as a refused buffer is.
  if (!rules.refused.empty()) return fail("refused to read " + rules.refused);
  if (!ok) return fail(err.empty() ? "cannot parse glTF" : err);
  for (const std::string& ext : model.extensionsRequired)
    if (!kSupportedRequired.count(ext)) return fail("requires unsupported extension " + ext);
  convertMaterials(model, scene);

  auto rig = std::make_shared<Rig>();
  std::string rigError;
  if (!rigNodes(model, *rig, rigError) || !rigSkins(model, *rig, rigError) || !rigClips(model, *rig, rigError))
    return fail(rigError);
  // Nodes that move: a channel's target (translation, rotation, scale) and everything below it.
  std::vector<uint8_t> moving(model.nodes.size(), 0), morphing(model.nodes.size(), 0);
  for (const AnimationClip& c : rig->clips)
    for (const AnimationChannel& ch : c.channels) (ch.path == AnimatedPath::Weights ? morphing : moving)[ch.node] = 1;
  for (uint32_t i : rig->order)
    if (rig->nodes[i].parent >= 0 && moving[rig->nodes[i].parent]) moving[i] = 1;

  std::string nodeError;
  std::set<int> visiting;
  std::function<bool(int, const glm::mat4&)> visit = [&](int index, const glm::mat4& parent) {
    if (index < 0 || index >= static_cast<int>(model.nodes.size()) || visiting.count(index)) {
      nodeError = "bad node hierarchy at node " + std::to_string(index);
      return false;
    }
    visiting.insert(index);
    const tinygltf::Node& node = model.nodes[index];
    const glm::mat4 world = parent * nodeMatrix(node);
    if (node.mesh >= 0) {
      if (node.mesh >= static_cast<int>(model.meshes.size())) {
        nodeError = "node " + std::to_string(index) + " names a missing mesh";
        return false;
      }
      const int skin = node.skin >= 0 && node.skin < static_cast<int>(rig->skins.size()) ? node.skin : -1;
      if (node.skin >= 0 && skin < 0) {
        nodeError = "node " + std::to_string(index) + " names a missing skin";
        return false;
      }
      for (const tinygltf::Primitive& prim : model.meshes[node.mesh].primitives) {
        // Skinned and morphed primitives are posed even when nothing plays (their rest pose is
        // the skin's, with the default weights).
        const bool posed = moving[index] || morphing[index] || skin >= 0 || !prim.targets.empty();
        RigPrimitive rp;
        rp.node = static_cast<uint32_t>(index);
        const size_t before = scene.positions.size();
        if (!addPrimitive(model, prim, world, scene, nodeError, posed ? &rp : nullptr, skin,
                          skin >= 0 ? rig->skins[skin].joints.size() : 0))
          return false;
        if (posed && scene.positions.size() > before) rig->primitives.push_back(std::move(rp));
      }
    }
    const size_t lights = scene.lights.size(), cameras = scene.cameras.size();
    addLight(model, node, world, scene);
    addCamera(model, node, world, scene);
    if (moving[index] && scene.lights.size() > lights)
      rig->lights.push_back({static_cast<uint32_t>(index), static_cast<uint32_t>(lights)});
    if (moving[index] && scene.cameras.size() > cameras)
      rig->cameras.push_back({static_cast<uint32_t>(index), static_cast<uint32_t>(cameras)});
    for (int child : node.children)
      if (!visit(child, world)) return false;
    visiting.erase(index);
    return true;
  };
  std::vector<int> roots;
  if (model.defaultScene >= 0 && model.defaultScene < static_cast<int>(model.scenes.size()))
    roots = model.scenes[model.defaultScene].nodes;
  else if (!model.scenes.empty())
    roots = model.scenes[0].nodes;
  else {  // no scene: every node that is nobody's child
    std::set<int> children;
    for (const tinygltf::Node& n : model.nodes) children.insert(n.children.begin(), n.children.end());
    for (int i = 0; i < static_cast<int>(model.nodes.size()); ++i)
      if (!children.count(i)) roots.push_back(i);
  }
  for (int root : roots)
    if (!visit(root, glm::mat4(1.0f))) return fail(nodeError);
  if (scene.triangleCount() == 0) return fail("no triangles");
  const auto finite = [](const glm::vec3& a, const glm::vec3& b) {
    return std::isfinite(a.x + a.y + a.z + b.x + b.y + b.z);
  };
  if (rig->primitives.empty() && rig->lights.empty() && rig->cameras.empty()) {
    finalizeScene(scene);
    if (!finite(scene.boundsMin, scene.boundsMax)) return fail("the node transforms take vertices to infinity or NaN");
    return true;
  }
  scene.rig = rig;
  poseScene(scene, 0.0);
  finalizeScene(scene);  // triangle order of the first pose
  // The bounds hold every pose (probe grids fitted to them stay put while things move).
  glm::vec3 lo = scene.boundsMin, hi = scene.boundsMax;
  if (rig->duration > 0.0f) {
    for (double t : poseTimes(*rig, 64)) {
      poseScene(scene, std::min(t, rig->duration * (1.0 - 1e-6)));
      for (const glm::vec3& p : scene.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
    }
  }
  if (!finite(lo, hi)) return fail("the node transforms or the animation take vertices to infinity or NaN");
  scene.boundsMin = lo;
  scene.boundsMax = hi;
  poseScene(scene, seconds);
  return true;
}

}  // namespace probecast::scene
