#include "probecast/session/scene_loading.h"

#include <stdexcept>

#include "probecast/scene/animation.h"

namespace probecast::session {

scene::Scene loadSceneOrThrow(const std::string& spec, double seconds, const scene::PackagedFiles* packaged) {
  scene::Scene s;
  std::string error;
  if (!scene::loadScene(spec, seconds, s, error, packaged)) throw std::runtime_error(error);
  return s;
}

namespace {
bool builtin(const std::string& spec) { return spec.rfind("builtin:", 0) == 0; }
}  // namespace

bool sceneMoves(const std::string& spec, const scene::Scene& scene) {
  return builtin(spec) || scene::sceneAnimates(scene);
}

void advanceScene(const std::string& spec, double seconds, scene::Scene& scene) {
  if (scene.rig) scene::poseScene(scene, seconds);
  else if (builtin(spec)) scene = loadSceneOrThrow(spec, seconds);
}

}  // namespace probecast::session
