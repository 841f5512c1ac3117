// The parts of `probecast bench codec` (codec_bench.h) that its files share: the maps' probes,
// each representation's records, the baked volume and the temporal sequence, and what they measure.
#pragma once

#include <array>
#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "codec_bench.h"
#include "probecast/codec/record.h"
#include "probecast/codec/stream.h"
#include "probecast/imaging/svg_chart.h"

namespace probecast::bench::codecs {

using Clock = std::chrono::steady_clock;
using Probe = std::array<float, kProbeFloats>;

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

inline constexpr int kTemporalPhases = 8;
inline constexpr float kTemporalNoise = 0.01f;
inline constexpr float kDegPerFrame = 0.5f;

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

// The phases (codec_records.cpp): each map's float L2 probe and true irradiance; what each float
// variant loses before quantisation; the throughput set; one representation's records; zh3h per
// map; the baked volume.
void irradianceEnergy(const float* test, const float* ref, double& err, double& energy);
// Bricks per representation of an encoder's layout.
nlohmann::json bricksByRepresentation(const StreamEncoder& encoder, const StreamLayout& layout);
MapProbes projectMaps(const CodecBenchOptions& opt);
std::map<std::string, double> floatBaselines(const MapProbes& maps);
std::vector<Probe> throughputSet(const CodecBenchOptions& opt, const MapProbes& maps);
StaticResult measureRecords(Representation repr, const MapProbes& maps, const std::vector<Probe>& many, int repeats);
nlohmann::json zh3hPerMap(const MapProbes& maps, const std::map<std::string, StaticResult>& results);
VolumeResult measureVolume(const CodecBenchOptions& opt);
// The temporal sequence through the stream coder (codec_temporal.cpp).
CodecMetrics::Temporal measureTemporal(const CodecBenchOptions& opt);

}  // namespace probecast::bench::codecs
