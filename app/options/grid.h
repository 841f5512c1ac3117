// The probe grid: --grid and --bounds.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <CLI/CLI.hpp>

#include "probecast/renderer/probe_updater.h"
#include "probecast/scene/scene.h"

namespace probecast::app {

struct GridOptions {
  std::vector<uint32_t> dims{8, 8, 8};
  std::vector<float> bounds;  // empty: cell-centred in the scene bounds
  // --grid (each count in [minDim, maxDim]) and, when withBounds, --bounds.
  void add(CLI::App* cmd, bool withBounds = true, uint32_t minDim = 1, uint32_t maxDim = 1024) {
    cmd->add_option("--grid", dims, "probes along X,Y,Z")->delimiter(',')->expected(3)->check(CLI::Range(static_cast<int>(minDim), static_cast<int>(maxDim)));
    if (!withBounds) return;
    cmd->add_option("--bounds", bounds, "minX,minY,minZ,maxX,maxY,maxZ of the first and last probe (metres)")
        ->delimiter(',')
        ->expected(6);
  }
  // The grid: the first and last probe at --bounds, or cell-centred over the scene's bounds.
  ProbeGrid resolve(const scene::Scene& s) const {
    if (static_cast<uint64_t>(dims[0]) * dims[1] * dims[2] > (1u << 24)) throw std::runtime_error("grid too large");
    if (bounds.size() != 6) return renderer::sceneGrid(s, {dims[0], dims[1], dims[2]});
    for (float b : bounds)
      if (!std::isfinite(b)) throw std::runtime_error("--bounds must be finite");
    return ProbeGrid{{dims[0], dims[1], dims[2]}, {{bounds[0], bounds[1], bounds[2]}, {bounds[3], bounds[4], bounds[5]}}};
  }
};

}  // namespace probecast::app
