// Scene, device, grid and tracer options together, for the commands that trace probes.
#pragma once

#include <memory>

#include <CLI/CLI.hpp>

#include "options/device.h"
#include "options/grid.h"
#include "options/scene.h"
#include "options/tracer.h"
#include "probecast/renderer/environment.h"

namespace probecast::app {

// Scene, device, grid and tracer options together, for the commands that trace probes.
struct TracingOptions {
  SceneOptions scene;
  DeviceOptions device;
  GridOptions grid;
  TracerOptions tracer;
  void add(CLI::App* cmd, bool withTracer = true) {
    scene.add(cmd);
    device.add(cmd);
    grid.add(cmd);
    if (withTracer) tracer.add(cmd);
  }
  // The tracer's options lit by `environment` (SceneOptions::environment, loaded once).
  renderer::UpdaterOptions updater(const std::shared_ptr<const renderer::Environment>& environment) const {
    renderer::UpdaterOptions o = tracer.options();
    o.environment = environment;
    return o;
  }
};

}  // namespace probecast::app
