#include "probecast/session/scene_loading.h"

#include <stdexcept>

namespace probecast::session {

scene::Scene loadSceneOrThrow(const std::string& spec, float t) {
  scene::Scene s;
  std::string error;
  if (!scene::loadScene(spec, t, s, error)) throw std::runtime_error(error);
  return s;
}

bool sceneAnimates(const std::string& spec) { return spec.rfind("builtin:", 0) == 0; }

}  // namespace probecast::session
