#include "bus_fuzz_common.h"

#include <cstring>

#include "codec_fuzz_common.h"
#include "probecast/codec/crc32c.h"
#include "probecast/service/bus_format.h"

namespace probecast::fuzz {

std::vector<std::vector<uint8_t>> sampleBusMessages() {
  std::vector<std::vector<uint8_t>> out;
  for (Representation repr : kAllRepresentations) {
    bus::Volume volume;
    volume.epoch = 0x1234567890abcdefull;
    volume.publishedUs = 1700000000000000ull;
    volume.layout = fuzzLayout(repr);
    volume.bounds = {{-1.0f, 0.0f, -1.0f}, {1.0f, 0.5f, 1.0f}};
    std::vector<uint8_t> m;
    bus::writeVolumeMessage(volume, 0, m);
    out.push_back(m);
    const uint32_t n = probeCount(volume.layout);
    // The same volume with probe offsets (3 bytes per probe in the volume message, their checksum
    // in every brick message below) and client area lights.
    volume.areaLights = {kAreaLightRuleVersion, 0.05f};
    volume.sceneHash.fill(0xa5);  // and a scene: its manifest in the volume message, its hash in every one
    volume.sceneManifest = R"({"files":[],"format":1,"lighting":{},"scene":{"builtin":"cornell"}})";
    volume.offsets.resize(static_cast<size_t>(n) * 3);
    for (size_t i = 0; i < volume.offsets.size(); ++i) volume.offsets[i] = static_cast<int8_t>(static_cast<int>(i % 11) * 23 - 115);
    bus::writeVolumeMessage(volume, 0, m);
    out.push_back(m);
    std::vector<float> probes(n * kProbeFloats);
    for (size_t i = 0; i < probes.size(); ++i) probes[i] = 0.4f + 0.01f * static_cast<float>(i % 17);
    StreamEncoder enc(volume.layout);
    for (int f = 0; f < 2; ++f) {
      if (f == 1)
        for (size_t i = 0; i < probes.size(); i += 5) probes[i] *= 1.25f;
      enc.update(probes.data(), nullptr);
      const uint32_t brick = 1;
      bus::Brick b;
      b.brick = brick;
      b.version = enc.brickVersion(brick);
      b.producerFrame = enc.frameSequence();
      b.change = enc.brickChange(brick);
      const std::span<const uint8_t> key = enc.keyframeSection(brick);
      const std::vector<uint8_t> keyCopy(key.begin(), key.end());
      b.keyframe = keyCopy;
      b.delta = f == 0 ? std::span<const uint8_t>{} : enc.deltaSection(brick);
      b.state.time = 0.5 * f;  // the scene state: a still frame, then a playing one with two lights
      if (f == 1) {
        b.state.rate = 0.05;
        b.state.clockUs = 1700000000000000ull;
        b.state.lights.resize(2);
        b.state.lights[1].type = 1;
        b.state.lights[1].outerCone = 0.5f;
      }
      bus::writeBrickMessage(volume, b, f == 0 ? 0 : bus::kEndOfBatch, m);
      out.push_back(m);
    }
  }
  return out;
}

void repairBusChecksum(std::vector<uint8_t>& m) {
  if (m.size() < bus::kHeaderSize) return;
  uint32_t crc = crc32c(m.data(), 12);
  crc = crc32c(m.data() + bus::kHeaderSize, m.size() - bus::kHeaderSize, crc);
  std::memcpy(m.data() + 12, &crc, 4);
}

}  // namespace probecast::fuzz
