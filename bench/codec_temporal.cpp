// bench codec's temporal sequence: a rotating, noisy map on a 16×4×16 grid through the stream
// coder, every representation at every dead-zone, and l2 per brick within each bound.
#include "codec_parts.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <random>

#include <fmt/format.h>

#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/record.h"
#include "probecast/codec/stream.h"
#include "probecast/codec/zh3.h"
#include "probecast/session/stats.h"
#include "probecast/imaging/svg_chart.h"
#include "harness.h"

namespace probecast::bench::codecs {
namespace {

// The temporal sequence: every frame of a 16×4×16 grid, clean and with noise.
struct TemporalSequence {
  StreamLayout layout;
  uint32_t count = 0;
  std::string map;
  std::vector<float> clean, noisy;
};

// The first map rotating about +Y, 0.5°/frame, on a 16×4×16 grid with per-probe intensity and
// phase, plus 1 % Gaussian noise per coefficient (relative to the DC).
TemporalSequence temporalSequence(const CodecBenchOptions& opt) {
  const EnvMap small = downsample(opt.maps[0], std::max(1, opt.maps[0].width / 128));
  TemporalSequence seq;
  seq.layout.grid[0] = 16;
  seq.layout.grid[1] = 4;
  seq.layout.grid[2] = 16;
  seq.layout.brickDim = 4;
  seq.count = probeCount(seq.layout);
  seq.map = small.name;
  const uint32_t count = seq.count;
  sayProgress(opt.progress, fmt::format("temporal: {} frames of {} probes from {} ({} phases)", opt.frames, count,
                                        small.name, kTemporalPhases));
  seq.clean.resize(static_cast<size_t>(opt.frames) * count * kProbeFloats);
  seq.noisy.resize(seq.clean.size());
  std::mt19937 nrng(2);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  std::vector<float> gain(count);
  for (uint32_t p = 0; p < count; ++p) gain[p] = 0.3f + 1.7f * static_cast<float>((p * 2654435761u) % 1000u) / 1000.0f;
  for (int f = 0; f < opt.frames; ++f) {
    Probe byPhase[kTemporalPhases];
    for (int k = 0; k < kTemporalPhases; ++k)
      projectToSh(small, byPhase[k].data(),
                  (static_cast<float>(f) * kDegPerFrame + 15.0f * static_cast<float>(k)) * kPi / 180.0f);
    for (uint32_t p = 0; p < count; ++p) {
      const Probe& src = byPhase[(p / 256) * 2 % kTemporalPhases + (p % 2)];
      float* c = &seq.clean[(static_cast<size_t>(f) * count + p) * kProbeFloats];
      float* n = &seq.noisy[(static_cast<size_t>(f) * count + p) * kProbeFloats];
      for (int i = 0; i < kProbeFloats; ++i) {
        c[i] = src[i] * gain[p];
        n[i] = c[i] + kTemporalNoise * c[i % 3] * gauss(nrng);
      }
    }
  }
  return seq;
}

// One stream over the sequence: its bytes, its error against the clean input, drift. Returns its
// row; `point` is its place on the chart.
nlohmann::json temporalStream(const TemporalSequence& seq, int frames, Representation repr, int dz, float errorBound,
                              imaging::ChartPoint& point) {
  StreamLayout layout = seq.layout;
  layout.repr = repr;
  const uint32_t count = seq.count;
  EncoderOptions eo;
  eo.deadzone = dz;
  eo.errorBound = errorBound;
  StreamEncoder encoder(layout, eo);
  StreamDecoder decoder(layout);
  std::vector<uint8_t> frame;
  size_t deltaBytes = 0, keyBytes = 0;
  double err = 0, energy = 0;
  bool driftFree = true;
  std::vector<double> encodeNs, decodeNs;  // per probe, each frame after the first
  for (int f = 0; f < frames; ++f) {
    const size_t at = static_cast<size_t>(f) * count * kProbeFloats;
    const auto t0 = Clock::now();
    encoder.update(seq.noisy.data() + at, nullptr);
    encoder.writeChangedFrame(frame);
    const auto t1 = Clock::now();
    driftFree = driftFree && decoder.apply(frame.data(), frame.size()) == CodecStatus::Ok;
    const auto t2 = Clock::now();
    if (f == 0) {
      keyBytes = frame.size();
      continue;
    }
    encodeNs.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / count);
    decodeNs.push_back(std::chrono::duration<double, std::nano>(t2 - t1).count() / count);
    deltaBytes += frame.size();
    for (uint32_t p = 0; p < count; ++p)
      irradianceEnergy(decoder.probes() + static_cast<size_t>(p) * kProbeFloats,
                       seq.clean.data() + at + static_cast<size_t>(p) * kProbeFloats, err, energy);
  }
  driftFree = driftFree && std::memcmp(decoder.probes(), encoder.reconstruction(),
                                       static_cast<size_t>(count) * kProbeFloats * sizeof(float)) == 0;
  const double perProbeFrame = static_cast<double>(deltaBytes) / (static_cast<double>(frames - 1) * count);
  const double rmse = std::sqrt(err / energy);
  nlohmann::json t = {{"representation", representationName(repr)},
                      {"deadzone", dz},
                      {"bytes_per_probe_per_frame", perProbeFrame},
                      {"first_frame_bytes_per_probe", static_cast<double>(keyBytes) / count},
                      {"irradiance_rmse_rel_vs_clean", rmse},
                      {"encode_ns_per_probe_median", session::median(encodeNs)},
                      {"decode_ns_per_probe_median", session::median(decodeNs)},
                      {"drift_free", driftFree}};
  if (errorBound > 0.0f) {
    t["error_bound"] = errorBound;
    t["bricks_by_representation"] = bricksByRepresentation(encoder, layout);  // after the last frame
  }
  point = {perProbeFrame, rmse, errorBound > 0.0f ? fmt::format("{:g}%", 100 * errorBound) : fmt::format("dz{}", dz)};
  return t;
}

}  // namespace

// Every representation at every dead-zone, then the l2 stream per brick within each bound.
CodecMetrics::Temporal measureTemporal(const CodecBenchOptions& opt) {
  const TemporalSequence seq = temporalSequence(opt);
  CodecMetrics::Temporal temporal;
  temporal.map = seq.map;
  const auto run = [&](Representation repr, int dz, float bound, imaging::ChartSeries& series) {
    series.points.emplace_back();
    temporal.rows.push_back(temporalStream(seq, opt.frames, repr, dz, bound, series.points.back()));
  };
  for (Representation repr : kAllRepresentations) {
    imaging::ChartSeries series{std::string(representationName(repr)) + " stream", {}, true};
    for (int dz : opt.deadzones) {
      if (repr == Representation::Fp16 && dz > 0) continue;  // fp16 steps are not ratio steps
      run(repr, dz, 0.0f, series);
    }
    temporal.series.push_back(std::move(series));
  }
  imaging::ChartSeries bounded{"l2 stream, per-brick representation (dz1)", {}, true};
  for (float bound : opt.errorBounds) run(Representation::L2, 1, bound, bounded);
  if (!bounded.points.empty()) temporal.series.push_back(std::move(bounded));
  return temporal;
}

}  // namespace probecast::bench::codecs
