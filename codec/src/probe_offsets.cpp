// Probe relocation offsets and their one-byte-per-axis form (probe_offsets.h).
#include "probecast/codec/probe_offsets.h"

#include <algorithm>
#include <cmath>

namespace probecast {
namespace {

const char* const kAxis[3] = {"x", "y", "z"};

// The one rule both sides use: q/256 is exact in float, so the only rounding is the product.
float stepsToMetres(int q, float cell) { return cell * (static_cast<float>(q) / static_cast<float>(kOffsetStepsPerCell)); }

}  // namespace

float probeCellSize(const ProbeGrid& grid, int axis) {
  if (grid.dims[axis] < 2) return 0.0f;
  return (grid.bounds.max[axis] - grid.bounds.min[axis]) / static_cast<float>(grid.dims[axis] - 1);
}

bool checkProbeOffsets(const ProbeGrid& grid, const std::vector<float>& offsets, std::string& error) {
  if (offsets.empty()) return true;
  const uint64_t count = grid.count();
  if (offsets.size() != count * 3)
    return error = "probe offsets: " + std::to_string(offsets.size()) + " floats for " + std::to_string(count) +
                   " probes (3 each, or none)",
           false;
  const float cell[3] = {probeCellSize(grid, 0), probeCellSize(grid, 1), probeCellSize(grid, 2)};
  for (size_t i = 0; i < offsets.size(); ++i) {
    const int a = static_cast<int>(i % 3);
    const float o = offsets[i];
    if (!std::isfinite(o))
      return error = "probe offsets: probe " + std::to_string(i / 3) + " has a non-finite " + kAxis[a] + " offset",
             false;
    if (!(std::fabs(o) <= 0.5f * cell[a]))
      return error = "probe offsets: probe " + std::to_string(i / 3) + " moves " + std::to_string(o) + " m along " +
                     kAxis[a] + ", more than half its cell (" + std::to_string(cell[a]) + " m)",
             false;
  }
  return true;
}

std::vector<int8_t> quantizeProbeOffsets(const ProbeGrid& grid, const std::vector<float>& offsets) {
  std::vector<int8_t> q(offsets.size());
  for (size_t i = 0; i < offsets.size(); ++i) {
    const float cell = probeCellSize(grid, static_cast<int>(i % 3));
    const float steps = cell > 0.0f ? offsets[i] / cell * static_cast<float>(kOffsetStepsPerCell) : 0.0f;
    q[i] = static_cast<int8_t>(std::clamp<long>(std::lround(steps), -kMaxOffsetSteps, kMaxOffsetSteps));
  }
  return q;
}

bool dequantizeProbeOffsets(const ProbeGrid& grid, const int8_t* q, size_t count, std::vector<float>& out,
                            std::string& why) {
  if (count == 0) return out.clear(), true;
  if (count != static_cast<uint64_t>(grid.count()) * kOffsetBytesPerProbe)
    return why = "probe offsets: " + std::to_string(count) + " bytes for " + std::to_string(grid.count()) +
                 " probes (3 each, or none)",
           false;
  std::vector<float> o(count);
  for (size_t i = 0; i < count; ++i) {
    const int a = static_cast<int>(i % 3);
    if (q[i] < -kMaxOffsetSteps || q[i] > kMaxOffsetSteps)
      return why = "probe offsets: probe " + std::to_string(i / 3) + " " + kAxis[a] + " offset of " +
                   std::to_string(q[i]) + " steps is outside ±" + std::to_string(kMaxOffsetSteps),
             false;
    if (grid.dims[a] < 2 && q[i] != 0)
      return why = "probe offsets: probe " + std::to_string(i / 3) + " moves along " + kAxis[a] +
                   ", an axis of one probe",
             false;
    o[i] = stepsToMetres(q[i], probeCellSize(grid, a));
  }
  out = std::move(o);
  return true;
}

void snapProbeOffsets(const ProbeGrid& grid, std::vector<float>& offsets) {
  const std::vector<int8_t> q = quantizeProbeOffsets(grid, offsets);
  for (size_t i = 0; i < q.size(); ++i) offsets[i] = stepsToMetres(q[i], probeCellSize(grid, static_cast<int>(i % 3)));
}

}  // namespace probecast
