// The parts of `probecast bench raster` (raster_bench.h) that its files share: what the bench
// measures, and the report made of it.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness.h"
#include "probecast/codec/record.h"
#include "probecast/imaging/image_metrics.h"
#include "raster_bench.h"

namespace probecast::bench::rasters {

struct Representation {
  std::string name;
  bool viaCodec = false;
  probecast::Representation repr = probecast::Representation::L2;
};


// One representation's mono view against the reference, and its speed.
struct Quality {
  Representation r;
  imaging::ImageMetrics metrics;
  double msPerView = 0;
};

// What the same views cost a producer with the noise rule on the CPU (probe_interest.h, as
// ProbeProducer uses it): their surfaces when views change, their weights every update.
struct ProducerWeights {
  size_t viewsSampled = 0, samples = 0;
  double surfacesMs = 0, directMs = 0, weightsMs = 0;  // medians
};

// One view set, drawn both ways: one pass per view, and multiview chunks.
struct ViewSetSpeed {
  std::string name;
  size_t count = 0;
  double setMs[2] = {0, 0}, perViewMs[2] = {0, 0};  // [way]
  double shadowMs = 0, areaShadowMs = 0;
  ProducerWeights producer;
};

// What the bench measures: filled by the phases below, written by the report functions.
struct RasterMetrics {
  double firstShadowMs = 0;  // drawn once, with the first representation
  std::vector<Quality> quality;
  bool visibilityOn = false;
  double visibilityRenderMs = 0, visibilityMomentsMs = 0;
  uint32_t multiviewChunk = 0;
  std::vector<ViewSetSpeed> viewSets;
  double shadowMs = 0, areaShadowMs = 0;  // after the view sets
  size_t areaLights = 0;
};

// The JSON, the table (up to the volume updates, which timeVolumeUpdates adds) and the charts.
nlohmann::json rasterJson(const RasterBenchOptions& o, const std::string& device, const Reference& ref,
                          const RasterMetrics& m);
std::string rasterTable(const RasterBenchOptions& o, const std::string& device, const Reference& ref,
                        const RasterMetrics& m);
void rasterCharts(const RasterBenchOptions& o, const RasterMetrics& m, RasterBenchResult& result);

}  // namespace probecast::bench::rasters
