#include "probecast/session/volumes.h"

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

}  // namespace probecast::session
