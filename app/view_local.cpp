// `probecast view` on local probes (traced here with --probes live, or a file's): a render to files
// and a live window. Viewers of a server's stream are in view_stream.cpp.
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "live_window.h"
#include "progress.h"
#include "probecast/codec/probe_file.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/scene_state.h"
#include "probecast/session/viewer.h"
#include "view.h"

namespace probecast::app {

// Local probes: traced now (--probes live) or read from a file, through --repr when given, set on a
// raster client of --size.
std::unique_ptr<renderer::RasterRenderer> localRaster(const ViewOptions& o, renderer::VulkanContext& context,
                                                      const scene::Scene& s, renderer::RasterOptions ro) {
  ProbeVolume volume;
  if (o.probes == "live") {
    renderer::UpdaterOptions uo = o.tracing.updater(ro.environment);
    ro.areaLights = o.areaLights.options();
    uo.areaLights = ro.areaLights;  // the probes leave out exactly what this viewer lights
    renderer::ProbeUpdater updater(context, s, o.tracing.grid.resolve(s), uo);
    Progress progress("view", /*bar=*/false);
    for (uint32_t u = 0; u < o.updates; ++u) {
      updater.update();
      progress.update(static_cast<double>(u + 1) / o.updates, fmt::format("probe update {}/{}", u + 1, o.updates));
    }
    progress.finish();
    volume = updater.volume();
    volume.areaLights = session::areaLightRuleOf(uo.areaLights);
  } else {
    std::string error;
    orThrow(readProbeFile(o.probes, volume, error), error);
    ro.areaLights = o.areaLights.follow(volume.areaLights, o.probes);
  }
  if (o.repr != "float")
    volume = decodeAs(volume, session::parseRepresentationOrThrow(o.repr), /*zh3PerPixel=*/true);
  auto raster = std::make_unique<renderer::RasterRenderer>(context, s, o.size[0], o.size[1], ro);
  raster->setProbes(volume);
  printAreaLights(volume.areaLights, raster->areaLights());
  if (raster->visibilityActive())
    fmt::print("view: probe visibility for {} probes made in {:.1f} ms (depth cubes, {} triangles drawn) + {:.1f} ms "
               "(moments), {} bytes per probe\n",
               volume.count(), raster->timings().visibilityRenderMs, raster->timings().visibilityTriangles,
               raster->timings().visibilityMomentsMs, renderer::RasterRenderer::visibilityBytesPerProbe());
  return raster;
}

Rendered renderLocal(const ViewOptions& o, renderer::VulkanContext& context, const scene::Scene& s,
                     const std::vector<renderer::ViewInfo>& views, const renderer::RasterOptions& ro) {
  const std::unique_ptr<renderer::RasterRenderer> raster = localRaster(o, context, s, ro);
  Rendered r;
  r.images = raster->renderViews(views);
  r.viewsMs = raster->timings().viewsMs;
  r.shadowMs = raster->timings().shadowMs;
  return r;
}

// A live window on local probes: a file's, or traced one update per frame up to --updates.
void windowLocal(const ViewOptions& o, renderer::VulkanContext& context, const scene::Scene& s,
                 const renderer::ViewSetSpec& spec, const renderer::ViewSetOptions& vso, renderer::RasterOptions ro,
                 const renderer::LookingGlassCalibration* lg) {
  std::unique_ptr<renderer::ProbeUpdater> updater;
  ProbeVolume volume;
  AreaLightRule rule;
  if (o.probes == "live") {
    renderer::UpdaterOptions uo = o.tracing.updater(ro.environment);
    ro.areaLights = o.areaLights.options();
    uo.areaLights = ro.areaLights;
    updater = std::make_unique<renderer::ProbeUpdater>(context, s, o.tracing.grid.resolve(s), uo);
    rule = session::areaLightRuleOf(uo.areaLights);
  } else {
    std::string error;
    orThrow(readProbeFile(o.probes, volume, error), error);
    ro.areaLights = o.areaLights.follow(volume.areaLights, o.probes);
  }
  renderer::RasterRenderer raster(context, s, o.size[0], o.size[1], ro);
  auto upload = [&](ProbeVolume v) {
    if (o.repr != "float") v = decodeAs(v, session::parseRepresentationOrThrow(o.repr), /*zh3PerPixel=*/true);
    raster.setProbes(v);
  };
  if (!updater) upload(volume);
  uint32_t done = 0;
  FrameSource source;
  source.render = [&](const std::vector<renderer::ViewInfo>& views, bool, std::vector<renderer::Image>& images) {
    if (updater && done < o.updates) {  // the light converges on screen
      updater->update();
      ++done;
      ProbeVolume v = updater->volume();
      v.areaLights = rule;
      upload(std::move(v));
    }
    images = raster.renderViews(views);
    return true;
  };
  source.status = [&] {
    return updater ? fmt::format("traced here: update {}/{}", done, o.updates) : "probes from " + o.probes;
  };
  source.setRenderScale = [&](float scale) { raster.setRenderScale(scale); };
  showOnLookingGlass(source, context, lg);
  const renderer::CameraView start = renderer::CameraView::fromScene(s);
  runLiveWindow(o.window, context, start, spec, vso, o.size[0], o.size[1], glm::length(s.boundsMax - s.boundsMin),
                source, o.out, o.exposure, toneMapOf(o));
}

}  // namespace probecast::app
