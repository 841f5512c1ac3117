// The stability suite's probe-math cases: ZH3 blended across probes with competing axes, ringing
// of sharp lobes, absurd but finite inputs to the codec, and light through a thin wall.
#include "stability.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "probecast/codec/record.h"
#include "probecast/codec/sh.h"
#include "probecast/codec/stream.h"
#include "probecast/codec/zh3.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/service/client.h"
#include "probecast/service/server.h"
#include "probecast/session/probe_producer.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/stats.h"
#include "probecast/session/volumes.h"
#include "harness.h"
#include "stream_bench.h"
#include "update_bench.h"

namespace probecast::bench {
namespace {

using Probe = std::vector<float>;

// Directions on a spherical Fibonacci set.
std::vector<glm::vec3> fibonacci(int n) {
  std::vector<glm::vec3> d(static_cast<size_t>(n));
  const double golden = 3.883222077450933;  // π (3 − √5)
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = golden * i;
    d[static_cast<size_t>(i)] =
        glm::vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
  }
  return d;
}

// Ambient plus a smooth lobe towards `dir`, projected to L2 with many samples.
Probe lobeProbe(const glm::vec3& dir, const glm::vec3& color) {
  Probe p(kProbeFloats, 0.0f);
  const auto dirs = fibonacci(8192);
  const float w = 4.0f * kPi / static_cast<float>(dirs.size());
  for (const glm::vec3& d : dirs) {
    const float lobe = std::pow(std::max(0.0f, glm::dot(d, dir)), 6.0f);
    const float rgb[3] = {0.1f + 2.0f * lobe * color.r, 0.1f + 2.0f * lobe * color.g, 0.1f + 2.0f * lobe * color.b};
    shAddSample(p.data(), d.x, d.y, d.z, rgb, w);
  }
  return p;
}

Probe mix(const Probe& a, const Probe& b, float w) {
  Probe out(kProbeFloats);
  for (int i = 0; i < kProbeFloats; ++i) out[i] = (1.0f - w) * a[i] + w * b[i];
  return out;
}

Probe storedZh3(const Probe& p) {  // L1 + stored zonal coefficient, expanded to SH3
  Probe out = p;
  float axis[3], zonal[3];
  zh3Axis(p.data(), axis);
  zh3Project(p.data(), axis, zonal);
  zh3ExpandToL2(out.data(), axis, zonal);
  return out;
}

Probe hallucinated(const Probe& p) {
  Probe out = p;
  zh3HallucinateInPlace(out.data());
  return out;
}

double probeError(const Probe& test, const Probe& reference) {
  return irradianceRmseRel(test.data(), reference.data(), nullptr, 1);
}

}  // namespace

Zh3Blending measureZh3Blending() {
  const Probe a = lobeProbe({1, 0, 0}, {1.0f, 0.8f, 0.6f}), b = lobeProbe({0, 1, 0}, {0.6f, 0.8f, 1.0f});
  const Probe za = storedZh3(a), zb = storedZh3(b), ha = hallucinated(a), hb = hallucinated(b);
  Zh3Blending r;
  for (int k = 0; k <= 20; ++k) {
    const float w = static_cast<float>(k) / 20.0f;
    const Probe truth = mix(a, b, w);
    // Naive: blend L1 and the zonal coefficients, re-derive the axis from the blended L1.
    float axisA[3], axisB[3], zonalA[3], zonalB[3], axis[3], zonal[3];
    zh3Axis(a.data(), axisA);
    zh3Axis(b.data(), axisB);
    zh3Project(a.data(), axisA, zonalA);
    zh3Project(b.data(), axisB, zonalB);
    Probe naive = truth;
    zh3Axis(naive.data(), axis);
    for (int c = 0; c < 3; ++c) zonal[c] = (1.0f - w) * zonalA[c] + w * zonalB[c];
    zh3ExpandToL2(naive.data(), axis, zonal);
    Probe l1 = truth;
    std::fill(l1.begin() + 12, l1.end(), 0.0f);
    r.storedExpandedFirst = std::max(r.storedExpandedFirst, probeError(mix(za, zb, w), truth));
    r.storedNaive = std::max(r.storedNaive, probeError(naive, truth));
    r.hallucinatedInterpolateFirst = std::max(r.hallucinatedInterpolateFirst, probeError(hallucinated(l1), truth));
    r.hallucinatedPerProbe = std::max(r.hallucinatedPerProbe, probeError(mix(ha, hb, w), truth));
    r.l1 = std::max(r.l1, probeError(l1, truth));
  }
  return r;
}

