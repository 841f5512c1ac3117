#include "probecast/session/volumes.h"

namespace probecast::session {

renderer::ProbeGrid cellCentredGrid(const scene::Scene& s, glm::uvec3 dims) {
  renderer::ProbeGrid g;
  g.dims = dims;
  const glm::vec3 cell = (s.boundsMax - s.boundsMin) / glm::vec3(dims);
  g.min = s.boundsMin + 0.5f * cell;
  g.max = s.boundsMax - 0.5f * cell;
  return g;
}

renderer::ProbeGrid unitGrid(glm::uvec3 dims) {
  renderer::ProbeGrid g;
  g.dims = dims;
  g.min = glm::vec3(0.0f);
  g.max = glm::vec3(dims) - glm::vec3(1.0f);
  return g;
}

StreamLayout streamLayoutFor(const renderer::ProbeGrid& grid, Representation repr, int brick) {
  StreamLayout layout;
  for (int a = 0; a < 3; ++a) layout.grid[a] = static_cast<uint16_t>(grid.dims[a]);
  layout.brickDim = static_cast<uint8_t>(brick);
  layout.repr = repr;
  return layout;
}

service::HubConfig hubConfigFor(const renderer::ProbeGrid& grid, Representation repr, int brick, int deadzone) {
  service::HubConfig hc;
  hc.layout = streamLayoutFor(grid, repr, brick);
  hc.encoder.deadzone = deadzone;
  for (int a = 0; a < 3; ++a) {
    hc.bounds.min[a] = grid.min[a];
    hc.bounds.max[a] = grid.max[a];
  }
  return hc;
}

service::HubConfig hubConfigFor(const ProbeVolume& file, Representation repr, int brick, int deadzone) {
  renderer::ProbeGrid g;
  g.dims = {file.dims[0], file.dims[1], file.dims[2]};
  g.min = {file.boundsMin[0], file.boundsMin[1], file.boundsMin[2]};
  g.max = {file.boundsMax[0], file.boundsMax[1], file.boundsMax[2]};
  return hubConfigFor(g, repr, brick, deadzone);
}

renderer::ProbeVolumeData volumeFromSnapshot(service::VolumeSnapshot&& snap) {
  renderer::ProbeVolumeData v;
  v.dims = {snap.layout.grid[0], snap.layout.grid[1], snap.layout.grid[2]};
  v.min = {snap.bounds.min[0], snap.bounds.min[1], snap.bounds.min[2]};
  v.max = {snap.bounds.max[0], snap.bounds.max[1], snap.bounds.max[2]};
  v.probes = std::move(snap.probes);
  v.active = std::move(snap.active);
  v.hallucinateZh3 = snap.l1Only;
  return v;
}

renderer::ProbeVolumeData volumeFromFile(ProbeVolume&& file) {
  renderer::ProbeVolumeData v;
  v.dims = {file.dims[0], file.dims[1], file.dims[2]};
  v.min = {file.boundsMin[0], file.boundsMin[1], file.boundsMin[2]};
  v.max = {file.boundsMax[0], file.boundsMax[1], file.boundsMax[2]};
  v.probes = std::move(file.probes);
  v.active = std::move(file.active);
  return v;
}

ProbeVolume fileFromUpdater(const renderer::ProbeUpdater& updater, const renderer::ProbeGrid& g) {
  ProbeVolume volume;
  for (int a = 0; a < 3; ++a) {
    volume.dims[a] = g.dims[a];
    volume.boundsMin[a] = g.min[a];
    volume.boundsMax[a] = g.max[a];
  }
  volume.probes.assign(updater.probes(), updater.probes() + static_cast<size_t>(g.count()) * kProbeFloats);
  volume.active.assign(updater.activeMask(), updater.activeMask() + g.count());
  return volume;
}

ProbeVolume fileFromSnapshot(const service::VolumeSnapshot& snap) {
  ProbeVolume v;
  for (int a = 0; a < 3; ++a) {
    v.dims[a] = snap.layout.grid[a];
    v.boundsMin[a] = snap.bounds.min[a];
    v.boundsMax[a] = snap.bounds.max[a];
  }
  v.probes = snap.probes;
  v.active = snap.active;
  return v;
}

bool holdsVolume(const service::VolumeSnapshot& snap, const std::vector<float>& probes,
                 const std::vector<uint8_t>& active) {
  if (snap.active != active || snap.probes.size() != probes.size()) return false;
  for (size_t i = 0; i < snap.probes.size(); ++i)
    if (!(snap.l1Only && i % kProbeFloats >= 12) && snap.probes[i] != probes[i]) return false;
  return true;
}

}  // namespace probecast::session
