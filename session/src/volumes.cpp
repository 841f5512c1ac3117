#include "probecast/session/volumes.h"

#include <stdexcept>

namespace probecast::session {

ProbeGrid unitGrid(glm::uvec3 dims) {
  return ProbeGrid{{dims.x, dims.y, dims.z},
                   {{0, 0, 0}, {static_cast<float>(dims.x - 1), static_cast<float>(dims.y - 1),
                                static_cast<float>(dims.z - 1)}}};
}

bool holdsVolume(const ProbeVolume& held, const ProbeVolume& server) {
  if (held.active != server.active || held.probes.size() != server.probes.size()) return false;
  for (size_t i = 0; i < held.probes.size(); ++i)
    if (!(held.zh3PerPixel && i % kProbeFloats >= 12) && held.probes[i] != server.probes[i]) return false;
  return true;
}

AreaLightRule areaLightRuleOf(const scene::AreaLightOptions& o) {
  if (!o.enabled) return {};
  const scene::AreaLightOptions defaults;
  if (o.maxLights != defaults.maxLights || o.maxTriangles != defaults.maxTriangles)
    throw std::invalid_argument("client area lights: rule " + std::to_string(kAreaLightRuleVersion) + " caps them at " +
                                std::to_string(defaults.maxLights) + " lights and " +
                                std::to_string(defaults.maxTriangles) + " triangles; viewers could not follow others");
  const AreaLightRule rule{kAreaLightRuleVersion, o.minPowerFraction};
  std::string error;
  if (!checkAreaLightRule(rule, error)) throw std::invalid_argument(error);
  return rule;
}

scene::AreaLightOptions areaLightOptionsOf(const AreaLightRule& rule) {
  std::string error;
  if (!checkAreaLightRule(rule, error)) throw std::invalid_argument(error);
  scene::AreaLightOptions o;
  o.enabled = rule.on();
  if (rule.on()) o.minPowerFraction = rule.minPowerFraction;
  return o;
}

scene::AreaLightOptions followAreaLightRule(const AreaLightRule& rule, std::optional<bool> wanted,
                                            std::optional<float> wantedMin, const std::string& source) {
  if (wanted && *wanted != rule.on())
    throw std::runtime_error(
        std::string("client area lights ") + (*wanted ? "on" : "off") + " asked for, but the probes of " + source +
        (rule.on() ? " leave emitters out for viewers to light (made with --area-lights on): without them their "
                     "direct light would be lost"
                   : " hold every emitter (made with --area-lights off): lighting them here would count their light "
                     "twice") +
        "; leave --area-lights out to follow the probes");
  if (wantedMin && rule.on() && *wantedMin != rule.minPowerFraction)
    throw std::runtime_error("client area lights above " + std::to_string(*wantedMin) + " of the emitted power asked "
                             "for, but the probes of " + source + " were made with " +
                             std::to_string(rule.minPowerFraction));
  return areaLightOptionsOf(rule);
}

}  // namespace probecast::session
