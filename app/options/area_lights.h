// Client area lights: --area-lights and --area-light-min.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "probecast/scene/area_lights.h"
#include "probecast/session/volumes.h"

namespace probecast::app {

// --area-lights on|off: emitters viewers shade themselves (scene/area_lights.h), left out of the
// probes traced here; the rule travels with the probes (file, stream, bus) so viewers follow it.
// A viewer of probes from a file or a server also takes "auto" (its default): light by the rule
// the probes state. on or off there must agree with the probes (a clear error otherwise: light
// would be counted twice or lost), and so must an --area-light-min given.
// Where probes are traced (view --probes live, serve, bake, demo) and --area-lights is not given:
// on, so emitters above --area-light-min are shaded by the viewers with soft shadows (a scene
// without such emitters has none either way). docs/MEASUREMENTS.md, "Defaults", has the figures.
inline constexpr char kAreaLightsDefault[] = "on";

struct AreaLightCli {
  std::string mode;
  float minFraction = 0.05f;
  CLI::Option* minOption = nullptr;
  AreaLightCli(std::string defaultMode = kAreaLightsDefault) : mode(std::move(defaultMode)) {}
  void add(CLI::App* cmd, bool follows = false) {
    std::vector<std::string> modes{"on", "off"};
    if (follows) modes.push_back("auto");
    cmd->add_option("--area-lights", mode,
                    "on: emissive surfaces become area lights the raster client shades with soft shadows, and the "
                    "probes traced here leave their direct light out" +
                        std::string(follows ? "; auto: as the probes say (live: " + std::string(kAreaLightsDefault) +
                                                  ")"
                                            : ""))
        ->check(CLI::IsMember(modes))
        ->capture_default_str();
    minOption = cmd->add_option("--area-light-min", minFraction,
                                "smallest share of the scene's emitted power an area light has")
                    ->check(CLI::Range(0.0f, 1.0f))
                    ->capture_default_str();
  }
  // Options for probes traced here ("auto": the default).
  scene::AreaLightOptions options() const {
    scene::AreaLightOptions o;
    o.enabled = (mode == "auto" ? std::string(kAreaLightsDefault) : mode) == "on";
    o.minPowerFraction = minFraction;
    return o;
  }
  // A viewer of probes made elsewhere (`source`): the options of their rule, or std::runtime_error
  // when what was asked for disagrees with it (session::followAreaLightRule).
  scene::AreaLightOptions follow(const AreaLightRule& rule, const std::string& source) const {
    return session::followAreaLightRule(rule, mode == "auto" ? std::nullopt : std::optional<bool>(mode == "on"),
                                        minOption && minOption->count() > 0 ? std::optional<float>(minFraction)
                                                                           : std::nullopt,
                                        source);
  }
};

}  // namespace probecast::app
