// What the commands and benchmarks need of probe volumes beyond the codec's ProbeVolume: a grid
// for generated (not traced) lighting, and whether a viewer holds what the server has.
#pragma once

#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "probecast/codec/probe_volume.h"
#include "probecast/scene/area_lights.h"

namespace probecast::session {

// dims probes from (0, 0, 0) to dims − 1, one metre apart.
ProbeGrid unitGrid(glm::uvec3 dims);

// Whether `held` (a viewer's snapshot) holds exactly the samples and mask of `server` (the hub's
// reconstruction). A zh3PerPixel holder has the first 12 floats of each probe: only those count.
bool holdsVolume(const ProbeVolume& held, const ProbeVolume& server);

// The rule a producer states for the client area lights its probes leave out, and the options a
// viewer lights by for a stated rule: the two are the same decision (area_lights.h), so a viewer
// that follows the rule lights exactly what the probes lack. Rule 1 fixes the caps at the
// defaults of AreaLightOptions; other caps, or a threshold outside [0, 1], throw
// std::invalid_argument, as does a rule this build does not know.
AreaLightRule areaLightRuleOf(const scene::AreaLightOptions& options);
scene::AreaLightOptions areaLightOptionsOf(const AreaLightRule& rule);
// The options a viewer lights probes by whose producer stated `rule`. `wanted` (on or off) and
// `wantedMin` (a threshold), when given, must agree with the rule: otherwise std::runtime_error
// naming `source` (light would be counted twice or lost); nullopt follows the probes.
scene::AreaLightOptions followAreaLightRule(const AreaLightRule& rule, std::optional<bool> wanted,
                                            std::optional<float> wantedMin, const std::string& source);

}  // namespace probecast::session