Ringing measureRinging(double capDeg) {
  Ringing r;
  r.capDeg = capDeg;
  const double alpha = capDeg * 3.14159265358979 / 180.0, ca = std::cos(alpha), sa2 = 1.0 - ca * ca;
  const double radiance = 1.0 / (3.14159265358979 * sa2);  // irradiance facing the cap = 1
  // The cap around +z in SH, exactly: c_l0 = 2π L ∫_{cos α}^1 Y_l0(t) dt.
  Probe p(kProbeFloats, 0.0f);
  const double c00 = 2.0 * 3.14159265358979 * radiance * kY00 * (1.0 - ca);
  const double c10 = 3.14159265358979 * radiance * kY1 * sa2;
  const double c20 = 2.0 * 3.14159265358979 * radiance * kY20 * ca * sa2;
  for (int c = 0; c < 3; ++c) {
    p[0 * 3 + c] = static_cast<float>(c00);
    p[2 * 3 + c] = static_cast<float>(c10);
    p[6 * 3 + c] = static_cast<float>(c20);
  }
  // Exact irradiance: the cap integrated on a fine (cos θ, φ) grid.
  const int nt = 64, np = 128;
  std::vector<glm::dvec3> capDirs;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      const double ct = 1.0 - (1.0 - ca) * (i + 0.5) / nt, st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
      const double phi = 2.0 * 3.14159265358979 * (j + 0.5) / np;
      capDirs.emplace_back(st * std::cos(phi), st * std::sin(phi), ct);
    }
  const double dOmega = 2.0 * 3.14159265358979 * (1.0 - ca) / static_cast<double>(capDirs.size());
  const auto normals = fibonacci(4096);
  double maxExact = 0, minL2 = std::numeric_limits<double>::max(), err = 0, errClamped = 0, energy = 0;
  int negative = 0;
  for (const glm::vec3& nf : normals) {
    const glm::dvec3 n(nf);
    double exact = 0;
    for (const glm::dvec3& d : capDirs) exact += std::max(0.0, glm::dot(n, d));
    exact *= radiance * dOmega;
    float rgb[3];
    shEvalIrradiance(p.data(), nf.x, nf.y, nf.z, rgb);
    const double l2 = rgb[0];
    maxExact = std::max(maxExact, exact);
    minL2 = std::min(minL2, l2);
    negative += l2 < 0.0;
    err += (l2 - exact) * (l2 - exact);
    errClamped += (std::max(l2, 0.0) - exact) * (std::max(l2, 0.0) - exact);
    energy += exact * exact;
  }
  r.minIrradianceRel = minL2 / maxExact;
  r.negativeFraction = static_cast<double>(negative) / static_cast<double>(normals.size());
  r.rmseRelUnclamped = std::sqrt(err / energy);
  r.rmseRelClamped = std::sqrt(errClamped / energy);
  return r;
}

ExtremeInputs measureExtremeInputs() {
  ExtremeInputs r;
  r.allFinite = true;
  uint8_t record[kMaxRecordBytes];
  float decoded[kProbeFloats];
  const auto roundTrip = [&](Representation repr, const Probe& p) {
    encodeProbeRecord(repr, p.data(), record);
    decodeProbeRecord(repr, record, decoded);
    for (float v : decoded) r.allFinite = r.allFinite && std::isfinite(v);
    return Probe(decoded, decoded + kProbeFloats);
  };
  for (Representation repr : kAllRepresentations) {
    for (float v : roundTrip(repr, Probe(kProbeFloats, 0.0f)))
      r.blackMaxAbs = std::max(r.blackMaxAbs, static_cast<double>(std::fabs(v)));
    Probe nan = lobeProbe({0, 0, 1}, {1, 1, 1});
    nan[4] = std::numeric_limits<float>::quiet_NaN();
    nan[13] = std::numeric_limits<float>::infinity();
    for (float v : roundTrip(repr, nan))
      r.nanDecodedMaxAbs = std::max(r.nanDecodedMaxAbs, static_cast<double>(std::fabs(v)));
  }
  for (float scale : {1e2f, 1e3f, 1e4f, 1e5f, 1e6f}) {
    Probe bright = lobeProbe({0.6f, 0.8f, 0.0f}, {1.0f, 0.5f, 0.25f});
    for (float& v : bright) v *= scale;
    r.brightRelError.emplace_back(scale, probeError(roundTrip(Representation::L2, bright), bright));
  }
  return r;
}

WallLeak measureWallLeak(renderer::VulkanContext& context) {
  const scene::Scene s = session::loadSceneOrThrow("builtin:thin-wall", 0.0f);
  const ProbeGrid grid = renderer::sceneGrid(s, {9, 5, 5});  // 9 along x: one plane inside the wall
  const auto traced = [&](bool classify) {
    renderer::UpdaterOptions o;
    o.samplesPerProbe = 128;
    o.classify = classify;
    o.relocate = false;  // classification alone: probes in the wall switch off rather than move
    o.surfaceProbesOnly = false;  // and only the probes inside geometry: the idle ones count as traced
    renderer::ProbeUpdater u(context, s, grid, o);
    u.update();
    u.update();
    return u.volume();
  };
  const ProbeVolume on = traced(true), off = traced(false);
  WallLeak r;
  r.probes = grid.count();
  for (uint8_t a : on.active) r.inactiveProbes += a == 0;
  r.raySavings = static_cast<double>(r.inactiveProbes) / r.probes;
  const uint32_t w = 48, h = 32;
  // Classification alone: visibility (on by default) also keeps probes inside the wall out.
  renderer::RasterOptions plain = singleSampleRaster();
  plain.visibility = false;
  renderer::RasterRenderer raster(context, s, w, h, plain);
  const renderer::CameraView cam = renderer::CameraView::fromScene(s);
  const auto mean = [](const renderer::Image& img) {
    double sum = 0;
    for (float v : img.rgb) sum += v;
    return sum / static_cast<double>(img.rgb.size());
  };
  renderer::ReferenceOptions ro;
  ro.width = w;
  ro.height = h;
  ro.samplesPerPixel = 256;
  const double reference = mean(renderer::renderReference(context, s, cam, ro));
  raster.setProbes(on);
  r.meanErrorRelClassified =
      std::abs(mean(raster.render(raster.viewProjection(cam), cam.position)) - reference) / reference;
  raster.setProbes(off);
  r.meanErrorRelUnclassified =
      std::abs(mean(raster.render(raster.viewProjection(cam), cam.position)) - reference) / reference;
  return r;
}

}  // namespace probecast::bench
