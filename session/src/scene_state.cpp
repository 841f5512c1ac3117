#include "probecast/session/scene_state.h"

#include <cmath>
#include <stdexcept>

#include <glm/glm.hpp>

namespace probecast::session {

SceneStamp stampOf(const service::ScenePackage& package, double time) {
  SceneStamp s;
  s.hash = package.hash;
  s.manifest = package.manifest;
  s.time = time;
  return s;
}

std::vector<bus::LightState> lightStates(const scene::Scene& scene) {
  std::vector<bus::LightState> out;
  for (const scene::Light& l : scene.lights) {
    if (out.size() == bus::kMaxStateLights)
      throw std::runtime_error(scene.name + " has more than 64 punctual lights: a scene state carries at most 64");
    bus::LightState s;
    s.type = static_cast<uint32_t>(l.type);
    const float len = glm::length(l.direction);
    const glm::vec3 d = len > 0.0f && std::isfinite(len) ? l.direction / len : glm::vec3(0.0f, -1.0f, 0.0f);
    for (int a = 0; a < 3; ++a) {
      s.position[a] = l.position[a];
      s.direction[a] = d[a];
      s.color[a] = l.color[a];
    }
    s.intensity = l.intensity;
    s.range = l.range;
    s.innerCone = l.innerConeAngle;
    s.outerCone = l.outerConeAngle;
    out.push_back(s);
  }
  return out;
}

bus::SceneState sceneStateOf(const scene::Scene& scene, double time, double rate, uint64_t clockUs) {
  bus::SceneState s;
  s.time = time;
  s.rate = rate;
  s.clockUs = clockUs;
  s.lights = lightStates(scene);
  return s;
}

void applyLights(const bus::SceneState& state, scene::Scene& scene) {
  scene.lights.clear();
  for (const bus::LightState& s : state.lights) {
    scene::Light l;
    l.type = static_cast<scene::LightType>(s.type);
    l.position = {s.position[0], s.position[1], s.position[2]};
    l.direction = {s.direction[0], s.direction[1], s.direction[2]};
    l.color = {s.color[0], s.color[1], s.color[2]};
    l.intensity = s.intensity;
    l.range = s.range;
    l.innerConeAngle = s.innerCone;
    l.outerConeAngle = s.outerCone;
    scene.lights.push_back(l);
  }
}

float animationT(double sceneTime) {
  const double t = sceneTime - std::floor(sceneTime);
  return t >= 1.0 ? 0.0f : static_cast<float>(t);
}

namespace {

// The files a package's glTF may read: the package's, relative to the glTF's folder.
scene::PackagedFiles packagedFiles(const service::ScenePackage& p) {
  scene::PackagedFiles files;
  const size_t slash = p.scene.rfind('/');
  const std::string folder = slash == std::string::npos ? std::string() : p.scene.substr(0, slash + 1);
  for (const service::PackageFile& f : p.files)
    if (f.path != p.scene && f.path.rfind(folder, 0) == 0) files.listed.push_back(f.path.substr(folder.size()));
  return files;
}

ViewerScene fromPackage(const service::ScenePackage& p, bool checked, std::string note) {
  ViewerScene v;
  v.spec = p.localSceneSpec();
  if (!p.builtin()) v.packaged = packagedFiles(p);
  v.environmentFile = p.localEnvironmentFile();
  v.lighting = p.lighting;
  v.checked = checked;
  v.note = std::move(note);
  return v;
}

bool lightingGiven(const service::LightingRequest& l) { return !l.environmentFile.empty() || !l.sky.empty(); }

std::string fetchNote(const service::ScenePackage& p, const service::SceneFetch& fetch) {
  if (p.files.empty()) return "scene " + p.describe() + " (named by the stream)";
  if (fetch.fromCache) return "scene " + p.describe() + " from the cache";
  char text[128];
  std::snprintf(text, sizeof text, " fetched from the server: %llu bytes in %.0f ms",
                static_cast<unsigned long long>(fetch.bytes), fetch.ms);
  return "scene " + p.describe() + text;
}

}  // namespace

namespace {

ViewerScene resolve(const SceneStamp& stamp, const SceneChoice& choice, const service::ClientConfig& client,
                    service::SceneFetch& fetch) {
  std::string error;
  if (!stamp.known()) {
    if (choice.localSpec.empty())
      throw std::runtime_error("the server does not name its scene (its probes were made before scenes were named, or "
                               "in code): give --scene");
    ViewerScene v;
    v.spec = choice.localSpec;
    v.environmentFile = choice.localLighting.environmentFile;
    v.note = "scene " + choice.localSpec + " as given: the server names no scene, so it is not checked";
    return v;
  }
  service::ScenePackage stream;
  if (!service::parseManifest(stamp.manifest, stream, error)) throw std::runtime_error("the stream's scene: " + error);
  if (choice.localSpec.empty()) {
    if (lightingGiven(choice.localLighting))
      throw std::runtime_error("--environment and --sky go with a local --scene; the stream's scene brings its own "
                               "lighting (" + stream.describe() + ")");
    service::ScenePackage p;
    if (!service::fetchScene(client, stamp, choice.cache, choice.maxBytes, p, fetch, error))
      throw std::runtime_error(error);
    return fromPackage(p, true, fetchNote(p, fetch));
  }
  service::ScenePackage local;
  if (!service::makeScenePackage(choice.localSpec, choice.localLighting, local, error)) throw std::runtime_error(error);
  if (local.sceneHash() != stream.sceneHash())
    throw std::runtime_error("--scene " + choice.localSpec + " is not the scene the server traces: yours is " +
                             local.scene + " (scene " + service::shortHex(local.sceneHash()) + "), the stream's " +
                             stream.scene + " (scene " + service::shortHex(stream.sceneHash()) +
                             "); leave --scene out to use the server's");
  if (lightingGiven(choice.localLighting)) {
    if (local.hash != stamp.hash)
      throw std::runtime_error("--environment/--sky light the scene otherwise than the server does: yours " +
                               local.describe() + ", the stream's " + stream.describe() +
                               "; leave them out to use the server's");
    ViewerScene v = fromPackage(local, true, "scene " + local.describe() + " as given, matching the stream's");
    v.packaged.reset();  // the viewer's own files
    return v;
  }
  if (stream.lighting.kind != service::SceneLighting::Kind::Environment) {
    ViewerScene v = fromPackage(local, true, "scene " + local.scene + " as given, matching the stream's (" +
                                                 stream.describe() + ")");
    v.packaged.reset();  // the viewer's own files
    v.lighting = stream.lighting;
    return v;
  }
  service::ScenePackage p;  // the stream's environment map: with its package
  if (!service::fetchScene(client, stamp, choice.cache, choice.maxBytes, p, fetch, error))
    throw std::runtime_error(error);
  ViewerScene v = fromPackage(p, true, fetchNote(p, fetch));
  v.spec = local.localSceneSpec();  // the viewer's own files: not a package's
  v.packaged.reset();
  return v;
}

}  // namespace

ViewerScene resolveViewerScene(const SceneStamp& stamp, const SceneChoice& choice,
                               const service::ClientConfig& client, service::SceneFetch& fetch) {
  ViewerScene v = resolve(stamp, choice, client, fetch);
  if (stamp.known()) v.hash = stamp.hash;
  return v;
}

}  // namespace probecast::session
