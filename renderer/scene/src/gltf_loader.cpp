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
    const size_t begin = view.byteOffset + acc_->byteOffset;
    const size_t elementBytes = static_cast<size_t>(components_ * componentSize_);
    const size_t need = acc_->count == 0 ? 0 : (acc_->count - 1) * stride_ + elementBytes;
    if (begin > buffer.data.size() || need > buffer.data.size() - begin || acc_->byteOffset + need > view.byteLength) {
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

bool addPrimitive(const tinygltf::Model& model, const tinygltf::Primitive& prim, const glm::mat4& world, Scene& scene,
                  std::string& error) {
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
  if (nrm != prim.attributes.end()) {
    AccessorReader n(model, nrm->second, error);
    if (!n.ok()) return false;
    if (n.count() == positions.count() && n.components() == 3) {
      for (size_t i = 0; i < n.count(); ++i) {
        const glm::vec3 v = normalMatrix * glm::vec3(n.component(i, 0), n.component(i, 1), n.component(i, 2));
        const float len = glm::length(v);
        normals[i] = len > 0.0f && std::isfinite(len) ? v / len : glm::vec3(0.0f);
      }
      haveNormals = true;
    }
  }
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

}  // namespace

bool loadGltf(const std::string& path, Scene& scene, std::string& error) {
  scene = Scene{};
  scene.name = std::filesystem::path(path).filename().string();
  const auto fail = [&](const std::string& why) {
    error = path + ": " + why;
    return false;
  };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail("no such file");
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  const bool binary = std::filesystem::path(path).extension() == ".glb";
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                         : loader.LoadASCIIFromFile(&model, &err, &warn, path);
  if (!ok) return fail(err.empty() ? "cannot parse glTF" : err);
  for (const std::string& ext : model.extensionsRequired)
    if (!kSupportedRequired.count(ext)) return fail("requires unsupported extension " + ext);
  convertMaterials(model, scene);

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
      for (const tinygltf::Primitive& prim : model.meshes[node.mesh].primitives)
        if (!addPrimitive(model, prim, world, scene, nodeError)) return false;
    }
    addLight(model, node, world, scene);
    addCamera(model, node, world, scene);
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
  finalizeScene(scene);
  return true;
}

}  // namespace probecast::scene
