// Every conversion between the probe-volume types of the codec (ProbeVolume, StreamLayout +
// GridBounds), the service (HubConfig, VolumeSnapshot) and the renderer (ProbeGrid,
// ProbeVolumeData) that the commands and benchmarks need, in one place.
#pragma once

#include <cstdint>
#include <vector>

#include "probecast/codec/probe_file.h"
#include "probecast/codec/record.h"
#include "probecast/codec/stream.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/scene/scene.h"
#include "probecast/service/client.h"
#include "probecast/service/probe_hub.h"

namespace probecast::session {

// A grid of `dims` probes at the centres of its cells over the scene's bounds.
renderer::ProbeGrid cellCentredGrid(const scene::Scene& scene, glm::uvec3 dims);
// dims probes from (0, 0, 0) to dims − 1, one metre apart.
renderer::ProbeGrid unitGrid(glm::uvec3 dims);

// The stream layout of `grid` as `repr` in bricks of `brick`³ probes.
StreamLayout streamLayoutFor(const renderer::ProbeGrid& grid, Representation repr, int brick = 4);
// A hub streaming `grid` as `repr` in bricks of `brick`³ probes, dropping changes up to `deadzone` steps.
service::HubConfig hubConfigFor(const renderer::ProbeGrid& grid, Representation repr, int brick, int deadzone);
// The same for a baked probe volume file.
service::HubConfig hubConfigFor(const ProbeVolume& file, Representation repr, int brick, int deadzone);

// What a client holds, as the raster client takes it (moves the probes out of `snapshot`).
renderer::ProbeVolumeData volumeFromSnapshot(service::VolumeSnapshot&& snapshot);
// A baked probe volume file as the raster client takes it (moves the probes out of `file`).
renderer::ProbeVolumeData volumeFromFile(ProbeVolume&& file);
// The updater's probes over `grid` as a probe volume file (updates and samples left for the caller).
ProbeVolume fileFromUpdater(const renderer::ProbeUpdater& updater, const renderer::ProbeGrid& grid);
// What a client holds, as a probe volume file.
ProbeVolume fileFromSnapshot(const service::VolumeSnapshot& snapshot);

// Whether `snapshot` holds exactly `probes` and `active` (a zh3h client decoding L1 only holds
// the first 12 floats of each probe: only those are compared).
bool holdsVolume(const service::VolumeSnapshot& snapshot, const std::vector<float>& probes,
                 const std::vector<uint8_t>& active);

}  // namespace probecast::session
