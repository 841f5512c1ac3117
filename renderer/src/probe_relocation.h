// The probe relocation rule of the probe updater (probe_updater.h), one classify round at a time.
//
// A round traces a fixed set of rays from every unsettled probe at its current position and keeps,
// per probe, the fraction of rays that hit a back face, the nearest back face and the nearest
// front face (distance, unit direction). Inside geometry (back faces
// above the threshold) the probe steps through the nearest back face and a little past it; free
// but nearer than the clearance to a front face, it steps away from that face; otherwise it stays.
// Every step is clamped to the allowed box (a fraction of the cell per axis) and a probe that
// cannot move any more is settled where it is.
#pragma once

#include <glm/glm.hpp>

namespace probecast::renderer {

struct ClassifyHits {
  float backFraction = 0.0f;  // rays that hit a back face / rays
  float backDistance = 0.0f, frontDistance = 0.0f;  // metres; huge = none
  glm::vec3 backDirection{0.0f}, frontDirection{0.0f};
};

struct RelocationRule {
  float backFaceThreshold = 0.25f;
  float clearance = 0.0f;        // metres
  glm::vec3 maxShift{0.0f};      // metres per axis (0 on an axis that cannot move)
};

enum class RelocationStep { Settled, Moved, Stuck };

// The probe's next offset from `offset` (metres from its grid position) given what the round's
// rays saw there. Settled: free and clear, `offset` unchanged. Moved: `offset` changed. Stuck:
// the step it needs leaves the allowed box (or is nothing), `offset` unchanged.
RelocationStep relocationStep(const ClassifyHits& hits, const RelocationRule& rule, glm::vec3& offset);

}  // namespace probecast::renderer
