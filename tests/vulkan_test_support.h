// Shared by the Vulkan tests: a context with the validation layer on, and built-in scenes.
#pragma once

#include <stdexcept>
#include <string>

#include "probecast/renderer/vulkan_context.h"
#include "probecast/scene/scene.h"

namespace probecast::test {

inline renderer::ContextOptions validatedContext() {
  renderer::ContextOptions co;
  co.validation = true;
  return co;
}

inline scene::Scene builtinScene(const std::string& name, float t = 0.0f) {
  scene::Scene s;
  std::string error;
  if (!scene::makeBuiltinScene(name, t, s, error)) throw std::runtime_error(error);
  return s;
}

}  // namespace probecast::test
