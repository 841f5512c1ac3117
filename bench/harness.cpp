#include "harness.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "probecast/imaging/image_io.h"

namespace probecast::bench {
namespace {

// FNV-1a, 64 bits: enough to tell entries apart (the JSON holds the full key, checked on load).
class Hasher {
 public:
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ull;
  }
  template <class T>
  void pod(const T& v) {
    bytes(&v, sizeof v);
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    pod(v.size());
    if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
  }
  void str(const std::string& s) {
    pod(s.size());
    bytes(s.data(), s.size());
  }
  std::string hex() const { return fmt::format("{:016x}", h_); }

 private:
  uint64_t h_ = 0xcbf29ce484222325ull;
};

}  // namespace

std::string pixelHash(const std::vector<float>& rgb) {
  Hasher h;
  h.vec(rgb);
  return h.hex();
}

namespace {

nlohmann::json vec3(const glm::vec3& v) { return {v.x, v.y, v.z}; }

std::string environmentHash(const renderer::Environment& env) {
  Hasher h;
  h.pod(env.width);
  h.pod(env.height);
  h.vec(env.rgb);
  h.pod(env.rotation);
  return h.hex();
}

}  // namespace

std::string sceneContentHash(const scene::Scene& s) {
  Hasher h;
  h.str(s.name);
  h.vec(s.positions);
  h.vec(s.normals);
  h.vec(s.texcoords);
  h.vec(s.texcoords1);
  h.vec(s.indices);
  h.vec(s.triangleMaterial);
  h.pod(s.materials.size());
  for (const scene::Material& m : s.materials) {
    h.str(m.name);
    h.pod(m.baseColor);
    h.pod(m.metallic);
    h.pod(m.roughness);
    h.pod(m.emission);
    h.pod(m.baseColorTexture);
    h.pod(m.emissiveTexture);
    for (const scene::TextureTransform* tt : {&m.baseColorTransform, &m.emissiveTransform}) {
      h.pod(tt->row0);
      h.pod(tt->row1);
      h.pod(tt->texCoord);
    }
    h.pod(m.alphaMode);
    h.pod(m.alpha);
    h.pod(m.alphaCutoff);
    h.pod(m.transmission);
  }
  h.pod(s.textures.size());
  for (const scene::Texture& t : s.textures) {
    h.pod(t.width);
    h.pod(t.height);
    h.vec(t.rgba);
  }
  h.pod(s.lights.size());
  for (const scene::Light& l : s.lights) {
    h.pod(l.type);
    h.pod(l.position);
    h.pod(l.direction);
    h.pod(l.color);
    h.pod(l.intensity);
    h.pod(l.range);
    h.pod(l.innerConeAngle);
    h.pod(l.outerConeAngle);
  }
  h.pod(s.boundsMin);
  h.pod(s.boundsMax);
  return h.hex();
}

nlohmann::json referenceKey(const scene::Scene& scene, const ReferenceRequest& r) {
  const renderer::ReferenceOptions& o = r.options;
  nlohmann::json env = nullptr;
  if (o.environment && !o.environment->empty())
    env = {{"name", o.environment->name},
           {"size", {o.environment->width, o.environment->height}},
           {"rotation", o.environment->rotation},
           {"pixels", environmentHash(*o.environment)},
           {"sampling", o.environmentSampling}};
  return {{"renderer_version", kReferenceRendererVersion},
          {"scene", scene.name},
          {"scene_hash", sceneContentHash(scene)},
          {"t", r.t},
          {"camera",
           {{"position", vec3(r.camera.position)},
            {"forward", vec3(r.camera.forward)},
            {"up", vec3(r.camera.up)},
            {"yfov", r.camera.yfov},
            {"shift", {r.camera.shift.x, r.camera.shift.y}}}},
          {"size", {o.width, o.height}},
          {"spp", o.samplesPerPixel},
          {"seed", o.seed},
          {"bounces", o.maxBounces},
          {"indirect_clamp", o.indirectClamp},
          {"environment", env}};
}

std::string referenceKeyStem(const nlohmann::json& key) {
  Hasher h;
  h.str(key.dump());
  return h.hex();
}

ReferenceRequest referenceRequest(const renderer::CameraView& camera, uint32_t width, uint32_t height, uint32_t spp,
                                  std::shared_ptr<const renderer::Environment> environment, float t) {
  ReferenceRequest request;
  request.t = t;
  request.camera = camera;
  request.options.width = width;
  request.options.height = height;
  request.options.samplesPerPixel = spp;
  request.options.environment = std::move(environment);
  return request;
}

void sayProgress(const std::function<void(const std::string&)>& progress, const std::string& line) {
  if (progress) progress(line);
}

double millisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

imaging::ImageMetrics compareChecked(const renderer::Image& image, const renderer::Image& reference,
                                     const std::string& what) {
  if (image.width != reference.width || image.height != reference.height || image.rgb.size() != reference.rgb.size())
    throw std::invalid_argument(fmt::format("{}: {}x{} against a {}x{} reference", what, image.width, image.height,
                                            reference.width, reference.height));
  for (const auto* rgb : {&image.rgb, &reference.rgb}) {
    const imaging::NonFinitePixels nf = imaging::findNonFinitePixels(*rgb);
    if (nf.count > 0)
      throw std::invalid_argument(fmt::format("{}: {} non-finite pixels in the {} (the first at x {}, y {})", what,
                                              nf.count, rgb == &image.rgb ? "render" : "reference",
                                              nf.first % image.width, nf.first / image.width));
  }
  return imaging::compareImages(image.rgb, reference.rgb, static_cast<int>(image.width),
                                static_cast<int>(image.height));
}

Comparison compareView(const renderer::Image& image, const Reference& reference, const renderer::Image& floatRender,
                       const std::string& what) {
  return {compareChecked(image, reference.mean, what), compareChecked(image, floatRender, what + " (against float probes)")};
}

std::string describeFloor(const Reference& r) {
  return fmt::format("floor {:.2f} dB, reference ≈ {:.2f} dB", r.floor.psnrDb, r.accuracyDb);
}

}  // namespace probecast::bench
