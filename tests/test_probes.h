// Probe generators shared by the tests.
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "probecast/codec/sh.h"

namespace probecast::test {

using Probe = std::array<float, kProbeFloats>;

// SH of a unit-intensity delta (all energy from one direction): coefficients Y(d).
Probe deltaProbe(float x, float y, float z, const float rgb[3]);

// A random non-negative radiance function: a sum of `lobes` weighted deltas plus ambient.
// Every such probe satisfies the ratio bounds of docs/CODEC.md §3.
Probe randomNonNegativeProbe(std::mt19937& rng, int lobes, float ambient);

// Uniform random unit vector.
void randomDirection(std::mt19937& rng, float d[3]);

// Grid of `count` probes that look like a lit room: ambient + one moving light lobe, scaled by
// distance, with multiplicative noise of relative size `noise` (like path-tracing noise).
std::vector<float> movingLightFrame(int count, int frame, float noise, std::mt19937& rng);

}  // namespace probecast::test
