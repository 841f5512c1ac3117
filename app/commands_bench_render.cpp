// `probecast bench raster|scene|pipeline|environment`: the raster client and the reference tracer
// measured against references.
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "commands.h"
#include "commands_bench.h"
#include "environment_bench.h"
#include "panel_bench.h"
#include "pipeline_bench.h"
#include "progress.h"
#include "raster_bench.h"
#include "scene_bench.h"
#include "scene_options.h"

namespace probecast::app {
namespace {

// What `bench raster` and `bench scene` share: the view size, probe updates, timed repeats, the
// reference (samples, cache folder) and the shadow maps.
struct RenderBenchCli {
  std::vector<uint32_t>* size;
  uint32_t* updates;
  uint32_t* repeats;
  uint32_t* referenceSpp;
  std::string* referenceCache;
  uint32_t* shadowMap;
  void add(CLI::App* cmd, const std::string& updatesWhat, const std::string& repeatsWhat) const {
    addSizeOption(cmd, *size, "size of each view WxH", 8, 4096);
    cmd->add_option("--updates", *updates, updatesWhat)->check(CLI::Range(1, 10000));
    cmd->add_option("--repeats", *repeats, repeatsWhat)->check(CLI::Range(1, 1000));
    addReferenceSppOption(cmd, *referenceSpp, 1u << 20, "samples per pixel of the reference (two halves of different seeds)");
    cmd->add_option("--reference-cache", *referenceCache,
                    "folder of cached references (default $XDG_CACHE_HOME/probecast/references or ~/.cache/...)");
    cmd->add_option("--shadow-map", *shadowMap, "shadow map texels per side")->check(CLI::Range(16, 8192));
  }
};

}  // namespace

// `probecast bench raster`: raster client speed and accuracy.
void addBenchRaster(CLI::App* bench) {
  CLI::App* raster = bench->add_subcommand("raster", "raster client: ms per view for 1..48 views, PSNR/SSIM per representation");
  auto rt = std::make_shared<TracingOptions>();
  struct RasterOptions {
    std::string json, chart;
    std::vector<uint32_t> size{320, 200};
    bench::RasterBenchOptions bench;
    AreaLightCli areaLights{"off"};  // a benchmark's figures do not move with the product's default
  };
  auto ro = std::make_shared<RasterOptions>();
  rt->add(raster);
  raster->add_option("--views", ro->bench.viewSets, "view sets to time (mono, stereo, lf:NxM, lfh:NxM), comma-separated")
      ->delimiter(',');
  RenderBenchCli{&ro->size, &ro->bench.updates, &ro->bench.repeats, &ro->bench.referenceSpp, &ro->bench.referenceCache,
                 &ro->bench.raster.shadowMapSize}
      .add(raster, "probe updates before rendering", "timed renders per case (median)");
  addShadowCascadesOption(raster, ro->bench.raster.shadowCascades);
  raster->add_option("--supersample", ro->bench.raster.samplesPerSide,
                     "N × N raster samples per pixel, averaged (1 here, so the timings compare like with like; "
                     "the viewers default to 4)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  addRasterFilterOptions(raster, ro->bench.raster.msaaSamples, ro->bench.raster.anisotropy);
  addVisibilityOption(raster, ro->bench.raster.visibility);
  ro->areaLights.add(raster);
  addJsonOption(raster, ro->json);
  raster->add_option("--chart", ro->chart, "write an SVG chart of PSNR against ms here (and *_views.svg)");
  raster->callback([=] {
    ro->bench.scene = rt->scene.load();
    ro->bench.grid = rt->grid.resolve(ro->bench.scene);
    ro->bench.updater = rt->updater(rt->scene.environment.load());  // the reference and background too
    ro->bench.updater.areaLights = ro->bench.raster.areaLights = ro->areaLights.options();
    ro->bench.context = rt->device.context();
    ro->bench.width = ro->size[0];
    ro->bench.height = ro->size[1];
    ro->bench.command = commandLine();
    ro->bench.progress = progressLine;
    const bench::RasterBenchResult r = bench::runRasterBench(ro->bench);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", ro->json, r.svg, ro->chart);
    if (!ro->chart.empty()) {
      std::string views = ro->chart;
      const size_t dot = views.rfind(".svg");
      views = (dot == std::string::npos ? views : views.substr(0, dot)) + "_views.svg";
      writeTextFile(views, r.svgViews);
      fmt::print("wrote {}\n", views);
    }
  });
}

// `probecast bench panel`: a Looking Glass panel frame, phase by phase, for ways of drawing its views.
void addBenchPanel(CLI::App* bench) {
  CLI::App* cmd = bench->add_subcommand(
      "panel", "a Looking Glass panel frame: ms per phase and PSNR against full-quality views, per way of drawing them");
  auto pt = std::make_shared<TracingOptions>();
  struct PanelCli {
    std::string json, calibration;
    std::vector<std::string> ways{"msaa4", "msaa1", "half", "narrow", "multiview"};
    std::vector<uint32_t> size;
    bench::PanelBenchOptions bench;
    AreaLightCli areaLights{"off"};
  };
  auto po = std::make_shared<PanelCli>();
  pt->add(cmd);
  cmd->add_option("--looking-glass", po->calibration, "the display's calibration (visual.json)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--ways", po->ways, "ways of drawing the views: msaa4 (the viewers' default), msaa1, half, narrow (half the width), multiview, ss2")
      ->delimiter(',')
      ->capture_default_str();
  addSizeOption(cmd, po->size, "size of each view WxH (default: the display model's)", 8, 4096);
  cmd->add_option("--updates", po->bench.updates, "probe updates before drawing")->check(CLI::Range(1, 10000));
  cmd->add_option("--repeats", po->bench.repeats, "timed frames per way (median)")->check(CLI::Range(1, 1000));
  addVisibilityOption(cmd, po->bench.raster.visibility);
  po->areaLights.add(cmd);
  addJsonOption(cmd, po->json);
  cmd->callback([=] {
    for (const std::string& name : po->ways) {
      bench::PanelWay way;
      std::string error;
      if (!bench::panelWay(name, way, error)) throw std::runtime_error("--ways: " + error);
      po->bench.ways.push_back(way);
    }
    po->bench.calibration = renderer::loadLookingGlassCalibration(po->calibration);
    if (!po->size.empty()) po->bench.viewWidth = po->size[0], po->bench.viewHeight = po->size[1];
    po->bench.scene = pt->scene.load();
    po->bench.grid = pt->grid.resolve(po->bench.scene);
    po->bench.updater = pt->updater(pt->scene.environment.load());
    po->bench.updater.areaLights = po->bench.raster.areaLights = po->areaLights.options();
    po->bench.context = pt->device.context();
    po->bench.command = commandLine();
    po->bench.progress = progressLine;
    const bench::PanelBenchResult r = bench::runPanelBench(po->bench);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", po->json, "", "");
  });
}

// `probecast bench scene`: the seeds' table for one scene against cached references.
void addBenchScene(CLI::App* bench) {
  CLI::App* cmd = bench->add_subcommand(
      "scene", "one scene: update ms, raster ms per view, PSNR/SSIM per representation against a cached reference");
  auto st = std::make_shared<TracingOptions>();
  struct SceneCli {
    std::string json, chart;
    std::vector<uint32_t> size{160, 100};
    bench::SceneBenchOptions bench;
    AreaLightCli areaLights;
  };
  auto so = std::make_shared<SceneCli>();
  st->add(cmd);
  cmd->add_option("--views", so->bench.views, "mono, stereo or lf:NxM");
  RenderBenchCli{&so->size, &so->bench.updates, &so->bench.repeats, &so->bench.referenceSpp, &so->bench.referenceCache,
                 &so->bench.raster.shadowMapSize}
      .add(cmd, "probe updates (each timed)", "timed renders of the view set per representation (median)");
  cmd->add_option("--supersample", so->bench.raster.samplesPerSide,
                  "N × N raster samples per pixel, averaged (as the reference averages each pixel's area)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  addRasterFilterOptions(cmd, so->bench.raster.msaaSamples, so->bench.raster.anisotropy);
  addVisibilityOption(cmd, so->bench.raster.visibility);
  so->areaLights.add(cmd);  // the reference sees every emitter either way, so the cached one still serves
  cmd->add_option("--reference-bounces", so->bench.referenceBounces, "surface interactions per reference path")
      ->check(CLI::Range(1, 16));
  cmd->add_option("--reference-seed", so->bench.referenceSeed, "seed of the first half-reference");
  cmd->add_option("--images", so->bench.imagesDir, "write PNGs of the reference and every representation here");
  cmd->add_option("--exposure", so->bench.exposure, "scale applied to the PNGs only")->check(CLI::Range(1e-6f, 1e6f));
  addJsonOption(cmd, so->json);
  cmd->add_option("--chart", so->chart, "write an SVG chart of PSNR against ms per view here");
  cmd->callback([=] {
    bench::SceneBenchOptions& o = so->bench;
    o.width = so->size[0];
    o.height = so->size[1];
    bench::checkSceneBenchOptions(o);  // before loading a large scene
    o.scene = st->scene.load();
    o.t = st->scene.t;
    o.grid = st->grid.resolve(o.scene);
    o.updater = st->updater(st->scene.environment.load());
    o.updater.areaLights = o.raster.areaLights = so->areaLights.options();
    o.context = st->device.context();
    o.command = commandLine();
    o.progress = progressLine;
    const bench::SceneBenchResult r = bench::runSceneBench(o);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", so->json, r.svg, so->chart);
  });
}

// `probecast bench pipeline`: PSNR against wire bytes, update time, representation.
void addBenchPipeline(CLI::App* bench) {
  CLI::App* pipeline = bench->add_subcommand("pipeline", "PSNR against wire bytes, update time and representation");
  auto pt = std::make_shared<TracingOptions>();
  struct PipelineCli {
    std::string json, chart;
    std::vector<uint32_t> size{160, 100};
    bench::PipelineBenchOptions bench;
  };
  auto po = std::make_shared<PipelineCli>();
  pt->add(pipeline, false);
  addSizeOption(pipeline, po->size, "image size WxH", 8, 4096);
  addReferenceSppOption(pipeline, po->bench.referenceSpp, 1u << 20);
  pipeline->add_option("--reference-cache", po->bench.referenceCache,
                       "folder of cached references (default $XDG_CACHE_HOME/probecast/references or ~/.cache/...)");
  pipeline->add_option("--spps", po->bench.spps, "samples per probe to try")->delimiter(',')->check(CLI::Range(1, 1 << 16));
  pipeline->add_option("--bounces", po->bench.bounces, "bounce limits to try")->delimiter(',')->check(CLI::Range(1, 16));
  pipeline->add_option("--deadzones", po->bench.deadzones, "dead-zones to try")->delimiter(',')->check(CLI::Range(0, 127));
  pipeline->add_option("--frames", po->bench.streamFrames, "moving-light frames streamed")->check(CLI::Range(2, 10000));
  addJsonOption(pipeline, po->json);
  pipeline->add_option("--chart", po->chart, "SVG prefix: writes PREFIX_bytes.svg, PREFIX_update.svg, PREFIX_repr.svg");
  pipeline->callback([=] {
    po->bench.sceneSpec = pt->scene.scene;
    po->bench.scene = pt->scene.load();
    po->bench.t = pt->scene.t;
    po->bench.grid = pt->grid.resolve(po->bench.scene);
    po->bench.context = pt->device.context();
    po->bench.environment = pt->scene.environment.load();
    po->bench.width = po->size[0];
    po->bench.height = po->size[1];
    po->bench.command = commandLine();
    po->bench.progress = progressLine;
    const bench::PipelineBenchResult r = bench::runPipelineBench(po->bench);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", po->json, "", "");
    if (!po->chart.empty())
      for (const auto& [suffix, svg] : {std::pair{"_bytes.svg", &r.svgBytes}, std::pair{"_update.svg", &r.svgUpdate},
                                        std::pair{"_repr.svg", &r.svgRepr}}) {
        writeTextFile(po->chart + suffix, *svg);
        fmt::print("wrote {}{}\n", po->chart, suffix);
      }
  });
}

// `probecast bench environment`: environment importance sampling against BSDF-only sampling.
void addBenchEnvironment(CLI::App* bench) {
  CLI::App* cmd = bench->add_subcommand(
      "environment", "reference tracer convergence under a small sun: environment importance sampling vs BSDF only");
  struct EnvironmentCli {
    SceneOptions scene;
    DeviceOptions device;
    std::string json, chart;
    std::vector<uint32_t> size{48, 32};
    bench::EnvironmentBenchOptions bench;
  };
  auto eo = std::make_shared<EnvironmentCli>();
  eo->scene.add(cmd);
  eo->device.add(cmd);
  addSizeOption(cmd, eo->size, "image size WxH", 4, 1024);
  addReferenceSppOption(cmd, eo->bench.referenceSpp, 1u << 20);
  cmd->add_option("--spps", eo->bench.spps, "samples per pixel to measure")->delimiter(',')->check(CLI::Range(1, 1 << 16));
  cmd->add_option("--bounces", eo->bench.maxBounces, "surface interactions per path")->check(CLI::Range(1, 16));
  addJsonOption(cmd, eo->json);
  cmd->add_option("--chart", eo->chart, "write an SVG chart of RMS error against spp here");
  cmd->callback([eo, cmd] {
    // Without --scene: a sunlit yard built in; without --environment or --sky: the built-in sunny sky.
    if (cmd->get_option("--scene")->count() > 0) {
      eo->bench.scene = eo->scene.load();
      eo->bench.camera = renderer::CameraView::fromScene(eo->bench.scene);
    } else {
      eo->bench.scene = bench::sunlitYard(eo->bench.camera);
    }
    eo->bench.environment = eo->scene.environment.given() ? eo->scene.environment.load() : bench::builtinSunSky();
    eo->bench.context = eo->device.context();
    eo->bench.width = eo->size[0];
    eo->bench.height = eo->size[1];
    eo->bench.command = commandLine();
    eo->bench.progress = progressLine;
    const bench::EnvironmentBenchResult r = bench::runEnvironmentBench(eo->bench);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", eo->json, r.svg, eo->chart);
  });
}

}  // namespace probecast::app
