#include "codec_fuzz_common.h"

#include <cmath>

#include "crc32c.h"
#include "probecast/codec/sh.h"

namespace probecast::fuzz {

StreamLayout fuzzLayout(Representation repr) {
  StreamLayout l;
  l.grid[0] = 5;
  l.grid[1] = 2;
  l.grid[2] = 3;
  l.brickDim = 2;
  l.repr = repr;
  return l;
}

void baseFrames(Representation repr, std::vector<uint8_t>& keyframe, std::vector<uint8_t>& delta) {
  const StreamLayout layout = fuzzLayout(repr);
  const uint32_t n = probeCount(layout);
  std::vector<float> probes(n * kProbeFloats);
  std::vector<uint8_t> active(n, 1);
  active[3] = 0;
  for (uint32_t i = 0; i < probes.size(); ++i) probes[i] = 0.5f + 0.25f * std::sin(static_cast<float>(i));
  StreamEncoder enc(layout);
  enc.update(probes.data(), active.data());
  enc.writeKeyframeFrame(keyframe);
  for (uint32_t i = 0; i < probes.size(); i += 7) probes[i] *= 1.3f;
  active[3] = 1;
  active[4] = 0;
  enc.update(probes.data(), active.data());
  enc.writeChangedFrame(delta);
}

void repairChecksums(std::vector<uint8_t>& f) {
  if (f.size() < kFrameHeaderSize) return;
  auto put = [&](size_t at, uint32_t v) {
    for (int b = 0; b < 4; ++b) f[at + b] = static_cast<uint8_t>(v >> (8 * b));
  };
  auto get = [&](size_t at) {
    return static_cast<uint32_t>(f[at]) | (static_cast<uint32_t>(f[at + 1]) << 8) |
           (static_cast<uint32_t>(f[at + 2]) << 16) | (static_cast<uint32_t>(f[at + 3]) << 24);
  };
  put(28, crc32c(f.data(), 28));
  size_t at = kFrameHeaderSize;
  while (at + kSectionHeaderSize <= f.size()) {
    const uint32_t stored = get(at + 14);
    if (stored > f.size() - at - kSectionHeaderSize) break;
    uint32_t crc = crc32c(f.data() + at, 18);
    crc = crc32c(f.data() + at + kSectionHeaderSize, stored, crc);
    put(at + 18, crc);
    at += kSectionHeaderSize + stored;
  }
}

}  // namespace probecast::fuzz
