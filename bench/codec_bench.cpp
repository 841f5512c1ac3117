#include "codec_bench.h"

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

namespace probecast::bench {
namespace {

using Clock = std::chrono::steady_clock;
using Probe = std::array<float, kProbeFloats>;

double rmseAgainst(const Probe& probe, const std::vector<float>& normals, const std::vector<float>& reference) {
  return irradianceRmseRel(probe.data(), normals.data(), reference.data(), normals.size() / 3);
}

void irradianceEnergy(const float* test, const float* ref, double& err, double& energy) {
  irradianceErrorEnergy(test, ref, err, energy);
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

// Each map's float L2 probe and its true irradiance (brute force) at the same normals.
struct MapProbes {
  std::vector<float> normals;
  std::vector<Probe> probes;
  std::vector<std::vector<float>> trueIrradiance;
  std::vector<std::string> names;
};

// One representation's records: error on the maps, speed on the throughput set.
struct StaticResult {
  size_t bytes = 0;  // per record
  double rmseTrue = 0, rmseFloat = 0, encodeRate = 0, decodeRate = 0;
  std::map<std::string, double> perMap;
};

// The baked volume (--probes): each representation against its float L2, and whole keyframes.
struct VolumeResult {
  uint32_t active = 0;
  std::map<std::string, double> rmse;  // per representation, against the float L2
  struct Keyframe {
    Representation repr;
    float bound = 0;
    size_t bytes = 0;
    double worst = 0, rmse = 0;
    nlohmann::json bricks;  // bricks per representation
  };
  std::vector<Keyframe> keyframes;
};

// The temporal sequence: every frame of a 16×4×16 grid, clean and with noise.
struct TemporalSequence {
  StreamLayout layout;
  uint32_t count = 0;
  std::string map;
  std::vector<float> clean, noisy;
};
constexpr int kTemporalPhases = 8;
constexpr float kTemporalNoise = 0.01f;
constexpr float kDegPerFrame = 0.5f;

// What the bench measures: filled by the phases below, written by reportCodecBench.
struct CodecMetrics {
  std::map<std::string, double> floatBaselines;         // per float variant: l1, zh3h, zh3, l2
  std::map<std::string, StaticResult> representations;  // by name
  nlohmann::json zh3hPerMap = nlohmann::json::array();
  std::optional<VolumeResult> volume;
  struct Temporal {
    std::string map;
    nlohmann::json rows = nlohmann::json::array();  // one per stream
    std::vector<imaging::ChartSeries> series;
  };
  std::optional<Temporal> temporal;  // none: no maps, or a single frame
};

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

nlohmann::json codecJson(const CodecBenchOptions& opt, const MapProbes& maps, const CodecMetrics& metrics) {
  nlohmann::json json;
  json["command"] = opt.command;
  json["codec_format_version"] = kFormatVersion;  // the temporal bytes are of this format
  json["maps"] = maps.names;
  json["metric"] =
      "irradiance relative RMSE, RGB pooled: sqrt(sum |E_test - E_ref|^2) / sqrt(sum |E_ref|^2) over equal-area "
      "normals, no clamping; 'true' = brute-force cosine convolution of the map, 'vs float l2' = exact over the sphere";
  json["normals"] = opt.normals;
  json["float_baselines_irradiance_rmse_rel"] = metrics.floatBaselines;
  for (const auto& [name, r] : metrics.representations)
    json["representations"][name] = {{"bytes_per_probe", r.bytes},
                                     {"irradiance_rmse_rel", r.rmseTrue},
                                     {"irradiance_rmse_rel_vs_float_l2", r.rmseFloat},
                                     {"encode_probes_per_s", r.encodeRate},
                                     {"decode_probes_per_s", r.decodeRate},
                                     {"per_map_irradiance_rmse_rel", r.perMap}};
  json["zh3h_per_map"] = metrics.zh3hPerMap;
  if (metrics.volume) {
    const VolumeResult& v = *metrics.volume;
    nlohmann::json& vol = json["probe_volume"];
    vol["name"] = opt.volumeName;
    vol["probes"] = opt.volumeActive.size();
    vol["active"] = v.active;
    for (Representation repr : kAllRepresentations)
      vol["representations"][representationName(repr)] = {
          {"bytes_per_probe", recordSize(repr)}, {"irradiance_rmse_rel_vs_float_l2", v.rmse.at(representationName(repr))}};
    for (const VolumeResult::Keyframe& k : v.keyframes)
      vol["keyframes"].push_back({{"representation", representationName(k.repr)},
                                  {"error_bound", k.bound},
                                  {"keyframe_bytes", k.bytes},
                                  {"worst_probe_irradiance_rmse_rel", k.worst},
                                  {"irradiance_rmse_rel", k.rmse},
                                  {"bricks_by_representation", k.bricks}});
  }
  json["timing"] = fmt::format("median of {} repeats, one thread", opt.repeats);
  if (metrics.temporal)
    json["temporal"] = {{"grid", {16, 4, 16}},
                        {"brick", 4},
                        {"frames", opt.frames},
                        {"map", metrics.temporal->map},
                        {"rotation_deg_per_frame", kDegPerFrame},
                        {"noise_rel_dc", kTemporalNoise},
                        {"raw_fp16_grid_bytes_per_probe_per_frame", 56},
                        {"error", "irradiance relative RMSE of the decoded stream against the noise-free float L2, "
                                  "frames 1.., exact over the sphere"},
                        {"results", metrics.temporal->rows}};
  json["temporal_results_note"] = "bytes include frame and section headers; zstd level 3";
  return json;
}

std::string volumeTable(const CodecBenchOptions& opt, const VolumeResult& v) {
  std::string table =
      fmt::format("\nbaked volume {} ({} active probes), irradiance error vs its float L2:", opt.volumeName, v.active);
  for (Representation repr : kAllRepresentations)
    table += fmt::format(" {} {:.2f}%", representationName(repr), 100 * v.rmse.at(representationName(repr)));
  table += "\n";
  for (const VolumeResult::Keyframe& k : v.keyframes)
    table += fmt::format("  {} stream{}: keyframe {} bytes, worst probe {:.2f}%, all {:.2f}%, bricks {}\n",
                         representationName(k.repr),
                         k.bound > 0 ? fmt::format(", error bound {:g}%", 100 * k.bound) : std::string(), k.bytes,
                         100 * k.worst, 100 * k.rmse, k.bricks.dump());
  return table;
}

std::string temporalTable(const CodecBenchOptions& opt, const nlohmann::json& temporal) {
  std::string table = fmt::format("\ntemporal ({} frames, 1024 probes, 1% noise): {:<6} {:>4} {:>14} {:>14} {:>12}\n",
                                  opt.frames, "repr", "dz", "B/probe/frame", "E rmse (clean)", "enc/dec ns");
  for (const auto& t : temporal)
    table += fmt::format("{:>44} {:<6} {:>4} {:>14.3f} {:>13.2f}% {:>6.0f}/{:<5.0f}{}{}\n", "",
                         t["representation"].get<std::string>(), t["deadzone"].get<int>(),
                         t["bytes_per_probe_per_frame"].get<double>(), 100 * t["irradiance_rmse_rel_vs_clean"].get<double>(),
                         t["encode_ns_per_probe_median"].get<double>(), t["decode_ns_per_probe_median"].get<double>(),
                         t.contains("error_bound")
                             ? fmt::format("  error bound {:g}%, first frame {:.2f} B/probe, bricks {}",
                                           100 * t["error_bound"].get<double>(),
                                           t["first_frame_bytes_per_probe"].get<double>(),
                                           t["bricks_by_representation"].dump())
                             : std::string(),
                         t["drift_free"].get<bool>() ? "" : "  DRIFT");
  return table;
}

std::string codecTable(const CodecBenchOptions& opt, const MapProbes& maps, const CodecMetrics& metrics) {
  std::string table = maps.probes.empty() ? "(no environment maps: the error columns below are empty)\n" : "";
  table += fmt::format("{:<6} {:>8} {:>14} {:>14} {:>14} {:>14}\n", "repr", "B/probe", "E rmse (true)", "vs float L2",
                       "encode Mpr/s", "decode Mpr/s");
  for (Representation repr : kAllRepresentations) {
    const StaticResult& r = metrics.representations.at(representationName(repr));
    table += fmt::format("{:<6} {:>8} {:>13.2f}% {:>13.3f}% {:>14.2f} {:>14.2f}\n", representationName(repr),
                         recordSize(repr), 100 * r.rmseTrue, 100 * r.rmseFloat, r.encodeRate / 1e6, r.decodeRate / 1e6);
  }
  const std::map<std::string, double>& b = metrics.floatBaselines;
  table += fmt::format("float baselines (E rmse vs true): l1 {:.2f}%  zh3h {:.2f}%  zh3 {:.2f}%  l2 {:.2f}%\n",
                       100 * b.at("l1"), 100 * b.at("zh3h"), 100 * b.at("zh3"), 100 * b.at("l2"));
  if (!maps.probes.empty()) {
    table += fmt::format("\nzh3h per map (E rmse vs true): {:<28} {:>8} {:>14} {:>8} {:>9}\n", "map", "l1",
                         "zh3h format 1", "zh3h", "decodes");
    for (const auto& row : metrics.zh3hPerMap)
      table += fmt::format("{:>31}{:<28} {:>7.2f}% {:>13.2f}% {:>7.2f}% {:>9}\n", "", row["map"].get<std::string>(),
                           100 * row["l1"].get<double>(), 100 * row["zh3h_format1"].get<double>(),
                           100 * row["zh3h"].get<double>(), row["decodes_as"] == "l1" ? "l1" : "zh3h");
  }
  if (metrics.volume) table += volumeTable(opt, *metrics.volume);
  if (metrics.temporal && !metrics.temporal->rows.empty()) table += temporalTable(opt, metrics.temporal->rows);
  return table;
}

// Error against bytes: the records on the maps, and every temporal stream.
std::string codecChart(const CodecBenchOptions& opt, const CodecMetrics& metrics) {
  imaging::ChartSeries keyframes{"records (static maps)", {}, false};
  for (Representation repr : kAllRepresentations)
    keyframes.points.push_back({static_cast<double>(recordSize(repr)),
                                metrics.representations.at(representationName(repr)).rmseTrue, representationName(repr)});
  std::vector<imaging::ChartSeries> all{keyframes};
  if (metrics.temporal) all.insert(all.end(), metrics.temporal->series.begin(), metrics.temporal->series.end());
  imaging::ChartSpec spec;
  spec.title = "probecast codec: irradiance error against bytes per probe";
  spec.xLabel = "bytes per probe (records) / per probe per frame (streams)";
  spec.yLabel = "irradiance relative RMSE";
  spec.logX = true;
  spec.logY = true;
  spec.footnote = opt.command;
  return imaging::renderSvgChart(spec, all);
}

}  // namespace

CodecBenchResult runCodecBench(const CodecBenchOptions& opt) {
  // 1. Each map: float L2 SH and the true irradiance by brute force.
  const MapProbes maps = projectMaps(opt);
  CodecMetrics metrics;
  metrics.floatBaselines = floatBaselines(maps);
  // 2. Every representation: size, error, speed.
  const std::vector<Probe> many = throughputSet(opt, maps);
  for (Representation repr : kAllRepresentations) {
    sayProgress(opt.progress, fmt::format("representation {}: error on {} maps, throughput on {} probes",
                                          representationName(repr), maps.probes.size(), many.size()));
    metrics.representations[representationName(repr)] = measureRecords(repr, maps, many, opt.repeats);
  }
  metrics.zh3hPerMap = zh3hPerMap(maps, metrics.representations);
  if (!opt.volumeProbes.empty()) metrics.volume = measureVolume(opt);
  // 3. Temporal: a moving sequence through the stream coder.
  if (!opt.maps.empty() && opt.frames > 1) metrics.temporal = measureTemporal(opt);
  return {codecJson(opt, maps, metrics), codecTable(opt, maps, metrics), codecChart(opt, metrics)};
}

}  // namespace probecast::bench
