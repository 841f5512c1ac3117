// Loading a scene where a failure ends the command: one place for "load or throw".
#pragma once

#include <string>

#include "probecast/scene/scene.h"

namespace probecast::session {

// The scene `spec` (glTF path or builtin:NAME) at animation parameter t; throws
// std::runtime_error with the loader's message when it cannot be loaded.
scene::Scene loadSceneOrThrow(const std::string& spec, float t);

// Whether the scene moves its light with t (the built-in scenes do; glTF files do not).
bool sceneAnimates(const std::string& spec);

}  // namespace probecast::session
