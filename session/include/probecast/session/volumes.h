// What the commands and benchmarks need of probe volumes beyond the codec's ProbeVolume: a grid
// for generated (not traced) lighting, and whether a viewer holds what the server has.
#pragma once

#include <glm/glm.hpp>

#include "probecast/codec/probe_volume.h"

namespace probecast::session {

// dims probes from (0, 0, 0) to dims − 1, one metre apart.
ProbeGrid unitGrid(glm::uvec3 dims);

// Whether `held` (a viewer's snapshot) holds exactly the samples and mask of `server` (the hub's
// reconstruction). A zh3PerPixel holder has the first 12 floats of each probe: only those count.
bool holdsVolume(const ProbeVolume& held, const ProbeVolume& server);

}  // namespace probecast::session
