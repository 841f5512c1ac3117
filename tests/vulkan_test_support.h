// Shared by the Vulkan tests: a context with the validation layer on, built-in scenes, a camera.
#pragma once

#include <stdexcept>
#include <string>

#include "probecast/renderer/reference_camera.h"
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

// The camera at the origin looking down −Z with a 90° square view: a square of half-size 1 at
// z = −1 fills the image, and pixel (x, y) sees texture coordinates ((x + ½)/W, (y + ½)/H).
inline renderer::CameraView frontCamera() {
  renderer::CameraView c;
  c.position = glm::vec3(0.0f);
  c.forward = {0, 0, -1};
  c.up = {0, 1, 0};
  c.yfov = 1.5707963f;
  return c;
}

}  // namespace probecast::test
