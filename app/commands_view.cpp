// `probecast view`: render mono, stereo or light-field views of a scene lit by a probe volume.
#include <filesystem>

#include <fmt/format.h>

#include "commands.h"
#include "image_io.h"
#include "probecast/codec/probe_file.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/service/client.h"
#include "probecast/session/viewer.h"
#include "scene_options.h"

namespace probecast::app {

void addViewCommand(CLI::App& app, int& exitCode) {
  CLI::App* cmd = app.add_subcommand("view", "render views (mono, stereo, lf:NxM quilt) lit by probes");
  auto tr = std::make_shared<TracingOptions>();
  struct Options {
    std::string probes = "live", views = "lf:5x5", out = "out/view", connect, token, tlsCa, tlsName;
    std::string repr = "float", passes = "per-view", toneMap = "filmic";
    uint32_t shadowMap = 1024;
    double waitSeconds = 3.0;
    std::vector<uint32_t> size{320, 200};
    uint32_t updates = 4;
    float exposure = 1.0f;
    bool exr = false;
  };
  auto o = std::make_shared<Options>();
  tr->add(cmd);
  cmd->add_option("--probes", o->probes, "probe volume file, or 'live' to trace it now");
  cmd->add_option("--updates", o->updates, "live: updates to accumulate")->check(CLI::Range(1, 100000));
  cmd->add_option("--connect", o->connect, "take the probes from a probecast server (host:port) instead");
  cmd->add_option("--token", o->token, "bearer token for --connect");
  cmd->add_option("--tls-ca", o->tlsCa, "PEM root certificate to trust (TLS)")->check(CLI::ExistingFile);
  cmd->add_option("--tls-name", o->tlsName, "server name to check in its certificate");
  cmd->add_option("--wait", o->waitSeconds, "--connect: seconds to receive the stream before rendering")
      ->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--views", o->views, "mono, stereo, lf:NxM (full parallax) or lfh:NxM (horizontal, Looking Glass quilt)");
  cmd->add_option("--size", o->size, "size of each view WxH")->delimiter('x')->expected(2)->check(CLI::Range(1, 8192));
  cmd->add_option("--out", o->out, "output folder");
  cmd->add_option("--exposure", o->exposure, "scale for the PNG only")->check(CLI::Range(1e-6f, 1e6f));
  cmd->add_flag("--exr", o->exr, "also write every view as a linear EXR");
  addRepresentationOption(cmd, o->repr, "local probes: pass them through the codec first (float = as traced)", true);
  cmd->add_option("--passes", o->passes, "per-view (one pass per view) or multiview (chunks of views per pass)")
      ->check(CLI::IsMember({"per-view", "multiview"}));
  cmd->add_option("--shadow-map", o->shadowMap, "shadow map texels per side")->check(CLI::Range(16, 8192));
  cmd->add_option("--tonemap", o->toneMap, "PNG tone map: filmic or gamma")->check(CLI::IsMember({"filmic", "gamma"}));
  cmd->callback([=, &exitCode] {
    renderer::ViewSetSpec spec;
    std::string error;
    if (!renderer::parseViewSet(o->views, spec, error)) throw std::runtime_error(error);
    const scene::Scene s = tr->scene.load();
    const std::vector<renderer::ViewInfo> viewSet =
        renderer::makeViewSet(renderer::CameraView::fromScene(s), spec, session::viewSetOptions(s, o->size[0], o->size[1]));
    renderer::VulkanContext context(tr->gpu.context());
    renderer::RasterOptions ro;
    ro.passes = o->passes == "multiview" ? renderer::ViewPasses::Multiview : renderer::ViewPasses::PerView;
    ro.shadowMapSize = o->shadowMap;
    std::vector<renderer::Image> images;
    double ms = 0.0;
    if (!o->connect.empty()) {  // a viewer of a server's stream: subscribe, wait, render what it holds
      session::ViewerConfig vc;
      vc.width = o->size[0];
      vc.height = o->size[1];
      vc.raster = ro;
      vc.client.address = o->connect;
      vc.client.token = o->token;
      vc.client.name = "probecast-view";
      if (!o->tlsCa.empty()) {
        vc.client.tls = true;
        vc.client.rootCertPem = readTextFile(o->tlsCa);
        vc.client.tlsServerName = o->tlsName;
      }
      vc.client.interpolateThenHallucinate = true;
      session::Viewer viewer(context, s, viewSet, vc);
      viewer.start();
      viewer.waitFor(o->waitSeconds);
      viewer.stop();
      const service::ClientStats st = viewer.clientStats();
      service::VolumeSnapshot held;
      if (!viewer.snapshot(held)) throw std::runtime_error("no probe volume from " + o->connect + ": " + st.lastError);
      fmt::print("view: {} frames ({} bytes) from {}\n", st.framesApplied, st.bytesReceived, o->connect);
      if (o->repr != "float") throw std::runtime_error("--repr applies to local probes; the server chooses for --connect");
      viewer.render();
      images = viewer.images();
      ms = viewer.timings().viewsMs;
    } else {
      renderer::ProbeVolumeData volume;
      if (o->probes == "live") {
        const renderer::ProbeGrid g = tr->grid.resolve(s);
        renderer::ProbeUpdater updater(context, s, g, tr->tracer.options());
        for (uint32_t u = 0; u < o->updates; ++u) {
          updater.update();
          fmt::print(stderr, "\rview: probe update {}/{}", u + 1, o->updates);
        }
        fmt::print(stderr, "\n");
        volume = renderer::volumeFromUpdater(updater);
      } else {
        ProbeVolume file;
        if (!readProbeFile(o->probes, file, error)) throw std::runtime_error(error);
        volume = session::volumeFromFile(std::move(file));
      }
      if (o->repr != "float") volume = renderer::decodeAs(volume, session::parseRepresentationOrThrow(o->repr));
      renderer::RasterRenderer raster(context, s, o->size[0], o->size[1], ro);
      raster.setProbes(volume);
      images = raster.renderViews(viewSet);
      ms = raster.timings().viewsMs;
    }
    const auto& views = viewSet;
    std::filesystem::create_directories(o->out);
    const renderer::Image quilt = renderer::composeQuilt(images, views, spec.columns, spec.rows);
    const auto w = static_cast<int>(quilt.width), h = static_cast<int>(quilt.height);
    bench::ToneMap toneMap = bench::ToneMap::Filmic;
    bench::parseToneMap(o->toneMap, toneMap);
    if (!bench::writePngPreview(o->out + "/quilt.png", quilt.rgb, w, h, o->exposure, error, toneMap) ||
        !bench::writeExr(o->out + "/quilt.exr", quilt.rgb, w, h, error))
      throw std::runtime_error(error);
    if (o->exr)
      for (size_t k = 0; k < images.size(); ++k)
        if (!bench::writeExr(fmt::format("{}/view_{:02}.exr", o->out, k), images[k].rgb, static_cast<int>(o->size[0]),
                             static_cast<int>(o->size[1]), error))
          throw std::runtime_error(error);
    fmt::print("view: {} {} views of {}x{} on {}: {:.1f} ms per view; wrote {}/quilt.png and quilt.exr\n", o->views,
               views.size(), o->size[0], o->size[1], context.deviceName(), ms / static_cast<double>(views.size()), o->out);
    exitCode = 0;
  });
}

}  // namespace probecast::app
