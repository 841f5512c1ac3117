// How probes are traced: --spp, --bounces, --seed, the temporal filter and the ray budget.
#pragma once

#include <cstdint>

#include <CLI/CLI.hpp>

#include "options/common.h"
#include "probecast/renderer/probe_updater.h"

namespace probecast::app {

struct TracerOptions {
  uint32_t spp = 128;
  uint32_t bounces = 4;
  uint32_t seed = 1;
  float wMin = renderer::UpdaterOptions{}.minBlendWeight;
  float rejectSigmas = 4.0f;
  float neighbourHistory = renderer::UpdaterOptions{}.neighbourHistory;
  float changeHistory = renderer::UpdaterOptions{}.changeHistory;
  float clamp = 16.0f;
  bool relocate = true;
  bool refit = true;
  bool surfaceProbesOnly = true;
  uint64_t raysPerUpdate = 0;
  void add(CLI::App* cmd) {
    addSppOption(cmd, spp);
    cmd->add_option("--rays-per-update", raysPerUpdate,
                    "paths per update spent over the probes by need (in view, light changed, noisy), in multiples of "
                    "32; at most 8x --spp per probe (a larger budget is capped); 0 = every probe traces --spp");
    cmd->add_option("--bounces", bounces, "surface interactions per path")->check(CLI::Range(1, 16));
    cmd->add_option("--seed", seed, "random seed (same seed, same result)");
    cmd->add_option("--w-min", wMin, "minimum temporal blend weight (0: a true mean until the history restarts or the scene changes)")
        ->check(CLI::Range(0.0f, 1.0f));
    cmd->add_option("--reject-sigmas", rejectSigmas,
                    "restart a probe's history when new estimates differ by more than this many standard errors (0 = never)")
        ->check(CLI::Range(0.0f, 1000.0f));
    cmd->add_option("--neighbour-history", neighbourHistory,
                    "the neighbours of a probe whose history restarts keep at most this many updates of theirs (0 = "
                    "off)")
        ->check(CLI::Range(0.0f, 1e6f));
    cmd->add_option("--change-history", changeHistory,
                    "when the scene's lights, materials or geometry change, every probe keeps at most this many "
                    "updates of history (0 = off)")
        ->check(CLI::Range(0.0f, 1e6f));
    cmd->add_option("--clamp", clamp, "max luminance of an indirect contribution (0 = off)")->check(CLI::Range(0.0f, 1e9f));
    cmd->add_flag("--relocate,!--no-relocate", relocate,
                  "move probes inside or too close to geometry (up to 45 % of a cell per axis) instead of only "
                  "switching them off (default on)");
    cmd->add_flag("--refit,!--no-refit", refit,
                  "moving geometry (animated glTF): refit the acceleration structures of the moving triangles in "
                  "place instead of building all of them anew on every move (default on)");
    cmd->add_flag("--surface-probes-only,!--all-probes", surfaceProbesOnly,
                  "trace and send only the probes that light some surface (a triangle passes through the cells "
                  "around them); the others light no pixel and stay off (default on)");
  }
  renderer::UpdaterOptions options() const {
    renderer::UpdaterOptions o;
    o.samplesPerProbe = spp;
    o.maxBounces = bounces;
    o.seed = seed;
    o.minBlendWeight = wMin;
    o.rejectSigmas = rejectSigmas;
    o.neighbourHistory = neighbourHistory;
    o.changeHistory = changeHistory;
    o.indirectClamp = clamp;
    o.relocate = relocate;
    o.refitMovingGeometry = refit;
    o.surfaceProbesOnly = surfaceProbesOnly;
    o.raysPerUpdate = raysPerUpdate;
    return o;
  }
};

}  // namespace probecast::app
