// The Vulkan device a command traces and draws on: --device, --validation.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "probecast/renderer/vulkan_context.h"

namespace probecast::app {

// --device auto|gpu|cpu and --validation: the Vulkan device probes are traced and views drawn on.
struct DeviceOptions {
  renderer::DeviceChoice device = renderer::DeviceChoice::Auto;
  bool validation = false;
  void add(CLI::App* cmd) {
    cmd->add_option_function<std::string>(
           "--device",
           [this](const std::string& text) {
             if (!renderer::parseDeviceChoice(text, device))
               throw CLI::ValidationError("--device", "'" + text + "' is not auto, gpu or cpu");
           },
           "auto: a GPU when one is present, lavapipe otherwise (ray tracing only where probes are traced here); gpu "
           "or cpu: that kind or an error")
        ->default_str("auto");
    cmd->add_flag("--validation", validation, "enable the Vulkan validation layer");
  }
  // `rayTracing` off: for raster-only work (viewers), so devices without ray tracing qualify.
  renderer::ContextOptions context(bool rayTracing = true) const {
    renderer::ContextOptions o;
    o.device = device;
    o.validation = validation;
    o.rayTracing = rayTracing;
    return o;
  }
};

}  // namespace probecast::app
