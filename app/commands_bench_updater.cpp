// `probecast bench update|motion|adaptive`: the probe updater over many updates: its speed,
// convergence and flicker, probes while geometry moves, and adaptive blending with the noise-aware
// stream.
#include <memory>
#include <string>
#include <vector>

#include "adaptive_bench.h"
#include "commands.h"
#include "commands_bench.h"
#include "motion_bench.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/representation.h"
#include "progress.h"
#include "scene_options.h"
#include "update_bench.h"

namespace probecast::app {

// `probecast bench update`: updater speed, convergence, flicker.
void addBenchUpdate(CLI::App* bench) {
  CLI::App* update = bench->add_subcommand("update", "probe updater speed, convergence and flicker");
  auto ut = std::make_shared<TracingOptions>();
  struct UpdateOptions {
    std::string json, chart;
    uint32_t updates = 16, referenceSamples = 16384;
    std::vector<float> wMins{0.02f, 0.05f, 0.1f, 0.25f};
  };
  auto uo = std::make_shared<UpdateOptions>();
  ut->add(update);
  addJsonOption(update, uo->json);
  update->add_option("--chart", uo->chart, "write an SVG chart of error against time here");
  update->add_option("--updates", uo->updates, "updates per run")->check(CLI::Range(2, 10000));
  update->add_option("--reference-samples", uo->referenceSamples, "samples per probe of the reference")
      ->check(CLI::Range(1024u, 1u << 24));
  update->add_option("--w-mins", uo->wMins, "w_min values for the flicker runs")->delimiter(',')->check(CLI::Range(0.0f, 1.0f));
  update->callback([=] {
    bench::UpdateBenchOptions o;
    o.scene = ut->scene.load();
    o.grid = ut->grid.resolve(o.scene);
    o.updater = ut->updater(ut->scene.environment.load());
    o.context = ut->device.context();
    o.updates = uo->updates;
    o.referenceSamples = uo->referenceSamples;
    o.minBlendWeights = uo->wMins;
    o.command = commandLine();
    o.progress = progressLine;
    const bench::UpdateBenchResult r = bench::runUpdateBench(o);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", uo->json, r.svg, uo->chart);
  });
}

// `probecast bench motion`: probes, stream and raster client while geometry moves.
void addBenchMotion(CLI::App* bench) {
  CLI::App* cmd = bench->add_subcommand(
      "motion", "an animated scene held, played and held again: error per scene time, lag, wire bytes, update and visibility ms");
  auto mt = std::make_shared<TracingOptions>();
  struct MotionCli {
    std::string json, repr = "zh3";
    int deadzone = 1;
    NoiseRuleCli noise;
    bench::MotionBenchOptions bench;
  };
  auto mo = std::make_shared<MotionCli>();
  mt->add(cmd);
  cmd->add_option("--step", mo->bench.step, "scene seconds per update while moving")->check(CLI::Range(1e-6, 1e6));
  cmd->add_option("--still-before", mo->bench.stillBefore, "updates held at --time before the motion")
      ->check(CLI::Range(2u, 10000u));
  cmd->add_option("--moving", mo->bench.moving, "updates while moving")->check(CLI::Range(1u, 10000u));
  cmd->add_option("--still-after", mo->bench.stillAfter, "updates held after the motion")->check(CLI::Range(1u, 10000u));
  cmd->add_option("--reference-samples", mo->bench.referenceSamples,
                  "paths per probe and update of each scene time's converged volume (4 updates)")
      ->check(CLI::Range(32u, 1u << 20));
  cmd->add_option("--repr", mo->repr, "stream representation (l1, zh3, l2)");
  cmd->add_option("--deadzone", mo->deadzone, "as serve's")->check(CLI::Range(0, 127));
  mo->noise.add(cmd);
  addJsonOption(cmd, mo->json);
  cmd->callback([=] {
    bench::MotionBenchOptions& o = mo->bench;
    o.sceneSpec = mt->scene.scene;
    o.start = mt->scene.t;
    const scene::Scene first = mt->scene.load();
    o.grid = mt->grid.resolve(first);
    o.updater = mt->updater(mt->scene.environment.load());
    o.context = mt->device.context();
    o.repr = session::parseRepresentationOrThrow(mo->repr);
    o.encoder.deadzone = mo->deadzone;
    mo->noise.apply(o.encoder, true);
    o.command = commandLine();
    o.progress = progressLine;
    const bench::MotionBenchResult r = bench::runMotionBench(o);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", mo->json, "", "");
  });
}

namespace {

// `bench adaptive`'s options: the bench's own and the command's.
struct AdaptiveOptions {
  std::string json, chart, repr = "zh3";
  GridOptions grid{{4, 4, 4}, {}};
  DeviceOptions device;
  bench::AdaptiveBenchOptions bench;
};

// The phases of the light and the traced rules' updaters.
void addAdaptivePhaseOptions(CLI::App* adaptive, bench::AdaptiveBenchOptions& b) {
  adaptive->add_option("--spp", b.samplesPerProbe, "paths per probe per update")->check(CLI::Range(1u, 1u << 16));
  adaptive->add_option("--still", b.stillUpdates, "updates of each still phase")->check(CLI::Range(8u, 100000u));
  adaptive->add_option("--moving", b.movingUpdates, "updates with the light moving")->check(CLI::Range(1u, 100000u));
  adaptive->add_option("--light-step", b.lightStep, "t the light moves per update")->check(CLI::Range(0.0f, 1.0f));
  adaptive->add_option("--seed", b.seed, "seed of the traced rules' updaters (the spread between seeds is the bench's own noise)");
}

// The adaptive rule and the fixed ones it is compared with.
void addAdaptiveRuleOptions(CLI::App* adaptive, bench::AdaptiveBenchOptions& b) {
  adaptive->add_option("--reject-sigmas", b.rejectSigmas, "k of the adaptive rule")->check(CLI::Range(0.5f, 1000.0f));
  adaptive->add_option("--neighbour-history", b.neighbourHistory,
                       "adaptive rule: neighbours of a restarted probe keep at most this many updates of history (0 = off)")
      ->check(CLI::Range(0.0f, 1e6f));
  adaptive->add_option("--change-history", b.changeHistory,
                       "adaptive rule: when the scene changes, every probe keeps at most this many updates of history "
                       "(0 = off)")
      ->check(CLI::Range(0.0f, 1e6f));
  adaptive->add_option("--w-mins", b.fixedWMins, "fixed rules to compare")->delimiter(',')->check(CLI::Range(0.0f, 1.0f));
}

// The streams each rule's volumes go through: the noise-aware one, the oracles, and all of them.
void addAdaptiveStreamOptions(CLI::App* adaptive, bench::AdaptiveBenchOptions& b) {
  adaptive->add_option("--noise-scale", b.noiseScale, "c of the noise-aware stream")->check(CLI::Range(0.0f, 1000.0f));
  adaptive->add_option("--confirmations", b.confirmations,
                       "the noise-aware stream re-sends a probe once it has been beyond c sigma this many updates more")
      ->check(CLI::Range(0u, 1000u));
  adaptive->add_option("--oracle", b.oracleErrorRatios,
                       "also streams that know the truth and keep the held error within each of these x the full "
                       "stream's (about the least bytes for that error)")
      ->delimiter(',')
      ->check(CLI::Range(0.5f, 100.0f));
  adaptive->add_option("--oracle-exponents", b.oracleExponents,
                       "oracle streams weigh each probe's error by its energy to the minus these")
      ->delimiter(',')
      ->check(CLI::Range(0.0f, 2.0f));
  adaptive->add_option("--deadzone", b.deadzone, "dead-zone of every stream")->check(CLI::Range(0, 127));
  adaptive->add_flag("--surface-probes-only,!--all-probes", b.surfaceProbesOnly,
                     "trace and stream only the probes that light some surface (default on)");
  adaptive->add_option("--view-weights", b.viewWeights,
                       "the noise-aware stream holds probes the scored views show little of longer: none, footprint "
                       "(each probe's measured share of their pixels), surface (the views' surfaces and the probes "
                       "that light them, as a server can work them out) or lit (surface, weighed by the light the "
                       "volume holds, after gamma, at every update, blended over updates: what a producer does)")
      ->check(CLI::IsMember({"none", "footprint", "surface", "lit"}));
  adaptive->add_option("--refinement-interval", b.refinementInterval,
                       "noise-aware stream: refinements wait for the next update whose sequence is a multiple of this")
      ->check(CLI::Range(0u, 100000u));
}

// How images are scored, against what, and over how many seeds.
void addAdaptiveScoringOptions(CLI::App* adaptive, bench::AdaptiveBenchOptions& b) {
  adaptive->add_option("--scored-updates", b.scoredUpdates,
                       "images scored at the last this many updates of each phase (the loss averaged over them)")
      ->check(CLI::Range(1u, 1000u));
  adaptive->add_option("--scored-views", b.scoredViews,
                       "views each scored image is made of: mono (the scene camera), stereo, lf:NxM or lfh:NxM "
                       "around it; one PSNR over all their pixels")
      ->check([](const std::string& text) {
        renderer::ViewSetSpec spec;
        std::string error;
        return renderer::parseViewSet(text, spec, error) ? std::string() : error;
      });
  adaptive->add_option("--truth-cache", b.truthCache,
                       "directory keeping the converged volumes images are scored against, between runs");
  adaptive->add_option("--stream-seeds", b.streamSeeds,
                       "the adaptive rule's streams are measured with this many seeds (--seed, --seed + 1, ...): "
                       "each noise-aware figure's mean and standard error")
      ->check(CLI::Range(1u, 1000u));
}

// The ray budget's re-convergence against brute force.
void addAdaptiveReconvergenceOptions(CLI::App* adaptive, bench::AdaptiveBenchOptions& b) {
  adaptive->add_option("--rays-per-update", b.raysPerUpdate,
                       "rays per update of the budget and of brute force (0 = active probes x --spp)");
  adaptive->add_option("--view-yfov", b.viewYfov, "field of view (radians) of the viewer whose probes are scored")
      ->check(CLI::Range(0.01f, 3.1f));
  adaptive->add_flag("--reconvergence-only", b.reconvergenceOnly,
                     "measure only the re-convergence of the ray budget against brute force");
  adaptive->add_option("--reconvergence-updates", b.reconvergenceUpdates, "updates measured after the re-convergence jump")
      ->check(CLI::Range(1u, 100000u));
  adaptive->add_option("--reconvergence-seeds", b.reconvergenceSeeds,
                       "seeds the re-convergence is measured with (--seed, --seed + 1, ...); the summary is their median")
      ->check(CLI::Range(1u, 1000u));
}

}  // namespace

// `probecast bench adaptive`: adaptive blending and the noise-aware stream against fixed w_min.
void addBenchAdaptive(CLI::App* bench) {
  CLI::App* adaptive = bench->add_subcommand(
      "adaptive", "history rejection and the noise-aware stream: bytes still/moving, flicker, lag, PSNR loss");
  auto ao = std::make_shared<AdaptiveOptions>();
  ao->device.add(adaptive);
  adaptive->add_option("--scene", ao->bench.sceneSpec, "an animated scene (t moves its light)");
  ao->grid.add(adaptive, /*withBounds=*/false, 2, 64);
  addAdaptivePhaseOptions(adaptive, ao->bench);
  addAdaptiveRuleOptions(adaptive, ao->bench);
  addAdaptiveStreamOptions(adaptive, ao->bench);
  addAdaptiveScoringOptions(adaptive, ao->bench);
  addRepresentationOption(adaptive, ao->repr, "l1, zh3h, zh3, l2 or fp16");
  addJsonOption(adaptive, ao->json);
  adaptive->add_option("--chart", ao->chart, "SVG prefix: writes PREFIX_bytes.svg and PREFIX_jump.svg");
  addAdaptiveReconvergenceOptions(adaptive, ao->bench);
  adaptive->callback([ao] {
    bench::AdaptiveBenchOptions o = ao->bench;
    o.dims = {ao->grid.dims[0], ao->grid.dims[1], ao->grid.dims[2]};
    o.repr = *parseRepresentation(ao->repr);
    o.context = ao->device.context();
    o.command = commandLine();
    o.progress = progressLine;
    const bench::AdaptiveBenchResult r = bench::runAdaptiveBench(o);
    writeBenchOutputs(r.table, r.json.dump(2) + "\n", ao->json, "", "");
    if (!ao->chart.empty() && !o.reconvergenceOnly)
      for (const auto& [suffix, svg] : {std::pair{"_bytes.svg", &r.svgBytes}, std::pair{"_jump.svg", &r.svgJump}})
        writeTextFile(ao->chart + suffix, *svg);
  });
}

}  // namespace probecast::app
