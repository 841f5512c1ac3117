// Probe relocation, one round (probe_relocation.h).
#include "probe_relocation.h"

namespace probecast::renderer {

RelocationStep relocationStep(const ClassifyHits& h, const RelocationRule& rule, glm::vec3& offset) {
  glm::vec3 step(0.0f);
  if (h.backFraction > rule.backFaceThreshold) {
    // Through the nearest back face, half the clearance past it: the next round then sees it as a
    // front face and pushes the probe the rest of the way out.
    step = h.backDirection * (h.backDistance + 0.5f * rule.clearance);
  } else if (h.frontDistance < rule.clearance) {
    step = -h.frontDirection * (rule.clearance - h.frontDistance);  // straight away from the nearest front face
  } else {
    return RelocationStep::Settled;
  }
  const glm::vec3 next = glm::clamp(offset + step, -rule.maxShift, rule.maxShift);
  if (glm::all(glm::equal(next, offset))) return RelocationStep::Stuck;
  offset = next;
  return RelocationStep::Moved;
}

}  // namespace probecast::renderer
