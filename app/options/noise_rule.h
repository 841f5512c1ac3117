// The noise-aware stream: --noise-scale and --refinement-interval.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "probecast/codec/stream.h"

namespace probecast::app {

// The noise-aware stream of serve and demo (EncoderOptions::noiseScale and refinementInterval):
// a probe is re-sent only when its change exceeds what its Monte Carlo noise explains, and
// refinements of probes whose light held still wait for every Kth update. On by default wherever
// probes are traced live (docs/MEASUREMENTS.md, "Defaults", has the figures behind these values);
// --noise-scale 0 turns it off, and the refinement interval with it unless one is given.
inline constexpr float kNoiseScaleDefault = 1.6f;
inline constexpr uint32_t kRefinementIntervalDefault = 8;

struct NoiseRuleCli {
  float scale = kNoiseScaleDefault;
  uint32_t refinementInterval = kRefinementIntervalDefault;
  CLI::Option* scaleOption = nullptr;
  CLI::Option* intervalOption = nullptr;
  void add(CLI::App* cmd) {
    scaleOption = cmd->add_option("--noise-scale", scale,
                                  "live tracing: a probe is not re-sent while its change stays within this many "
                                  "standard errors of its Monte Carlo noise (0 = off)")
                      ->check(CLI::Range(0.0f, 1000.0f))
                      ->capture_default_str();
    intervalOption = cmd->add_option("--refinement-interval", refinementInterval,
                                     "with the noise rule: refinements (changes within twice the noise threshold of "
                                     "probes whose light held still this many updates) wait for the next update "
                                     "whose sequence is a multiple of this, every brick's going in that one frame "
                                     "(0 = at once)")
                         ->check(CLI::Range(0u, 100000u))
                         ->capture_default_str();
  }
  bool scaleGiven() const { return scaleOption && scaleOption->count() > 0; }
  bool intervalGiven() const { return intervalOption && intervalOption->count() > 0; }
  // The rule into `encoder`: as given (or the defaults) for live tracing; off for probes from a
  // file, which carry no per-probe noise. Throws std::runtime_error when what was given cannot
  // hold: a scale for a file, or a refinement interval with the rule off.
  void apply(EncoderOptions& encoder, bool live) const {
    if (!live && scaleGiven() && scale > 0.0f)
      throw std::runtime_error("--noise-scale needs live tracing: a --probes file carries no per-probe noise");
    const bool on = live && scale > 0.0f;
    if (!on && intervalGiven() && refinementInterval > 0)
      throw std::runtime_error("--refinement-interval holds back what the noise rule calls refinements, and the rule is " +
                               std::string(live ? "off (--noise-scale 0)" : "off for a --probes file"));
    encoder.noiseScale = on ? scale : 0.0f;
    encoder.refinementInterval = on ? refinementInterval : 0;
  }
};

}  // namespace probecast::app
