// bench codec's records: each representation's error on the maps and its speed, zh3h per map,
// and the baked volume as records and as one keyframe.
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

double rmseAgainst(const Probe& probe, const std::vector<float>& normals, const std::vector<float>& reference) {
  return irradianceRmseRel(probe.data(), normals.data(), reference.data(), normals.size() / 3);
}

Probe floatVariant(const Probe& l2, const std::string& which) {
  Probe p = l2;
  if (which == "l2") return p;
  for (int i = 12; i < kProbeFloats; ++i) p[i] = 0.0f;
  if (which == "l1") return p;
  float axis[3], zonal[3];
  zh3Axis(l2.data(), axis);
  if (which == "zh3") zh3Project(l2.data(), axis, zonal);
  else zh3Hallucinate(l2.data(), axis, zonal);
  zh3ExpandToL2(p.data(), axis, zonal);
  return p;
}

// The whole baked volume as one keyframe of a `repr` stream, each brick in the cheapest
// representation within `bound` (0: all `repr`): bytes and worst probe.
VolumeResult::Keyframe volumeKeyframe(const CodecBenchOptions& opt, StreamLayout layout, Representation repr, float bound) {
  layout.repr = repr;
  EncoderOptions eo;
  eo.errorBound = bound;
  StreamEncoder encoder(layout, eo);
  encoder.update(opt.volumeProbes.data(), opt.volumeActive.data());
  std::vector<uint8_t> frame;
  encoder.writeKeyframeFrame(frame);
  double worst = 0, err = 0, energy = 0;
  for (size_t p = 0; p < opt.volumeActive.size(); ++p) {
    if (!opt.volumeActive[p]) continue;
    double e = 0, n = 0;
    irradianceErrorEnergy(encoder.reconstruction() + p * kProbeFloats, opt.volumeProbes.data() + p * kProbeFloats, e, n);
    if (n > 0) worst = std::max(worst, std::sqrt(e / n));
    err += e;
    energy += n;
  }
  return {repr, bound, frame.size(), worst, energy > 0 ? std::sqrt(err / energy) : 0.0,
          bricksByRepresentation(encoder, layout)};
}

}  // namespace

void irradianceEnergy(const float* test, const float* ref, double& err, double& energy) {
  irradianceErrorEnergy(test, ref, err, energy);
}

MapProbes projectMaps(const CodecBenchOptions& opt) {
  MapProbes maps;
  maps.normals = fibonacciSphere(opt.normals);
  for (size_t m = 0; m < opt.maps.size(); ++m) {
    const EnvMap& map = opt.maps[m];
    sayProgress(opt.progress, fmt::format("[{}/{}] {} ({}x{}): projecting, brute-force irradiance at {} normals", m + 1,
                                          opt.maps.size(), map.name, map.width, map.height, opt.normals));
    Probe p{};
    projectToSh(map, p.data());
    maps.probes.push_back(p);
    const int factor = std::max(1, map.width / 256);
    std::vector<float> e;
    bruteForceIrradiance(factor > 1 ? downsample(map, factor) : map, maps.normals, e);
    maps.trueIrradiance.push_back(std::move(e));
    maps.names.push_back(map.name);
  }
  return maps;
}

// How much each representation loses before quantisation (mean over the maps).
std::map<std::string, double> floatBaselines(const MapProbes& maps) {
  std::map<std::string, double> baselines;
  for (const char* which : {"l1", "zh3h", "zh3", "l2"}) {
    double sum = 0;
    for (size_t m = 0; m < maps.probes.size(); ++m)
      sum += rmseAgainst(floatVariant(maps.probes[m], which), maps.normals, maps.trueIrradiance[m]);
    baselines[which] = maps.probes.empty() ? 0.0 : sum / static_cast<double>(maps.probes.size());
  }
  return baselines;
}

// The throughput set: the maps' probes and the baked volume's at many intensities.
std::vector<Probe> throughputSet(const CodecBenchOptions& opt, const MapProbes& maps) {
  std::vector<Probe> many(static_cast<size_t>(opt.throughputProbes));
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> scale(0.05f, 20.0f);
  std::vector<Probe> sources = maps.probes;
  for (size_t p = 0; p < opt.volumeActive.size(); ++p)
    if (opt.volumeActive[p]) {
      Probe q;
      std::copy_n(opt.volumeProbes.begin() + static_cast<std::ptrdiff_t>(p * kProbeFloats), kProbeFloats, q.begin());
      sources.push_back(q);
    }
  if (sources.empty()) many.clear();
  for (size_t i = 0; i < many.size(); ++i) {
    const float s = scale(rng);
    for (int k = 0; k < kProbeFloats; ++k) many[i][k] = sources[i % sources.size()][k] * s;
  }
  return many;
}

