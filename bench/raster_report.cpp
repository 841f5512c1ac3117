// The report of `probecast bench raster`: its JSON, table and charts.
#include <fmt/format.h>

#include "probecast/imaging/svg_chart.h"
#include "probecast/renderer/raster_client.h"
#include "raster_parts.h"

namespace probecast::bench::rasters {

nlohmann::json rasterJson(const RasterBenchOptions& o, const std::string& device, const Reference& ref,
                          const RasterMetrics& m) {
  nlohmann::json json;
  json["command"] = o.command;
  json["scene"] = o.scene.name;
  json["device"] = device;
  json["size"] = {o.width, o.height};
  json["grid"] = {o.grid.dims[0], o.grid.dims[1], o.grid.dims[2]};
  json["probe_updates"] = o.updates;
  json["reference_spp"] = o.referenceSpp;
  json["reference_key"] = ref.key;
  json["floor_psnr_db"] = ref.floor.psnrDb;
  json["reference_psnr_db_estimate"] = ref.accuracyDb;
  json["shadow_map_size"] = o.raster.shadowMapSize;
  json["shadow_cascades"] = o.raster.shadowCascades;
  json["supersample"] = o.raster.samplesPerSide;  // ms per view are for the supersampled size
  json["msaa_samples"] = o.raster.msaaSamples;
  json["texture_anisotropy"] = o.raster.anisotropy;
  json["area_lights"] = o.raster.areaLights.enabled;
  json["metric"] = "PSNR (RGB) and SSIM (luminance) after plain gamma 2.2 on both images, no clamping first";
  if (!m.quality.empty()) json["shadow_ms"] = m.firstShadowMs;
  for (const Quality& q : m.quality)
    json["representations"].push_back({{"representation", q.r.name},
                                       {"record_bytes", q.r.viaCodec ? recordSize(q.r.repr) : 108},
                                       {"psnr_db", q.metrics.psnrDb},
                                       {"ssim", q.metrics.ssim},
                                       {"ms_per_view", q.msPerView}});
  json["visibility"] = {{"on", m.visibilityOn},
                        {"build_render_ms", m.visibilityRenderMs},
                        {"build_moments_ms", m.visibilityMomentsMs},
                        {"bytes_per_probe", renderer::RasterRenderer::visibilityBytesPerProbe()}};
  json["multiview_chunk"] = m.multiviewChunk;
  for (const ViewSetSpeed& v : m.viewSets)
    json["view_sets"].push_back(
        {{"views", v.name},
         {"count", v.count},
         {"per_view_pass", {{"ms_per_view_set", v.setMs[0]}, {"ms_per_view", v.perViewMs[0]}}},
         {"multiview", {{"ms_per_view_set", v.setMs[1]}, {"ms_per_view", v.perViewMs[1]}}},
         {"shadow_ms", v.shadowMs},
         {"area_shadow_ms", v.areaShadowMs},
         {"producer_view_weights", {{"views_sampled", v.producer.viewsSampled},
                                    {"samples", v.producer.samples},
                                    {"surfaces_ms_median", v.producer.surfacesMs},
                                    {"direct_light_ms_median", v.producer.directMs},
                                    {"weights_ms_median", v.producer.weightsMs}}}});
  return json;
}

std::string rasterTable(const RasterBenchOptions& o, const std::string& device, const Reference& ref,
                        const RasterMetrics& m) {
  std::string table = fmt::format("raster bench: {} at {}x{} ({}x{} supersampled, MSAA {}) on {}; reference {} spp, {}\n",
                                  o.scene.name, o.width, o.height, o.raster.samplesPerSide, o.raster.samplesPerSide,
                                  o.raster.msaaSamples, device, o.referenceSpp, describeFloor(ref));
  table += fmt::format("{:<6} {:>9} {:>7} {:>11}\n", "repr", "PSNR dB", "SSIM", "ms/view");
  for (const Quality& q : m.quality)
    table += fmt::format("{:<6} {:>9.2f} {:>7.4f} {:>11.2f}\n", q.r.name, q.metrics.psnrDb, q.metrics.ssim, q.msPerView);
  table += fmt::format("shadow maps ({} cascades per directional light): {:.2f} ms\n", o.raster.shadowCascades,
                       m.firstShadowMs);
  table += fmt::format("visibility {}: made in {:.1f} ms (depth cubes) + {:.1f} ms (moments), {} bytes per probe\n",
                       m.visibilityOn ? "on" : "off", m.visibilityRenderMs, m.visibilityMomentsMs,
                       renderer::RasterRenderer::visibilityBytesPerProbe());
  table += fmt::format("\n{:<8} {:>6} {:>16} {:>16}\n", "views", "count", "per-view ms/view", "multiview ms/view");
  for (const ViewSetSpeed& v : m.viewSets)
    table += fmt::format("{:<8} {:>6} {:>16.2f} {:>16.2f}\n", v.name, v.count, v.perViewMs[0], v.perViewMs[1]);
  table += fmt::format("multiview chunk: {} views per pass\n", m.multiviewChunk);
  table += "producer view weights on the CPU (up to 16 views), ms: surfaces (when the views change), direct light "
           "(when the lights move), weights (every update)\n";
  for (const ViewSetSpeed& v : m.viewSets)
    table += fmt::format("  {:<8} {:>8.2f} {:>8.2f} {:>8.2f}\n", v.name, v.producer.surfacesMs, v.producer.directMs,
                         v.producer.weightsMs);
  table += fmt::format("shadow maps: punctual {:.2f} ms, {} client area lights {:.2f} ms (drawn once per plan)\n",
                       m.shadowMs, m.areaLights, m.areaShadowMs);
  return table;
}

// PSNR against ms per view per representation; ms per view against views per set, both ways.
void rasterCharts(const RasterBenchOptions& o, const RasterMetrics& m, RasterBenchResult& result) {
  imaging::ChartSeries qualitySeries{"representations (mono view)", {}, false};
  for (const Quality& q : m.quality) qualitySeries.points.push_back({q.msPerView, q.metrics.psnrDb, q.r.name});
  std::vector<imaging::ChartSeries> speedSeries = {{"one pass per view", {}, true}, {"multiview chunks", {}, true}};
  for (const ViewSetSpeed& v : m.viewSets)
    for (size_t way = 0; way < 2; ++way)
      speedSeries[way].points.push_back({static_cast<double>(v.count), v.perViewMs[way], ""});
  imaging::ChartSpec spec;
  spec.title =
      fmt::format("Raster client, {} at {}x{}: image quality against time per view", o.scene.name, o.width, o.height);
  spec.xLabel = "ms per view (mono, median)";
  spec.yLabel = "PSNR against the reference, dB";
  spec.yFromZero = false;
  spec.footnote = o.command;
  result.svg = imaging::renderSvgChart(spec, {qualitySeries});
  imaging::ChartSpec views;
  views.title =
      fmt::format("Raster client, {} at {}x{}: time per view against views per set", o.scene.name, o.width, o.height);
  views.xLabel = "views in the set";
  views.yLabel = "ms per view (median)";
  views.logX = true;
  views.footnote = o.command;
  result.svgViews = imaging::renderSvgChart(views, speedSeries);
}

}  // namespace probecast::bench::rasters
