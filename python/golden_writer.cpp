// Writes what the C++ codec makes of a fixed input, for the Python tests to compare against byte
// for byte: `probecast_python_golden DIR` writes DIR/input.f32 (N × 27 float32), DIR/<repr>.rec
// (N records) and DIR/<repr>.dec (N × 27 float32) for every representation, and DIR/stream_<repr>.bin
// (a keyframe frame then one changed frame of a 6 × 5 × 3 grid, each prefixed by its u32 size, sections
// stored raw) made from DIR/stream_input0.f32 and DIR/stream_input1.f32.
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <string>
#include <vector>

#include "probecast/codec/record.h"
#include "probecast/codec/stream.h"

using namespace probecast;

namespace {

bool writeFile(const std::string& path, const void* data, size_t size) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  const bool ok = std::fwrite(data, 1, size, f) == size;
  return std::fclose(f) == 0 && ok;
}

// Deterministic probes: a positive DC and coefficients of both signs up to the ratio bounds, plus a
// few awkward ones (black, negative DC, huge DC).
std::vector<float> fixedProbes(size_t count, float phase) {
  std::vector<float> p(count * kProbeFloats);
  for (size_t i = 0; i < count; ++i)
    for (int k = 0; k < kProbeFloats; ++k) {
      const float dc = 0.05f + 3.0f * static_cast<float>((i * 7 + 3) % 17) / 17.0f;
      const float s = std::sin(0.37f * static_cast<float>(i * kProbeFloats + k) + phase);
      p[i * kProbeFloats + k] = k < 3 ? dc * (1.0f + 0.2f * static_cast<float>(k)) : 0.6f * dc * s;
    }
  if (count > 3) {
    for (int k = 0; k < kProbeFloats; ++k) p[k] = 0.0f;
    p[kProbeFloats] = -1.0f;
    p[2 * kProbeFloats + 1] = 1.0e6f;
  }
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: probecast_python_golden DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  const size_t n = 200;
  const std::vector<float> input = fixedProbes(n, 0.0f);
  bool ok = writeFile(dir + "/input.f32", input.data(), input.size() * sizeof(float));
  const uint32_t streamCount = 6 * 5 * 3;
  const std::vector<float> frame0 = fixedProbes(streamCount, 0.0f), frame1 = fixedProbes(streamCount, 0.3f);
  ok = ok && writeFile(dir + "/stream_input0.f32", frame0.data(), frame0.size() * sizeof(float));
  ok = ok && writeFile(dir + "/stream_input1.f32", frame1.data(), frame1.size() * sizeof(float));
  for (Representation repr : kAllRepresentations) {
    const size_t bytes = recordSize(repr);
    std::vector<uint8_t> rec(n * bytes);
    std::vector<float> dec(n * kProbeFloats);
    for (size_t i = 0; i < n; ++i) {
      encodeProbeRecord(repr, &input[i * kProbeFloats], &rec[i * bytes]);
      decodeProbeRecord(repr, &rec[i * bytes], &dec[i * kProbeFloats]);
    }
    const std::string name = representationName(repr);
    ok = ok && writeFile(dir + "/" + name + ".rec", rec.data(), rec.size());
    ok = ok && writeFile(dir + "/" + name + ".dec", dec.data(), dec.size() * sizeof(float));

    const StreamLayout layout = streamLayoutFor(ProbeGrid{{6, 5, 3}, {{0, 0, 0}, {5, 4, 2}}}, repr, 4);
    EncoderOptions options;
    options.compress = false;  // byte-exact whatever zstd the module links
    StreamEncoder encoder(layout, options);
    std::vector<uint8_t> out, frame;
    const auto append = [&] {
      const uint32_t size = static_cast<uint32_t>(frame.size());
      const auto* s = reinterpret_cast<const uint8_t*>(&size);
      out.insert(out.end(), s, s + 4);
      out.insert(out.end(), frame.begin(), frame.end());
    };
    encoder.update(frame0.data(), nullptr);
    encoder.writeKeyframeFrame(frame);
    append();
    encoder.update(frame1.data(), nullptr);
    encoder.writeChangedFrame(frame);
    append();
    ok = ok && writeFile(dir + "/stream_" + name + ".bin", out.data(), out.size());
  }
  if (!ok) {
    std::fprintf(stderr, "probecast_python_golden: cannot write into %s\n", dir.c_str());
    return 1;
  }
  return 0;
}
