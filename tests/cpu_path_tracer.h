// A plain C++ path tracer of probes for cross-checking the Vulkan updater: brute-force
// ray/triangle tests, the same material model and path rules, independent sampling (uniform
// random directions instead of a rotated Fibonacci set, std::mt19937 instead of PCG).
#pragma once

#include <array>
#include <cstdint>

#include "probecast/scene/scene.h"

namespace probecast::test {

struct CpuTraceOptions {
  uint32_t samples = 16384;
  uint32_t maxBounces = 4;
  uint32_t seed = 1;
};

// L2 SH (sh.h layout) of the radiance arriving at `position`.
std::array<double, 27> cpuTraceProbe(const scene::Scene& scene, const glm::vec3& position, const CpuTraceOptions& options);

}  // namespace probecast::test
