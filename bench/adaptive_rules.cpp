// bench adaptive: one blend rule with one seed through the phases (light still, moving, still
// again), every stream it feeds, and their scores at the scored updates.
#include "adaptive_parts.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/probe_file.h"
#include "probecast/session/stats.h"
#include "probecast/session/viewer.h"
#include "update_bench.h"

namespace probecast::bench::adaptive {
namespace {

// The streams one rule's volumes go through: every quantised change, the dead-zone, the
// noise-aware stream, and the oracles.
std::vector<Stream> makeStreams(const Setup& s, const std::vector<float>& footprint) {
  const AdaptiveBenchOptions& o = s.o;
  std::vector<Stream> streams(3);
  streams[0].name = "full";  // every quantised change
  streams[1].name = "deadzone";
  streams[1].options.deadzone = o.deadzone;
  streams[2].name = "noise";
  streams[2].options.deadzone = o.deadzone;
  streams[2].options.noiseScale = o.noiseScale;
  streams[2].options.confirmations = o.confirmations;
  streams[2].options.refinementInterval = o.refinementInterval;
  streams[2].withNoise = true;
  streams[2].viewWeights = footprint;
  for (float exponent : o.oracleExponents)
    for (float ratio : o.oracleErrorRatios) {
      Stream& st = streams.emplace_back();
      st.name = fmt::format("oracle {:g}/{:g}", ratio, exponent);
      st.oracleRatio = ratio;
      st.oracleExponent = exponent;
      st.options.deadzone = o.deadzone;
    }
  return streams;
}

// Every stream takes the update's volume (the oracles what they choose of it) and writes its frame.
void encodeUpdate(const Setup& s, const Truth& truth, uint32_t f, const ProbeVolume& v, std::vector<Stream>& streams) {
  std::vector<float> oracleInput;
  std::vector<uint8_t> frame;
  for (Stream& st : streams) {
    const float* input = v.probes.data();
    if (st.oracleRatio > 0.0f) {
      // What knows the truth: re-send the fewest probes (largest error cut first) that bring the
      // held volume's error to the stream's ratio × the full stream's; the rest input what is held.
      oracleSelect(truth.probes(s.tAt(f)).data(), v.probes.data(), v.active.data(), streams[0].encoder->reconstruction(),
                   st.encoder->reconstruction(), s.count, st.oracleRatio, st.oracleExponent, oracleInput);
      input = oracleInput.data();
    }
    const uint32_t changed = st.encoder->update(input, v.active.data(), st.withNoise ? v.noise.data() : nullptr,
                                                st.withNoise ? v.stillUpdates.data() : nullptr);
    st.encoder->writeChangedFrame(frame);
    // Frame 0 is the keyframe; a frame that changes no brick is never sent.
    st.bytesPerProbe.push_back(f == 0 || changed == 0 ? 0.0 : static_cast<double>(frame.size()) / s.count);
    ProbeVolume held;
    st.encoder->copyVolume(s.grid.bounds, held);
    st.heldChanges.push_back(st.held.empty() ? 0.0
                                             : irradianceRmseRel(held.probes.data(), st.held.data(), held.active.data(),
                                                                 s.count));
    st.held = std::move(held.probes);
  }
}

// At a scored update: what each stream holds against the truth, as probes and as images.
void scoreUpdate(const Setup& s, const Truth& truth, uint32_t f, std::vector<Stream>& streams) {
  for (size_t m = 0; m < s.moments.size(); ++m) {
    if (f < s.moments[m].first || f > s.moments[m].frame) continue;
    const std::vector<float>& converged = truth.probes(s.tAt(f));
    for (Stream& st : streams) {
      ProbeVolume held;
      st.encoder->copyVolume(s.grid.bounds, held);
      st.probeError[m].push_back(irradianceRmseRel(held.probes.data(), converged.data(), held.active.data(), s.count));
      st.probeErrorEach[m].push_back(
          irradianceRmseRelPerProbe(held.probes.data(), converged.data(), held.active.data(), s.count));
      st.psnr[m].push_back(s.psnrOf(s.render(held, s.tAt(f)), truth.images(s.tAt(f))));
    }
  }
}

renderer::UpdaterOptions updaterOptions(const AdaptiveBenchOptions& o, uint32_t seed, const BlendRule& rule) {
  renderer::UpdaterOptions uo;
  uo.samplesPerProbe = o.samplesPerProbe;
  uo.seed = seed;
  uo.minBlendWeight = rule.wMin;
  uo.rejectSigmas = rule.rejectSigmas;
  uo.neighbourHistory = rule.rejectSigmas > 0 ? o.neighbourHistory : 0.0f;
  uo.changeHistory = rule.rejectSigmas > 0 ? o.changeHistory : 0.0f;
  uo.surfaceProbesOnly = o.surfaceProbesOnly;
  return uo;
}

}  // namespace

RuleRun runRule(const Setup& s, const Truth& truth, const std::vector<float>& footprint, uint32_t seed,
                const BlendRule& rule) {
  const AdaptiveBenchOptions& o = s.o;
  renderer::ProbeUpdater u(s.context, s.first, s.grid, updaterOptions(o, seed, rule));
  RuleRun run{rule, seed, s.count - u.classifyStats().inactive, {}, {}, makeStreams(s, footprint)};
  std::vector<Stream>& streams = run.streams;
  SeenSurfaces seen;
  seen.lighting = s.firstLighting;
  if (o.viewWeights == "surface" || o.viewWeights == "lit") {
    seen.samples = renderer::sampleViewSurfaces(s.first, s.grid, u.volume().active, {}, s.serverViews, s.sampleSize.x,
                                                s.sampleSize.y);
    if (o.viewWeights == "surface") streams[2].viewWeights = renderer::probeViewFootprints(seen.samples, s.count);
  }
  if (!seen.samples.empty()) seen.direct = renderer::sampleDirectLight(s.first, seen.samples, seen.lighting);
  for (Stream& st : streams) {
    st.encoder = std::make_unique<StreamEncoder>(s.layout, st.options);
    // The views' own weights: a probe's active flag in this updater may differ from the truth's.
    if (!st.viewWeights.empty() && !st.encoder->setViewWeights(st.viewWeights))
      throw std::runtime_error("bench adaptive: no probe shows in the scored views");
    st.psnr.assign(s.moments.size(), {});
    st.probeError = st.probeErrorEach = st.psnr;
  }
  std::vector<float> previous;
  for (uint32_t f = 0; f < s.frames; ++f) {
    if (f >= o.stillUpdates && f < o.stillUpdates + o.movingUpdates) {
      const scene::Scene now = s.sceneAt(s.tAt(f));
      u.setScene(now);
      if (!seen.samples.empty() && now.lights != seen.lighting.lights) {
        seen.lighting.lights = now.lights;
        seen.direct = renderer::sampleDirectLight(now, seen.samples, seen.lighting);
      }
    }
    run.restarts.push_back(u.update().restartedProbes);
    const ProbeVolume& v = u.volume();
    if (o.viewWeights == "lit") {
      renderer::blendViewWeights(seen.litWeights, renderer::probeViewSensitivity(seen.samples, seen.direct,
                                                                                 seen.lighting, v.probes, s.count));
      if (!streams[2].encoder->setViewWeights(seen.litWeights))
        streams[2].encoder->setViewWeights({});  // nothing the views show is lit yet: as the hub does
    }
    run.changes.push_back(previous.empty() ? 0.0
                                           : irradianceRmseRel(v.probes.data(), previous.data(), v.active.data(), s.count));
    previous = v.probes;
    encodeUpdate(s, truth, f, v, streams);
    scoreUpdate(s, truth, f, streams);
  }
  return run;
}

}  // namespace probecast::bench::adaptive