// One representation: error on every map, then encode and decode rates (median over repeats).
StaticResult measureRecords(Representation repr, const MapProbes& maps, const std::vector<Probe>& many, int repeats) {
  StaticResult r;
  const size_t bytes = r.bytes = recordSize(repr);
  for (size_t m = 0; m < maps.probes.size(); ++m) {
    uint8_t rec[kMaxRecordBytes];
    encodeProbeRecord(repr, maps.probes[m].data(), rec);
    Probe q{};
    decodeProbeRecord(repr, rec, q.data());
    const double e = rmseAgainst(q, maps.normals, maps.trueIrradiance[m]);
    double err = 0, energy = 0;
    irradianceEnergy(q.data(), maps.probes[m].data(), err, energy);
    r.rmseTrue += e;
    r.rmseFloat += std::sqrt(err / energy);
    r.perMap[maps.names[m]] = e;
  }
  if (!maps.probes.empty()) {
    r.rmseTrue /= static_cast<double>(maps.probes.size());
    r.rmseFloat /= static_cast<double>(maps.probes.size());
  }
  std::vector<uint8_t> encoded(many.size() * bytes);
  std::vector<Probe> decoded(many.size());
  std::vector<double> enc, dec;
  for (int rep = 0; rep < repeats; ++rep) {
    auto t0 = Clock::now();
    for (size_t i = 0; i < many.size(); ++i) encodeProbeRecord(repr, many[i].data(), encoded.data() + i * bytes);
    auto t1 = Clock::now();
    for (size_t i = 0; i < many.size(); ++i) decodeProbeRecord(repr, encoded.data() + i * bytes, decoded[i].data());
    auto t2 = Clock::now();
    enc.push_back(static_cast<double>(many.size()) / std::chrono::duration<double>(t1 - t0).count());
    dec.push_back(static_cast<double>(many.size()) / std::chrono::duration<double>(t2 - t1).count());
  }
  r.encodeRate = session::median(enc);
  r.decodeRate = session::median(dec);
  return r;
}

// zh3h per map: the per-probe choice against l1 and against format 1 (every probe hallucinating
// from the same L1 bytes), irradiance error against the true irradiance.
nlohmann::json zh3hPerMap(const MapProbes& maps, const std::map<std::string, StaticResult>& results) {
  nlohmann::json rows = nlohmann::json::array();
  for (size_t m = 0; m < maps.probes.size(); ++m) {
    uint8_t rec[kMaxRecordBytes];
    encodeProbeRecord(Representation::L1, maps.probes[m].data(), rec);
    Probe always{};
    decodeProbeRecord(Representation::L1, rec, always.data());
    zh3HallucinateInPlace(always.data());
    encodeProbeRecord(Representation::Zh3Hallucinated, maps.probes[m].data(), rec);
    Probe chosen{};
    decodeProbeRecord(Representation::Zh3Hallucinated, rec, chosen.data());
    const bool keptL1 = std::all_of(chosen.begin() + 12, chosen.end(), [](float v) { return v == 0.0f; });
    rows.push_back({{"map", maps.names[m]},
                    {"l1", results.at("l1").perMap.at(maps.names[m])},
                    {"zh3h_format1", rmseAgainst(always, maps.normals, maps.trueIrradiance[m])},
                    {"zh3h", results.at("zh3h").perMap.at(maps.names[m])},
                    {"decodes_as", keptL1 ? "l1" : "hallucinated"}});
  }
  return rows;
}

// Bricks per representation of an encoder's layout.
nlohmann::json bricksByRepresentation(const StreamEncoder& encoder, const StreamLayout& layout) {
  nlohmann::json bricks = nlohmann::json::object();
  for (uint32_t b = 0; b < brickCount(layout); ++b) {
    const std::string name = representationName(encoder.brickRepresentation(b));
    bricks[name] = bricks.value(name, 0) + 1;
  }
  return bricks;
}

// Baked probes: each representation against the float L2 it was made from (exact over the
// sphere); then the volume as one keyframe, every brick as l1, zh3 and l2 and per brick within
// each bound.
VolumeResult measureVolume(const CodecBenchOptions& opt) {
  VolumeResult v;
  for (uint8_t a : opt.volumeActive) v.active += a ? 1 : 0;
  for (Representation repr : kAllRepresentations) {
    double err = 0, energy = 0;
    for (size_t p = 0; p < opt.volumeActive.size(); ++p) {
      if (!opt.volumeActive[p]) continue;
      const float* src = opt.volumeProbes.data() + p * kProbeFloats;
      uint8_t rec[kMaxRecordBytes];
      encodeProbeRecord(repr, src, rec);
      Probe q{};
      decodeProbeRecord(repr, rec, q.data());
      irradianceEnergy(q.data(), src, err, energy);
    }
    v.rmse[representationName(repr)] = energy > 0 ? std::sqrt(err / energy) : 0.0;
  }
  StreamLayout layout;
  for (int a = 0; a < 3; ++a) layout.grid[a] = static_cast<uint16_t>(opt.volumeDims[a]);
  layout.brickDim = 4;
  layout.repr = Representation::L2;
  if (!isValidLayout(layout) || probeCount(layout) != opt.volumeActive.size()) return v;
  for (Representation repr : {Representation::L1, Representation::Zh3, Representation::L2})
    v.keyframes.push_back(volumeKeyframe(opt, layout, repr, 0.0f));
  for (float bound : opt.errorBounds) v.keyframes.push_back(volumeKeyframe(opt, layout, Representation::L2, bound));
  return v;
}

}  // namespace probecast::bench::codecs
