// `probecast view`: render mono, stereo or light-field views of a scene lit by a probe volume.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <filesystem>

#include <fmt/format.h>

#include "commands.h"
#include "live_window.h"
#include "probecast/imaging/image_io.h"
#include "probecast/renderer/looking_glass.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/service/client.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/scene_state.h"
#include "probecast/session/viewer.h"
#include "scene_options.h"
#include "view.h"

namespace probecast::app {

imaging::ToneMap toneMapOf(const ViewOptions& o) {
  imaging::ToneMap toneMap = imaging::ToneMap::Filmic;
  imaging::parseToneMap(o.toneMap, toneMap);
  return toneMap;
}

void printAreaLights(const AreaLightRule& rule, const scene::AreaLightSet& set) {
  if (rule.on())
    fmt::print("view: client area lights on as the probes say (emitters of at least {} of the power): {} lights\n",
               rule.minPowerFraction, set.lights.size());
  else
    fmt::print("view: client area lights off (the probes hold every emitter)\n");
}

namespace {

// quilt.png (tone-mapped), quilt.exr and, with --exr, every view as an EXR.
void writeViews(const ViewOptions& o, const Rendered& r, const std::vector<renderer::ViewInfo>& views,
                const renderer::ViewSetSpec& spec) {
  std::filesystem::create_directories(o.out);
  const renderer::Image quilt = renderer::composeQuilt(r.images, views, spec.columns, spec.rows);
  const auto w = static_cast<int>(quilt.width), h = static_cast<int>(quilt.height);
  imaging::ToneMap toneMap = imaging::ToneMap::Filmic;
  imaging::parseToneMap(o.toneMap, toneMap);
  std::string error;
  orThrow(imaging::writePngPreview(o.out + "/quilt.png", quilt.rgb, w, h, o.exposure, error, toneMap) &&
              imaging::writeExr(o.out + "/quilt.exr", quilt.rgb, w, h, error),
          error);
  if (o.exr)
    for (size_t k = 0; k < r.images.size(); ++k)
      orThrow(imaging::writeExr(fmt::format("{}/view_{:02}.exr", o.out, k), r.images[k].rgb, static_cast<int>(o.size[0]),
                              static_cast<int>(o.size[1]), error),
              error);
}

// Where the probes come from: traced here, a file, or a server (--connect and its limits, --wait).
void addViewProbeOptions(CLI::App* cmd, ViewOptions& o) {
  o.tracing.add(cmd);
  cmd->add_option("--probes", o.probes, "probe volume file, or 'live' to trace it now");
  cmd->add_option("--updates", o.updates, "live: updates to accumulate")->check(CLI::Range(1, 100000));
  o.connection.add(cmd, "take the probes from a probecast server (host:port) instead", false, true);
  o.connection.addLimits(cmd);
  cmd->add_option("--wait", o.waitSeconds, "--connect: seconds to receive the stream before rendering")
      ->check(CLI::Range(0.1, 3600.0));
}

// The views drawn: their set (or a Looking Glass's), their size and their samples per pixel.
void addViewSetOptions(CLI::App* cmd, ViewOptions& o) {
  o.viewsOption =
      cmd->add_option("--views", o.views,
                      "mono, stereo, lf:NxM (full parallax) or lfh:NxM (horizontal, Looking Glass quilt); default "
                      "lf:5x5, mono in a --window");
  o.sizeOption = addSizeOption(cmd, o.size, "size of each view WxH", 1, 8192);
  cmd->add_option("--looking-glass", o.lookingGlass,
                  "a Looking Glass display's calibration (visual.json): render its model's view set (Portrait 8x6 "
                  "views 560 pixels high, Go 11x6 of 682, 16\" and 32\" in both orientations...; unknown serials "
                  "8x6 on portrait panels, 5x9 on others, 560 high; --size sets their pixels, the views keep the "
                  "panel's aspect) across its view cone, and interleave it for the panel: looking_glass.png/.exr "
                  "beside the quilt, or the window (with --fullscreen on the display)")
      ->check(CLI::ExistingFile)
      ->excludes(o.viewsOption);
  cmd->add_option("--supersample", o.supersample,
                  "N × N raster samples per pixel, averaged (as a reference averages the pixel's footprint; 1: "
                  "one sample at the pixel's centre, about N² times faster)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  addRasterFilterOptions(cmd, o.msaa, o.anisotropy);
}

// The files written: the folder, the PNG's exposure, EXRs of every view.
void addViewOutputOptions(CLI::App* cmd, ViewOptions& o) {
  cmd->add_option("--out", o.out, "output folder");
  cmd->add_option("--exposure", o.exposure, "scale for the PNG only")->check(CLI::Range(1e-6f, 1e6f));
  cmd->add_flag("--exr", o.exr, "also write every view as a linear EXR");
  addViewSequenceOptions(cmd, o);
}

// How the probes light the views: their representation, the passes, shadows, probe visibility and
// the client's area lights.
void addViewShadingOptions(CLI::App* cmd, ViewOptions& o) {
  addRepresentationOption(cmd, o.repr,
                          "local probes: pass them through the codec first (float = as traced); --connect: ask the "
                          "server for this representation (float = the server's; a coarser one is transcoded)",
                          true);
  cmd->add_option("--passes", o.passes, "per-view (one pass per view) or multiview (chunks of views per pass)")
      ->check(CLI::IsMember({"per-view", "multiview"}));
  cmd->add_option("--shadow-map", o.shadowMap, "shadow map texels per side")->check(CLI::Range(16, 8192));
  addShadowCascadesOption(cmd, o.shadowCascades);
  addVisibilityOption(cmd, o.visibility);
  cmd->add_option("--visibility-reach", o.visibilityReach,
                  "probe visibility sees this many times 1.5 cell diagonals far (0: no limit)")
      ->check(CLI::Range(0.0f, 1e6f));
  cmd->add_option("--visibility-culling", o.visibilityCulling,
                  "on: each depth-cube face draws only the triangles within reach; off: all (same result)");
  o.areaLights.add(cmd, /*follows=*/true);
}

// The raster client's options as the command line sets them, lit by `environment`.
renderer::RasterOptions rasterOptionsOf(const ViewOptions& o,
                                        const std::shared_ptr<const renderer::Environment>& environment) {
  renderer::RasterOptions ro;
  ro.passes = o.passes == "multiview" ? renderer::ViewPasses::Multiview : renderer::ViewPasses::PerView;
  ro.shadowMapSize = o.shadowMap;
  ro.shadowCascades = o.shadowCascades;
  ro.visibility = o.visibility;
  ro.visibilityReach = o.visibilityReach;
  ro.visibilityCulling = o.visibilityCulling;
  ro.environment = environment;
  ro.samplesPerSide = o.supersample;
  ro.msaaSamples = o.msaa;
  ro.anisotropy = o.anisotropy;
  return ro;
}

void runView(ViewOptions& o) {
  if (o.window.enabled && o.viewsOption->count() == 0) o.views = "mono";  // a window: one view unless asked
  checkSequenceOptions(o);
  renderer::ViewSetSpec spec;
  std::string error;
  orThrow(renderer::parseViewSet(o.views, spec, error), error);
  std::string sceneSpec = o.tracing.scene.scene;
  double t = o.tracing.scene.t;
  std::shared_ptr<const renderer::Environment> environment;
  session::ViewerScene streamed;
  if (!o.connection.connect.empty()) {
    if (o.tracing.scene.tOption->count() > 0)
      throw std::runtime_error("--time: a viewer of a stream draws at the stream's scene clock");
    streamed = streamScene(o);
    o.streamScene = streamed.hash;
    sceneSpec = streamed.spec;
    t = streamed.time;
    environment = streamed.environmentFile.empty() && streamed.lighting.kind == service::SceneLighting::Kind::None
                      ? o.tracing.scene.environment.load()
                      : loadLighting(streamed.lighting, streamed.environmentFile);
  } else {
    environment = o.tracing.scene.environment.load();  // background, and the light of live probes
  }
  const scene::Scene s = session::loadSceneOrThrow(sceneSpec, t, streamed.packaged ? &*streamed.packaged : nullptr);
  std::optional<renderer::LookingGlassCalibration> lg;
  if (!o.lookingGlass.empty()) lg = lookingGlassViewSet(o, spec);
  renderer::ViewSetOptions vso = session::viewSetOptions(s, o.size[0], o.size[1]);
  if (lg)  // the panel's views have its aspect, whatever --size draws them at (narrow views: wide pixels)
    vso.lfConeDeg = lg->viewCone, vso.aspect = static_cast<float>(lg->screenW) / static_cast<float>(lg->screenH);
  const std::vector<renderer::ViewInfo> views = renderer::makeViewSet(renderer::CameraView::fromScene(s), spec, vso);
  // Only live probes are traced here: every other viewer rasterises, on any Vulkan 1.3 device.
  renderer::ContextOptions co =
      o.tracing.device.context(/*rayTracing=*/o.connection.connect.empty() && o.probes == "live");
  if (o.window.enabled) co = LiveWindowOptions::presenting(co);
  renderer::VulkanContext context(co);
  const renderer::RasterOptions ro = rasterOptionsOf(o, environment);
  renderer::checkRasterSize(o.size[0], o.size[1], ro);  // before any tracing or connecting
  if (!o.window.enabled && !o.window.headTrace.empty()) return writeSequence(o, context, s, spec, vso, ro);
  if (o.window.enabled) {
    if (o.connection.connect.empty())
      windowLocal(o, context, s, spec, vso, ro, lg ? &*lg : nullptr);
    else
      windowFromServer(o, context, s, sceneSpec, spec, vso, ro, lg ? &*lg : nullptr);
    return;
  }
  const Rendered r = o.connection.connect.empty() ? renderLocal(o, context, s, views, ro)
                                                  : renderFromServer(o, context, s, sceneSpec, views, ro);
  writeViews(o, r, views, spec);
  if (lg) writeLookingGlass(o, context, r.images, views, *lg);
  fmt::print("view: {} {} views of {}x{} ({}² samples per pixel) on {}: {:.1f} ms per view, shadow maps {:.1f} ms; "
             "wrote {}/quilt.png and quilt.exr\n",
             o.views, views.size(), o.size[0], o.size[1], o.supersample, context.deviceName(),
             r.viewsMs / static_cast<double>(views.size()), r.shadowMs, o.out);
}

}  // namespace

void addViewCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("view", "render views (mono, stereo, lf:NxM quilt) lit by probes");
  auto o = std::make_shared<ViewOptions>();
  // --help lists the options in the order they are added here (and docs/CLI.md is made from it).
  addViewProbeOptions(cmd, *o);
  addViewSetOptions(cmd, *o);
  addViewOutputOptions(cmd, *o);
  addViewShadingOptions(cmd, *o);
  o->window.add(cmd);
  cmd->add_option("--scene-cache", o->sceneCache,
                  "--connect: folder of scenes fetched from servers, by hash (default $PROBECAST_SCENE_CACHE, else "
                  "~/.cache/probecast/scenes)");
  cmd->add_option("--scene-max-bytes", o->sceneMaxBytes, "--connect: the largest scene this viewer fetches")
      ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 40))
      ->capture_default_str();
  cmd->add_option("--tonemap", o->toneMap, "PNG tone map: filmic or gamma")->check(CLI::IsMember({"filmic", "gamma"}));
  cmd->callback([o] { runView(*o); });
}

}  // namespace probecast::app
