#include "codec_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <algorithm>

#include <fmt/format.h>

#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/record.h"
#include "probecast/codec/stream.h"
#include "probecast/codec/zh3.h"
#include "probecast/session/stats.h"
#include "probecast/imaging/svg_chart.h"

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

struct StaticResult {
  double rmseTrue = 0, rmseFloat = 0, encodeRate = 0, decodeRate = 0;
  std::map<std::string, double> perMap;
};

}  // namespace

CodecBenchResult runCodecBench(const CodecBenchOptions& opt) {
  const auto say = [&](const std::string& s) {
    if (opt.progress) opt.progress(s);
  };
  const std::vector<float> normals = fibonacciSphere(opt.normals);
  std::vector<Probe> mapProbes;
  std::vector<std::vector<float>> trueIrradiance;
  std::vector<std::string> names;

  // 1. Each map: float L2 SH and the true irradiance by brute force.
  for (size_t m = 0; m < opt.maps.size(); ++m) {
    const EnvMap& map = opt.maps[m];
    say(fmt::format("[{}/{}] {} ({}x{}): projecting, brute-force irradiance at {} normals", m + 1, opt.maps.size(),
                    map.name, map.width, map.height, opt.normals));
    Probe p{};
    projectToSh(map, p.data());
    mapProbes.push_back(p);
    const int factor = std::max(1, map.width / 256);
    std::vector<float> e;
    bruteForceIrradiance(factor > 1 ? downsample(map, factor) : map, normals, e);
    trueIrradiance.push_back(std::move(e));
    names.push_back(map.name);
  }

  nlohmann::json json;
  json["command"] = opt.command;
  json["codec_format_version"] = kFormatVersion;  // the temporal bytes are of this format
  json["maps"] = names;
  json["metric"] =
      "irradiance relative RMSE, RGB pooled: sqrt(sum |E_test - E_ref|^2) / sqrt(sum |E_ref|^2) over equal-area "
      "normals, no clamping; 'true' = brute-force cosine convolution of the map, 'vs float l2' = exact over the sphere";
  json["normals"] = opt.normals;

  // Float baselines: how much each representation loses before quantisation.
  nlohmann::json baselines;
  for (const char* which : {"l1", "zh3h", "zh3", "l2"}) {
    double sum = 0;
    for (size_t m = 0; m < mapProbes.size(); ++m)
      sum += rmseAgainst(floatVariant(mapProbes[m], which), normals, trueIrradiance[m]);
    baselines[which] = mapProbes.empty() ? 0.0 : sum / static_cast<double>(mapProbes.size());
  }
  json["float_baselines_irradiance_rmse_rel"] = baselines;

  // Throughput set: the maps' probes at many intensities.
  std::vector<Probe> many(static_cast<size_t>(opt.throughputProbes));
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> scale(0.05f, 20.0f);
  std::vector<Probe> sources = mapProbes;
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

  // 2. Every representation: size, error, speed.
  std::map<std::string, StaticResult> results;
  nlohmann::json reprJson;
  for (Representation repr : kAllRepresentations) {
    const std::string name = representationName(repr);
    say(fmt::format("representation {}: error on {} maps, throughput on {} probes", name, mapProbes.size(),
                    many.size()));
    StaticResult r;
    const size_t bytes = recordSize(repr);
    for (size_t m = 0; m < mapProbes.size(); ++m) {
      uint8_t rec[kMaxRecordBytes];
      encodeProbeRecord(repr, mapProbes[m].data(), rec);
      Probe q{};
      decodeProbeRecord(repr, rec, q.data());
      const double e = rmseAgainst(q, normals, trueIrradiance[m]);
      double err = 0, energy = 0;
      irradianceEnergy(q.data(), mapProbes[m].data(), err, energy);
      r.rmseTrue += e;
      r.rmseFloat += std::sqrt(err / energy);
      r.perMap[names[m]] = e;
    }
    if (!mapProbes.empty()) {
      r.rmseTrue /= static_cast<double>(mapProbes.size());
      r.rmseFloat /= static_cast<double>(mapProbes.size());
    }
    std::vector<uint8_t> encoded(many.size() * bytes);
    std::vector<Probe> decoded(many.size());
    std::vector<double> enc, dec;
    for (int rep = 0; rep < opt.repeats; ++rep) {
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
    reprJson[name] = {{"bytes_per_probe", bytes},
                      {"irradiance_rmse_rel", r.rmseTrue},
                      {"irradiance_rmse_rel_vs_float_l2", r.rmseFloat},
                      {"encode_probes_per_s", r.encodeRate},
                      {"decode_probes_per_s", r.decodeRate},
                      {"per_map_irradiance_rmse_rel", r.perMap}};
    results[name] = r;
  }
  json["representations"] = reprJson;

  // zh3h per map: the per-probe choice against l1 and against format 1 (every probe hallucinating
  // from the same L1 bytes), irradiance error against the true irradiance.
  nlohmann::json zh3hMaps = nlohmann::json::array();
  std::string zh3hTable;
  if (!mapProbes.empty()) {
    zh3hTable = fmt::format("\nzh3h per map (E rmse vs true): {:<28} {:>8} {:>14} {:>8} {:>9}\n", "map", "l1",
                            "zh3h format 1", "zh3h", "decodes");
    for (size_t m = 0; m < mapProbes.size(); ++m) {
      uint8_t rec[kMaxRecordBytes];
      encodeProbeRecord(Representation::L1, mapProbes[m].data(), rec);
      Probe always{};
      decodeProbeRecord(Representation::L1, rec, always.data());
      zh3HallucinateInPlace(always.data());
      encodeProbeRecord(Representation::Zh3Hallucinated, mapProbes[m].data(), rec);
      Probe chosen{};
      decodeProbeRecord(Representation::Zh3Hallucinated, rec, chosen.data());
      const bool keptL1 = std::all_of(chosen.begin() + 12, chosen.end(), [](float v) { return v == 0.0f; });
      const double l1 = results["l1"].perMap[names[m]], format1 = rmseAgainst(always, normals, trueIrradiance[m]),
                   zh3h = results["zh3h"].perMap[names[m]];
      zh3hMaps.push_back({{"map", names[m]},
                          {"l1", l1},
                          {"zh3h_format1", format1},
                          {"zh3h", zh3h},
                          {"decodes_as", keptL1 ? "l1" : "hallucinated"}});
      zh3hTable += fmt::format("{:>31}{:<28} {:>7.2f}% {:>13.2f}% {:>7.2f}% {:>9}\n", "", names[m], 100 * l1,
                               100 * format1, 100 * zh3h, keptL1 ? "l1" : "zh3h");
    }
  }
  json["zh3h_per_map"] = zh3hMaps;

  // Baked probes: each representation against the float L2 it was made from (exact over the sphere).
  std::string volumeTable;
  if (!opt.volumeProbes.empty()) {
    nlohmann::json vol;
    vol["name"] = opt.volumeName;
    uint32_t active = 0;
    for (uint8_t a : opt.volumeActive) active += a ? 1 : 0;
    vol["probes"] = opt.volumeActive.size();
    vol["active"] = active;
    volumeTable = fmt::format("\nbaked volume {} ({} active probes), irradiance error vs its float L2:", opt.volumeName, active);
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
      const double rmse = energy > 0 ? std::sqrt(err / energy) : 0.0;
      vol["representations"][representationName(repr)] = {{"bytes_per_probe", recordSize(repr)},
                                                           {"irradiance_rmse_rel_vs_float_l2", rmse}};
      volumeTable += fmt::format(" {} {:.2f}%", representationName(repr), 100 * rmse);
    }
    volumeTable += "\n";
    // The whole volume as one keyframe of an l2 stream, each brick in the cheapest representation
    // within each bound, against every brick as l1, zh3 and l2: bytes and worst probe.
    StreamLayout layout;
    for (int a = 0; a < 3; ++a) layout.grid[a] = static_cast<uint16_t>(opt.volumeDims[a]);
    layout.brickDim = 4;
    layout.repr = Representation::L2;
    if (isValidLayout(layout) && probeCount(layout) == opt.volumeActive.size()) {
      const auto keyframe = [&](Representation repr, float bound, nlohmann::json& row) {
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
        nlohmann::json bricks = nlohmann::json::object();
        for (uint32_t b = 0; b < brickCount(layout); ++b) {
          const std::string name = representationName(encoder.brickRepresentation(b));
          bricks[name] = bricks.value(name, 0) + 1;
        }
        row = {{"representation", representationName(repr)},
               {"error_bound", bound},
               {"keyframe_bytes", frame.size()},
               {"worst_probe_irradiance_rmse_rel", worst},
               {"irradiance_rmse_rel", energy > 0 ? std::sqrt(err / energy) : 0.0},
               {"bricks_by_representation", bricks}};
        volumeTable += fmt::format("  {} stream{}: keyframe {} bytes, worst probe {:.2f}%, all {:.2f}%, bricks {}\n",
                                   representationName(repr),
                                   bound > 0 ? fmt::format(", error bound {:g}%", 100 * bound) : std::string(),
                                   frame.size(), 100 * worst, 100 * row["irradiance_rmse_rel"].get<double>(),
                                   bricks.dump());
      };
      for (Representation repr : {Representation::L1, Representation::Zh3, Representation::L2}) {
        nlohmann::json row;
        keyframe(repr, 0.0f, row);
        vol["keyframes"].push_back(row);
      }
      for (float bound : opt.errorBounds) {
        nlohmann::json row;
        keyframe(Representation::L2, bound, row);
        vol["keyframes"].push_back(row);
      }
    }
    json["probe_volume"] = vol;
  }
  json["timing"] = fmt::format("median of {} repeats, one thread", opt.repeats);

  // 3. Temporal: the first map rotating about +Y, 0.5°/frame, on a 16×4×16 grid with per-probe
  // intensity and phase, plus 1 % Gaussian noise per coefficient (relative to the DC).
  nlohmann::json temporal = nlohmann::json::array();
  std::vector<imaging::ChartSeries> temporalSeries;
  if (!opt.maps.empty() && opt.frames > 1) {
    const EnvMap small = downsample(opt.maps[0], std::max(1, opt.maps[0].width / 128));
    StreamLayout layout;
    layout.grid[0] = 16;
    layout.grid[1] = 4;
    layout.grid[2] = 16;
    layout.brickDim = 4;
    const uint32_t count = probeCount(layout);
    const int phases = 8;
    const float noise = 0.01f;
    const float degPerFrame = 0.5f;
    say(fmt::format("temporal: {} frames of {} probes from {} ({} phases)", opt.frames, count, small.name, phases));
    std::vector<float> clean(static_cast<size_t>(opt.frames) * count * kProbeFloats);
    std::vector<float> noisy(clean.size());
    std::mt19937 nrng(2);
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    std::vector<float> gain(count);
    for (uint32_t p = 0; p < count; ++p) gain[p] = 0.3f + 1.7f * static_cast<float>((p * 2654435761u) % 1000u) / 1000.0f;
    for (int f = 0; f < opt.frames; ++f) {
      Probe byPhase[phases];
      for (int k = 0; k < phases; ++k)
        projectToSh(small, byPhase[k].data(), (static_cast<float>(f) * degPerFrame + 15.0f * static_cast<float>(k)) * kPi / 180.0f);
      for (uint32_t p = 0; p < count; ++p) {
        const Probe& src = byPhase[(p / 256) * 2 % phases + (p % 2)];
        float* c = &clean[(static_cast<size_t>(f) * count + p) * kProbeFloats];
        float* n = &noisy[(static_cast<size_t>(f) * count + p) * kProbeFloats];
        for (int i = 0; i < kProbeFloats; ++i) {
          c[i] = src[i] * gain[p];
          n[i] = c[i] + noise * c[i % 3] * gauss(nrng);
        }
      }
    }
    // One stream over the sequence: its bytes, its error against the clean input, drift.
    const auto runStream = [&](Representation repr, int dz, float errorBound, imaging::ChartSeries& series) {
      layout.repr = repr;
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
      for (int f = 0; f < opt.frames; ++f) {
        const size_t at = static_cast<size_t>(f) * count * kProbeFloats;
        const auto t0 = Clock::now();
        encoder.update(noisy.data() + at, nullptr);
        encoder.writeChangedFrame(frame);
        const auto t1 = Clock::now();
        driftFree = driftFree && decoder.apply(frame.data(), frame.size()) == CodecStatus::Ok;
        const auto t2 = Clock::now();
        if (f > 0) {
          encodeNs.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / count);
          decodeNs.push_back(std::chrono::duration<double, std::nano>(t2 - t1).count() / count);
        }
        if (f == 0) {
          keyBytes = frame.size();
          continue;
        }
        deltaBytes += frame.size();
        for (uint32_t p = 0; p < count; ++p)
          irradianceEnergy(decoder.probes() + static_cast<size_t>(p) * kProbeFloats,
                           clean.data() + at + static_cast<size_t>(p) * kProbeFloats, err, energy);
      }
      driftFree = driftFree && std::memcmp(decoder.probes(), encoder.reconstruction(),
                                           static_cast<size_t>(count) * kProbeFloats * sizeof(float)) == 0;
      const double perProbeFrame = static_cast<double>(deltaBytes) / (static_cast<double>(opt.frames - 1) * count);
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
        nlohmann::json bricks = nlohmann::json::object();  // bricks per representation after the last frame
        for (uint32_t b = 0; b < brickCount(layout); ++b)
          bricks[representationName(encoder.brickRepresentation(b))] =
              bricks.value(representationName(encoder.brickRepresentation(b)), 0) + 1;
        t["bricks_by_representation"] = bricks;
      }
      temporal.push_back(t);
      series.points.push_back(
          {perProbeFrame, rmse, errorBound > 0.0f ? fmt::format("{:g}%", 100 * errorBound) : fmt::format("dz{}", dz)});
    };
    for (Representation repr : kAllRepresentations) {
      imaging::ChartSeries series{std::string(representationName(repr)) + " stream", {}, true};
      for (int dz : opt.deadzones) {
        if (repr == Representation::Fp16 && dz > 0) continue;  // fp16 steps are not ratio steps
        runStream(repr, dz, 0.0f, series);
      }
      temporalSeries.push_back(std::move(series));
    }
    imaging::ChartSeries bounded{"l2 stream, per-brick representation (dz1)", {}, true};
    for (float bound : opt.errorBounds) runStream(Representation::L2, 1, bound, bounded);
    if (!bounded.points.empty()) temporalSeries.push_back(std::move(bounded));
    json["temporal"] = {{"grid", {16, 4, 16}},
                        {"brick", 4},
                        {"frames", opt.frames},
                        {"map", small.name},
                        {"rotation_deg_per_frame", degPerFrame},
                        {"noise_rel_dc", noise},
                        {"raw_fp16_grid_bytes_per_probe_per_frame", 56},
                        {"error", "irradiance relative RMSE of the decoded stream against the noise-free float L2, "
                                  "frames 1.., exact over the sphere"},
                        {"results", temporal}};
  }
  json["temporal_results_note"] = "bytes include frame and section headers; zstd level 3";

  // Table.
  std::string table = mapProbes.empty() ? "(no environment maps: the error columns below are empty)\n" : "";
  table += fmt::format("{:<6} {:>8} {:>14} {:>14} {:>14} {:>14}\n", "repr", "B/probe", "E rmse (true)",
                                  "vs float L2", "encode Mpr/s", "decode Mpr/s");
  for (Representation repr : kAllRepresentations) {
    const StaticResult& r = results[representationName(repr)];
    table += fmt::format("{:<6} {:>8} {:>13.2f}% {:>13.3f}% {:>14.2f} {:>14.2f}\n", representationName(repr),
                         recordSize(repr), 100 * r.rmseTrue, 100 * r.rmseFloat, r.encodeRate / 1e6,
                         r.decodeRate / 1e6);
  }
  table += fmt::format("float baselines (E rmse vs true): l1 {:.2f}%  zh3h {:.2f}%  zh3 {:.2f}%  l2 {:.2f}%\n",
                       100 * baselines["l1"].get<double>(), 100 * baselines["zh3h"].get<double>(),
                       100 * baselines["zh3"].get<double>(), 100 * baselines["l2"].get<double>());
  table += zh3hTable;
  table += volumeTable;
  if (!temporal.empty()) {
    table += fmt::format("\ntemporal ({} frames, 1024 probes, 1% noise): {:<6} {:>4} {:>14} {:>14} {:>12}\n", opt.frames,
                         "repr", "dz", "B/probe/frame", "E rmse (clean)", "enc/dec ns");
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
  }

  // Chart: error against bytes.
  imaging::ChartSeries keyframes{"records (static maps)", {}, false};
  for (Representation repr : kAllRepresentations)
    keyframes.points.push_back({static_cast<double>(recordSize(repr)), results[representationName(repr)].rmseTrue,
                                representationName(repr)});
  std::vector<imaging::ChartSeries> all{keyframes};
  all.insert(all.end(), temporalSeries.begin(), temporalSeries.end());
  imaging::ChartSpec spec;
  spec.title = "probecast codec: irradiance error against bytes per probe";
  spec.xLabel = "bytes per probe (records) / per probe per frame (streams)";
  spec.yLabel = "irradiance relative RMSE";
  spec.logX = true;
  spec.logY = true;
  spec.footnote = opt.command;
  return {json, table, imaging::renderSvgChart(spec, all)};
}

}  // namespace probecast::bench
