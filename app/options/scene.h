// The scene a command loads and the distant light around it: --scene, --time, --environment, --sky.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "probecast/renderer/environment.h"
#include "probecast/scene/scene.h"
#include "probecast/service/scene_package.h"
#include "probecast/session/scene_loading.h"

namespace probecast::app {

// Distant light around the scene: --environment FILE (.hdr or .exr, equirect) with
// --environment-intensity K and --environment-rotation DEG, or a uniform --sky R,G,B. The map's
// convention is renderer/environment.h's (top row +Y, centre −Z, u = 0.75 toward +X; positive
// rotation turns it counter-clockwise seen from above, the centre toward −X).
struct EnvironmentOptions {
  std::string file;
  float intensity = 1.0f, rotationDeg = 0.0f;
  std::vector<float> sky;
  void add(CLI::App* cmd) {
    CLI::Option* e = cmd->add_option(
        "--environment", file, "equirect environment map (.hdr or .exr): top row +Y, image centre facing -Z");
    cmd->add_option("--environment-intensity", intensity, "scale of the environment map's radiance (>= 0)")->needs(e);
    cmd->add_option("--environment-rotation", rotationDeg,
                    "turn the map about +Y, degrees (counter-clockwise seen from above)")
        ->needs(e);
    cmd->add_option("--sky", sky, "uniform sky radiance R,G,B instead of a map")->delimiter(',')->expected(3)->excludes(e);
  }
  bool given() const { return !file.empty() || !sky.empty(); }
  // As a scene package names it.
  service::LightingRequest request() const {
    service::LightingRequest r;
    r.environmentFile = file;
    r.intensity = intensity;
    r.rotationDeg = rotationDeg;
    r.sky = sky;
    return r;
  }
  // The environment, or null when neither option is given; throws with a clear message for a
  // missing or unreadable file, non-finite pixels, or a negative or NaN intensity or sky value.
  std::shared_ptr<const renderer::Environment> load() const {
    if (!given()) return nullptr;
    auto env = std::make_shared<renderer::Environment>();
    std::string error;
    const bool ok = !file.empty() ? renderer::loadEnvironment(file, intensity, rotationDeg, *env, error)
                                  : renderer::makeUniformSky({sky[0], sky[1], sky[2]}, *env, error);
    if (!ok) throw std::runtime_error((!file.empty() ? "--environment: " : "--sky: ") + error);
    return env;
  }
};

// The distant light a stream's scene package names (service::SceneLighting), with its map at `file`.
inline std::shared_ptr<const renderer::Environment> loadLighting(const service::SceneLighting& lighting,
                                                                const std::filesystem::path& file) {
  if (lighting.kind == service::SceneLighting::Kind::None) return nullptr;
  auto env = std::make_shared<renderer::Environment>();
  std::string error;
  const bool ok = lighting.kind == service::SceneLighting::Kind::Environment
                      ? renderer::loadEnvironment(file.string(), lighting.intensity, lighting.rotationDeg, *env, error)
                      : renderer::makeUniformSky({lighting.sky[0], lighting.sky[1], lighting.sky[2]}, *env, error);
  if (!ok) throw std::runtime_error("the stream's lighting: " + error);
  return env;
}

struct SceneOptions {
  std::string scene = "builtin:cornell";
  float t = 0.0f;
  EnvironmentOptions environment;
  CLI::Option* sceneOption = nullptr;
  CLI::Option* tOption = nullptr;
  void add(CLI::App* cmd) {
    sceneOption = cmd->add_option("--scene", scene, "glTF file or builtin:NAME (cornell, closed-box, thin-wall, hall)");
    tOption = cmd->add_option("--time,--t", t,
                              "scene time, seconds (built-in scenes move their light once around per second; glTF "
                              "animations loop over their longest clip)")
                  ->check(CLI::Range(0.0f, 1.0e6f));
    environment.add(cmd);
  }
  bool sceneGiven() const { return sceneOption && sceneOption->count() > 0; }
  scene::Scene load() const { return session::loadSceneOrThrow(scene, t); }
  // The scene package (scene_package.h) these options name: what descriptions and probe files carry.
  service::ScenePackage package() const {
    service::ScenePackage p;
    std::string error;
    if (!service::makeScenePackage(scene, environment.request(), p, error)) throw std::runtime_error(error);
    return p;
  }
};

}  // namespace probecast::app
