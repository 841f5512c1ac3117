// Writes the seed corpus for codec_fuzz into a folder: valid frames and records per representation.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "codec_fuzz_common.h"
#include "probecast/codec/probe_file.h"
#include "probecast/codec/record.h"

using namespace probecast;

namespace {

void write(const std::string& dir, const std::string& name, uint8_t control, const std::vector<uint8_t>& body) {
  std::ofstream out(dir + "/" + name, std::ios::binary);
  out.put(static_cast<char>(control));
  out.write(reinterpret_cast<const char*>(body.data()), static_cast<std::streamsize>(body.size()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: codec_fuzz_seeds OUTDIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  for (int r = 0; r < 5; ++r) {
    const Representation repr = kAllRepresentations[r];
    const std::string name = representationName(repr);
    std::vector<uint8_t> key, delta, small;
    fuzz::baseFrames(repr, key, delta, false, &small);
    const auto control = [&](uint8_t mode, bool repair) {
      return static_cast<uint8_t>(r | (mode << 3) | (repair ? fuzz::kRepairFlag : 0));
    };
    write(dir, name + "-keyframe", control(fuzz::kFrameFresh, false), key);
    write(dir, name + "-keyframe-repair", control(fuzz::kFrameFresh, true), key);
    write(dir, name + "-delta", control(fuzz::kFrameOnBase, false), delta);
    write(dir, name + "-delta-repair", control(fuzz::kFrameOnBase, true), delta);
    write(dir, name + "-small-delta", control(fuzz::kFrameOnBase, false), small);
    write(dir, name + "-small-delta-repair", control(fuzz::kFrameOnBase, true), small);
    std::vector<uint8_t> record(recordSize(repr));
    float probe[kProbeFloats];
    for (int i = 0; i < kProbeFloats; ++i) probe[i] = 1.0f / static_cast<float>(1 + i);
    encodeProbeRecord(repr, probe, record.data());
    write(dir, name + "-record", control(fuzz::kRecord, false), record);
    const size_t floats = probeCount(fuzz::fuzzLayout(repr)) * kProbeFloats;
    std::vector<uint8_t> raw(floats * sizeof(float));
    for (size_t i = 0; i < floats; ++i) {
      const float v = 0.3f + 0.2f * std::cos(static_cast<float>(i));
      std::memcpy(raw.data() + i * sizeof(float), &v, sizeof v);
    }
    write(dir, name + "-floats", control(fuzz::kEncodeFloats, false), raw);
    // The same with a per-brick representation (a zh3 or l2 stream mixes cheaper bricks in).
    std::vector<uint8_t> mixedKey, mixedDelta;
    fuzz::baseFrames(repr, mixedKey, mixedDelta, true);
    write(dir, name + "-perbrick-keyframe", static_cast<uint8_t>(control(fuzz::kFrameFresh, false) | fuzz::kPerBrickFlag), mixedKey);
    write(dir, name + "-perbrick-delta-repair", static_cast<uint8_t>(control(fuzz::kFrameOnBase, true) | fuzz::kPerBrickFlag), mixedDelta);
    write(dir, name + "-perbrick-floats", static_cast<uint8_t>(control(fuzz::kEncodeFloats, false) | fuzz::kPerBrickFlag), raw);
  }
  ProbeVolume volume;
  volume.grid.dims[0] = 2;
  volume.grid.dims[1] = 1;
  volume.grid.dims[2] = 2;
  volume.probes.assign(4 * 27, 0.5f);
  volume.active = {1, 0, 1, 1};
  std::vector<uint8_t> bytes;
  serializeProbeVolume(volume, bytes);
  write(dir, "probe-volume", 0x40, bytes);
  // With the scene it was traced in (probe file version 4's scene block).
  volume.scene.manifest = R"({"files":[],"format":1,"lighting":{"sky":[0.5,0.5,0.5]},"scene":{"builtin":"cornell"}})";
  volume.scene.hash.fill(0x5a);
  volume.scene.time = 0.25;
  serializeProbeVolume(volume, bytes);
  write(dir, "probe-volume-scene", 0x40, bytes);
  return 0;
}
