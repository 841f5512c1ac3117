#include "codec_fuzz_common.h"

#include <cmath>

#include "probecast/codec/internal/frame_checksums.h"
#include "probecast/codec/sh.h"

namespace probecast::fuzz {

StreamLayout fuzzLayout(Representation repr) {
  StreamLayout l;
  l.grid[0] = 5;
  l.grid[1] = 2;
  l.grid[2] = 3;
  l.brickDim = 4;  // bricks of 24 and 6 probes: a delta of one probe lists it
  l.repr = repr;
  return l;
}

void baseFrames(Representation repr, std::vector<uint8_t>& keyframe, std::vector<uint8_t>& delta, bool perBrick,
                std::vector<uint8_t>* smallDelta) {
  const StreamLayout layout = fuzzLayout(repr);
  const uint32_t n = probeCount(layout);
  std::vector<float> probes(n * kProbeFloats);
  std::vector<uint8_t> active(n, 1);
  active[3] = 0;
  for (uint32_t i = 0; i < probes.size(); ++i) probes[i] = 0.5f + 0.25f * std::sin(static_cast<float>(i));
  EncoderOptions options;
  options.errorBound = perBrick ? kErrorBound : 0.0f;
  StreamEncoder enc(layout, options);
  enc.update(probes.data(), active.data());
  enc.writeKeyframeFrame(keyframe);
  if (smallDelta) {
    StreamEncoder small(layout, options);
    small.update(probes.data(), active.data());
    std::vector<float> nudged = probes;
    nudged[kProbeFloats + 4] *= 1.2f;  // one L1 coefficient of probe 1
    small.update(nudged.data(), active.data());
    small.writeChangedFrame(*smallDelta);
  }
  for (uint32_t i = 0; i < probes.size(); i += 7) probes[i] *= 1.3f;
  active[3] = 1;
  active[4] = 0;
  enc.update(probes.data(), active.data());
  enc.writeChangedFrame(delta);
}

void repairChecksums(std::vector<uint8_t>& f) { rewriteFrameChecksums(f); }

}  // namespace probecast::fuzz
