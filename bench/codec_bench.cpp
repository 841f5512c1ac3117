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
#include "codec_parts.h"

namespace probecast::bench {

using namespace codecs;

namespace {

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
