// libFuzzer target: arbitrary bytes into every codec decoder, and floats through encode/decode.
// Crashes, sanitizer reports and broken invariants abort.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "codec_fuzz_common.h"
#include "probecast/codec/probe_file.h"
#include "probecast/codec/record.h"

using namespace probecast;

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

bool finite(const float* v, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const uint8_t control = data[0];
  if (control & 0x40u) {  // probe volume files
    ProbeVolume volume;
    std::string error;
    if (parseProbeVolume(data + 1, size - 1, volume, error))
      require(volume.probes.size() == static_cast<size_t>(volume.count()) * 27 && volume.active.size() == volume.count());
    else
      require(!error.empty());
    return 0;
  }
  const Representation repr = kAllRepresentations[(control & 7u) % 5u];
  const uint8_t mode = (control >> 3) & 3u;
  std::vector<uint8_t> body(data + 1, data + size);
  const StreamLayout layout = fuzz::fuzzLayout(repr);
  const size_t floats = probeCount(layout) * kProbeFloats;

  if (mode == fuzz::kFrameFresh || mode == fuzz::kFrameOnBase) {
    StreamDecoder dec(layout);
    if (mode == fuzz::kFrameOnBase) {
      std::vector<uint8_t> key, delta;
      fuzz::baseFrames(repr, key, delta, (control & fuzz::kPerBrickFlag) != 0);
      require(dec.apply(key.data(), key.size()) == CodecStatus::Ok);
    }
    if (control & fuzz::kRepairFlag) fuzz::repairChecksums(body);
    const std::vector<float> before(dec.probes(), dec.probes() + floats);
    const CodecStatus verified = verifyFrame(body.data(), body.size());
    const CodecStatus st = dec.apply(body.data(), body.size());
    if (st != CodecStatus::Ok) require(std::memcmp(before.data(), dec.probes(), floats * sizeof(float)) == 0);
    if (st == CodecStatus::Ok) require(verified == CodecStatus::Ok);  // the container check is never stricter
    require(finite(dec.probes(), floats));
  } else if (mode == fuzz::kRecord) {
    const size_t n = recordSize(repr);
    if (body.size() < n) return 0;
    float probe[kProbeFloats];
    if (decodeProbeRecord(repr, body.data(), probe)) require(finite(probe, kProbeFloats));
  } else {
    // Floats (any bits, NaN and Inf included) through the encoder; the decoder must match it.
    if (body.size() < floats * sizeof(float)) return 0;
    std::vector<float> probes(floats);
    std::memcpy(probes.data(), body.data(), floats * sizeof(float));
    std::vector<uint8_t> active(probeCount(layout));
    for (size_t i = 0; i < active.size(); ++i) active[i] = body.size() > floats * 4 + i ? body[floats * 4 + i] & 1 : 1;
    EncoderOptions options;
    options.errorBound = (control & fuzz::kPerBrickFlag) ? fuzz::kErrorBound : 0.0f;
    StreamEncoder enc(layout, options);
    StreamDecoder dec(layout);
    std::vector<uint8_t> frame;
    for (int f = 0; f < 2; ++f) {
      if (f == 1)
        for (float& v : probes) v *= 0.75f;
      enc.update(probes.data(), active.data());
      enc.writeChangedFrame(frame);
      require(dec.apply(frame.data(), frame.size()) == CodecStatus::Ok);
      require(std::memcmp(enc.reconstruction(), dec.probes(), floats * sizeof(float)) == 0);
      require(finite(dec.probes(), floats));
    }
  }
  return 0;
}
