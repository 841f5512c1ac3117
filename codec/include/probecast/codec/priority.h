// Brick priority for a subscriber (docs/CODEC.md §6): which bricks to send first under a byte budget.
//
// Units: positions in metres (world space), matrices column-major (m[col * 4 + row]) mapping
// world to Vulkan clip space (x, y in [-w, w], z in [0, w]).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "probecast/codec/stream.h"

namespace probecast {

struct View {
  float viewProj[16];
  float eye[3];
};

// The most views one view set may hold (lf:16x16): what the raster client renders in one pass and
// what a subscriber may send the server in one view update.
constexpr uint32_t kMaxViewsPerSet = 256;

struct PriorityParams {
  float outOfViewWeight = 0.05f;  // bricks outside every frustum still trickle in
  float ageWeight = 0.25f;        // per frame waited: no starvation
  float minChange = 0.01f;        // floor of the change term once a brick is stale
};

struct BrickCandidate {
  float change = 0.0f;      // relative change since the subscriber's version (use 1 when it holds nothing)
  uint32_t ageFrames = 0;   // frames since the subscriber's version became stale
  uint32_t bytes = 0;       // size of the section it would be sent
};

// The probes' trilinear support: the brick's probe box grown by one cell on every side,
// clipped to the grid bounds.
void brickInfluenceBox(const StreamLayout& layout, const GridBounds& bounds, uint32_t brick, float boxMin[3],
                       float boxMax[3]);

// True if the box intersects the frustum of `viewProj` (conservative: may say true for a box just
// outside a frustum corner, never false for a box inside).
bool boxIntersectsFrustum(const float viewProj[16], const float boxMin[3], const float boxMax[3]);

// Score of each brick (0 = nothing to send). Higher is sent first. A brick with something to send
// scores a finite positive float for any views, however far (a non-finite eye counts as the
// farthest), so every brick is sent eventually.
void scoreBricks(const StreamLayout& layout, const GridBounds& bounds, std::span<const View> views,
                 std::span<const BrickCandidate> candidates, const PriorityParams& params, float* scores);

// Picks bricks by descending score while they fit in `budgetBytes` (bricks that do not fit are
// skipped, smaller ones after them may still fit). Writes brick indices to `out` (capacity
// candidates.size()) and returns how many were chosen. Ties break by lower brick index.
size_t selectBricks(std::span<const float> scores, std::span<const BrickCandidate> candidates, uint64_t budgetBytes,
                    uint32_t* out);

}  // namespace probecast
