// The scene a stream names and the state it carries, between probecast's scene types and the
// service's: the package a command's options make, the lights of a frame's scene state, and the
// scene a viewer draws for a stream (its own copy, checked, or the one the server delivers).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "probecast/scene/scene.h"
#include "probecast/service/bus_format.h"
#include "probecast/service/client.h"
#include "probecast/service/scene_package.h"

namespace probecast::session {

// The stamp a volume or description carries for `package` (hash and manifest) at `time`.
SceneStamp stampOf(const service::ScenePackage& package, double time);

// The lights of `scene` as a frame's scene state carries them (directions normalised).
std::vector<bus::LightState> lightStates(const scene::Scene& scene);
// The state of `scene` at scene time `time`, playing at `rate`, the producer's wall clock `clockUs`.
bus::SceneState sceneStateOf(const scene::Scene& scene, double time, double rate, uint64_t clockUs);
// Replaces the scene's punctual lights with a state's (a viewer that does not know the animation
// draws the lights the server traced with).
void applyLights(const bus::SceneState& state, scene::Scene& scene);

// Scene time → the built-in scenes' animation parameter t in [0, 1) (one turn per scene second).
float animationT(double sceneTime);

// What a viewer knows of the scene it draws for a stream.
struct ViewerScene {
  std::string spec;      // for loadScene: builtin:NAME or a glTF path on this machine
  // A delivered or cached package's glTF: the only files it may read (loadScene's `packaged`);
  // empty for a built-in or the viewer's own --scene.
  std::optional<scene::PackagedFiles> packaged;
  std::optional<service::SceneHash> hash;  // the stream's scene (ClientConfig::scene); none when it names none
  std::filesystem::path environmentFile;  // the stream's environment map here (empty: none)
  service::SceneLighting lighting;        // the stream's lighting (or the viewer's own)
  bool checked = false;  // the stream named its scene and it matched (or was delivered)
  double time = 0.0;     // the stream's scene time when it was described
  std::string note;      // one line for the user: what was checked, fetched or assumed
};

struct SceneChoice {
  std::string localSpec;  // --scene given (empty: none)
  service::LightingRequest localLighting;  // --environment / --sky given (empty: none)
  std::filesystem::path cache;             // where fetched scenes are kept
  uint64_t maxBytes = 0;                   // largest scene fetched
};

// The scene a viewer of `stamp` (a description's; unknown when the server names none) draws:
// - a local --scene: its package must match the stream's scene (its lighting too when the viewer
//   gives its own); otherwise std::runtime_error naming both hashes;
// - none: the stream's, from the cache or fetched from the server (fetch says how);
// - an unknown stamp: the local scene unchecked (none given: std::runtime_error).
ViewerScene resolveViewerScene(const SceneStamp& stamp, const SceneChoice& choice,
                               const service::ClientConfig& client, service::SceneFetch& fetch);

}  // namespace probecast::session
