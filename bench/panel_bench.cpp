#include "panel_bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "harness.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/stats.h"
#include "probecast/session/viewer.h"

namespace probecast::bench {
namespace {

using Clock = std::chrono::steady_clock;

// What every phase needs: the device, the probes, the base camera and the view size.
struct PanelSetup {
  const PanelBenchOptions& o;
  renderer::VulkanContext& context;
  ProbeVolume volume;
  uint32_t width = 0, height = 0;  // of each view at scale 1
};

// One way's frame: its phases' medians and its panel against the full-quality one.
struct PanelFrame {
  PanelWay way;
  uint32_t width = 0, height = 0;
  double viewsMs = 0, composeMs = 0, interleaveMs = 0, shadowMs = 0;
  imaging::ImageMetrics vsFull;
  renderer::Image panel;
};

// The views of the calibration's model across its view cone, at the panel's aspect whatever size
// they are drawn at (a narrow view has wide pixels, as the panel samples it).
std::vector<renderer::ViewInfo> panelViews(const PanelSetup& s) {
  const auto& cal = s.o.calibration;
  renderer::ViewSetOptions vso = session::viewSetOptions(s.o.scene, s.width, s.height);
  vso.lfConeDeg = cal.viewCone;
  vso.aspect = static_cast<float>(cal.screenW) / static_cast<float>(cal.screenH);  // as view --looking-glass
  const renderer::ViewSetSpec spec{renderer::ViewSetSpec::Kind::HorizontalLightField, cal.quiltColumns, cal.quiltRows};
  return renderer::makeViewSet(renderer::CameraView::fromScene(s.o.scene), spec, vso);
}

// Draws one way's frames: each phase timed, `repeats` times after one warm-up frame.
PanelFrame drawWay(const PanelSetup& s, const PanelWay& way) {
  const auto& cal = s.o.calibration;
  PanelFrame f;
  f.way = way;
  f.width = std::max<uint32_t>(1, static_cast<uint32_t>(std::lround(s.width * way.viewScaleX)));
  f.height = std::max<uint32_t>(1, static_cast<uint32_t>(std::lround(s.height * way.viewScaleY)));
  renderer::RasterOptions ro = s.o.raster;
  ro.environment = s.o.updater.environment;
  ro.samplesPerSide = way.samplesPerSide;
  ro.msaaSamples = way.msaa;
  ro.passes = way.passes;
  renderer::checkRasterSize(f.width, f.height, ro);
  renderer::RasterRenderer raster(s.context, s.o.scene, f.width, f.height, ro);
  raster.setProbes(s.volume);
  const std::vector<renderer::ViewInfo> views = panelViews(s);
  std::vector<double> viewsMs, composeMs, interleaveMs;
  for (uint32_t k = 0; k <= s.o.repeats; ++k) {  // repeats 0: one frame, timed as it is
    const std::vector<renderer::Image> images = raster.renderViews(views);
    if (k == 0) f.shadowMs = raster.timings().shadowMs;  // drawn with the first frame, then kept
    const auto t0 = Clock::now();
    const renderer::Image quilt = renderer::composeQuilt(images, views, cal.quiltColumns, cal.quiltRows);
    const auto t1 = Clock::now();
    f.panel = renderer::interleaveQuilt(s.context, quilt, cal.quiltColumns, cal.quiltRows, cal);
    if (k == 0 && s.o.repeats > 0) continue;  // the warm-up: pipelines made, memory first touched
    viewsMs.push_back(raster.timings().viewsMs);
    composeMs.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    interleaveMs.push_back(millisecondsSince(t1));
  }
  f.viewsMs = session::medianMidpoint(viewsMs);
  f.composeMs = session::medianMidpoint(composeMs);
  f.interleaveMs = session::medianMidpoint(interleaveMs);
  return f;
}

PanelWay fullQuality() {
  PanelWay w;
  w.name = "full (4x4 supersampling, 4x MSAA)";
  w.samplesPerSide = 4;
  return w;
}

nlohmann::json panelJson(const PanelSetup& s, const std::vector<PanelFrame>& frames) {
  const auto& cal = s.o.calibration;
  nlohmann::json ways = nlohmann::json::array();
  for (const PanelFrame& f : frames)
    ways.push_back({{"way", f.way.name},
                    {"samples_per_side", f.way.samplesPerSide},
                    {"msaa", f.way.msaa},
                    {"multiview", f.way.passes == renderer::ViewPasses::Multiview},
                    {"view_size", {f.width, f.height}},
                    {"views_ms", f.viewsMs},
                    {"compose_ms", f.composeMs},
                    {"interleave_ms", f.interleaveMs},
                    {"frame_ms", f.viewsMs + f.composeMs + f.interleaveMs},
                    {"shadow_ms_first_frame", f.shadowMs},
                    {"psnr_vs_full_db", f.vsFull.psnrDb},
                    {"ssim_vs_full", f.vsFull.ssim}});
  return {{"command", s.o.command},
          {"device", s.context.deviceName()},
          {"display", {{"model", cal.model}, {"serial", cal.serial}, {"panel", {cal.screenW, cal.screenH}},
                       {"views", {cal.quiltColumns, cal.quiltRows}}, {"subpixel_cells", cal.subpixelCells.size()}}},
          {"probes", {s.o.grid.dims[0], s.o.grid.dims[1], s.o.grid.dims[2]}},
          {"updates", s.o.updates},
          {"repeats", s.o.repeats},
          {"psnr", "the panel image against the panel of the same views at full quality, after gamma 2.2"},
          {"ways", ways}};
}

std::string panelTable(const PanelSetup& s, const std::vector<PanelFrame>& frames) {
  const auto& cal = s.o.calibration;
  std::string t = fmt::format("bench panel: {} ({}x{}), {} views of {}x{} on {}; medians of {} frames\n", cal.model,
                              cal.screenW, cal.screenH, cal.quiltColumns * cal.quiltRows, s.width, s.height,
                              s.context.deviceName(), s.o.repeats);
  t += fmt::format("{:<36} {:>9} {:>10} {:>8} {:>10} {:>9} {:>9}\n", "way", "view", "views ms", "quilt", "interleave",
                   "frame ms", "dB vs full");
  for (const PanelFrame& f : frames)
    t += fmt::format("{:<36} {:>9} {:>10.0f} {:>8.0f} {:>10.0f} {:>9.0f} {:>9}\n", f.way.name,
                     fmt::format("{}x{}", f.width, f.height), f.viewsMs, f.composeMs, f.interleaveMs,
                     f.viewsMs + f.composeMs + f.interleaveMs,
                     std::isfinite(f.vsFull.psnrDb) ? fmt::format("{:.2f}", f.vsFull.psnrDb) : std::string("same"));
  return t;
}

}  // namespace

bool panelWay(const std::string& name, PanelWay& out, std::string& error) {
  out = PanelWay{};
  out.name = name;
  if (name == "msaa4") return true;
  if (name == "msaa1") return out.msaa = 1, true;
  if (name == "half") return out.viewScaleX = out.viewScaleY = 0.5, true;
  if (name == "narrow") return out.viewScaleX = 0.5, true;
  if (name == "multiview") return out.passes = renderer::ViewPasses::Multiview, true;
  if (name == "ss2") return out.samplesPerSide = 2, true;
  error = "unknown way \"" + name + "\" (msaa4, msaa1, half, narrow, multiview, ss2)";
  return false;
}

PanelBenchResult runPanelBench(const PanelBenchOptions& o) {
  if (o.ways.empty()) throw std::invalid_argument("bench panel: no way of drawing the views to measure");
  if (o.repeats < 1) throw std::invalid_argument("bench panel: --repeats must be at least 1");
  renderer::VulkanContext context(o.context);
  PanelSetup s{o, context, {}, o.viewWidth, o.viewHeight};
  const auto& cal = o.calibration;
  if (!s.height) s.height = static_cast<uint32_t>(cal.viewHeight);
  if (!s.width) s.width = std::max<uint32_t>(1, static_cast<uint32_t>(std::lround(double(s.height) * cal.screenW / cal.screenH)));
  renderer::ProbeUpdater updater(context, o.scene, o.grid, o.updater);
  for (uint32_t u = 0; u < o.updates; ++u) updater.update();
  s.volume = updater.volume();
  sayProgress(o.progress, fmt::format("bench panel: {} probe updates done; the full-quality panel", o.updates));
  PanelBenchOptions once = o;
  once.repeats = 0;
  const PanelFrame full = drawWay(PanelSetup{once, context, s.volume, s.width, s.height}, fullQuality());
  std::vector<PanelFrame> frames;
  for (const PanelWay& way : o.ways) {
    sayProgress(o.progress, "bench panel: " + way.name);
    frames.push_back(drawWay(s, way));
    frames.back().vsFull = compareChecked(frames.back().panel, full.panel, "bench panel: " + way.name);
  }
  PanelBenchResult r;
  r.json = panelJson(s, frames);
  r.json["full_quality"] = {{"view_size", {full.width, full.height}}, {"views_ms", full.viewsMs}};
  r.json["validation_messages"] = context.validationMessages();
  r.table = panelTable(s, frames);
  return r;
}

}  // namespace probecast::bench
