// Which probes of a grid light any surface (UpdaterOptions::surfaceProbesOnly).
//
// A viewer lights a surface point from the eight probes of its grid cell, weighted trilinearly
// (raster.frag), a point outside the grid's box taking the cell it clamps to. A probe therefore
// lights nothing unless some triangle passes through the open box of the cells around it: one
// probe spacing either way on each axis, reaching to infinity on the sides where the probe is
// the last of the grid. The box is taken a hair smaller (kSurfaceBoxSlack of a spacing), so that
// a wall lying exactly on the next probes' plane, where this probe's weight is zero, does not count.
// The probe updater's path tracing never reads the probes (paths are traced in full), so a probe
// that lights no surface is traced and sent for nobody.
#pragma once

#include <cstdint>
#include <vector>

#include "probecast/codec/probe_volume.h"
#include "probecast/scene/scene.h"

namespace probecast::renderer {

constexpr float kSurfaceBoxSlack = 1e-4f;

// One byte per probe (grid order): 1 when some triangle of `scene` meets the probe's box.
std::vector<uint8_t> probesNearSurfaces(const scene::Scene& scene, const ProbeGrid& grid);

// Whether the triangle (a, b, c) meets the closed box of the given centre and half extents
// (separating axes: the box's faces, the triangle's plane and the nine edge cross products).
bool triangleMeetsBox(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& centre,
                      const glm::vec3& half);

}  // namespace probecast::renderer
