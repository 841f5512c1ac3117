// Loading a scene where a failure ends the command: one place for "load or throw".
#pragma once

#include <string>

#include "probecast/scene/scene.h"

namespace probecast::session {

// The scene `spec` (glTF path or builtin:NAME) at scene time `seconds`; throws
// std::runtime_error with the loader's message when it cannot be loaded.
scene::Scene loadSceneOrThrow(const std::string& spec, double seconds, const scene::PackagedFiles* packaged = nullptr);

// Whether `scene` (loaded from `spec`) changes with the scene time: the built-ins move their light,
// glTF files with animation move nodes, skins and morph targets (scene/animation.h).
bool sceneMoves(const std::string& spec, const scene::Scene& scene);

// `scene` (loaded from `spec`) at scene time `seconds`: a glTF scene is posed in place, a built-in
// made again. Nothing happens to a scene that does not move.
void advanceScene(const std::string& spec, double seconds, scene::Scene& scene);

}  // namespace probecast::session
