// Probe updater: sample directions, classification, dispatch, reduction and temporal blend.
#include "probecast/renderer/probe_updater.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>

#include "probe_trace.rgen.h"
#include "gpu_scene.h"
#include "probe_history.h"
#include "probe_relocation.h"
#include "probe_surfaces.h"
#include "ray_budget.h"
#include "probecast/codec/probe_offsets.h"
#include "vk_raytracing.h"

namespace probecast::renderer {
namespace {

using shaders::PtPushConstants;

constexpr uint32_t kLanes = PT_LANES_PER_PROBE;
constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;

uint32_t roundUpLanes(uint32_t n) { return std::max(kLanes, (n + kLanes - 1) / kLanes * kLanes); }

uint32_t spread2(uint32_t v) {  // 16 bits → every other bit
  v &= 0xffffu;
  v = (v | (v << 8)) & 0x00ff00ffu;
  v = (v | (v << 4)) & 0x0f0f0f0fu;
  v = (v | (v << 2)) & 0x33333333u;
  v = (v | (v << 1)) & 0x55555555u;
  return v;
}

// Spherical Fibonacci directions, reordered along a Morton curve of their octahedral coordinates
// so consecutive samples (neighbouring invocations) point in nearby directions.
std::vector<shaders::vec4> coherentFibonacci(uint32_t count) {
  std::vector<glm::vec3> dirs(count);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (uint32_t i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    dirs[i] = glm::vec3(static_cast<float>(r * std::cos(golden * i)), static_cast<float>(r * std::sin(golden * i)),
                        static_cast<float>(z));
  }
  std::vector<uint32_t> key(count);
  for (uint32_t i = 0; i < count; ++i) {
    const glm::vec3 d = dirs[i] / (std::fabs(dirs[i].x) + std::fabs(dirs[i].y) + std::fabs(dirs[i].z));
    glm::vec2 o(d.x, d.y);
    if (d.z < 0) o = (1.0f - glm::abs(glm::vec2(o.y, o.x))) * glm::vec2(o.x >= 0 ? 1 : -1, o.y >= 0 ? 1 : -1);
    const glm::vec2 u = glm::clamp(o * 0.5f + 0.5f, 0.0f, 1.0f) * 65535.0f;
    key[i] = spread2(static_cast<uint32_t>(u.x)) | (spread2(static_cast<uint32_t>(u.y)) << 1);
  }
  std::vector<uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key[a] < key[b]; });
  std::vector<shaders::vec4> out(count);
  for (uint32_t i = 0; i < count; ++i) out[i] = {dirs[order[i]].x, dirs[order[i]].y, dirs[order[i]].z, 0.0f};
  return out;
}

// A uniformly random rotation (Shoemake's quaternion), deterministic in (seed, update).
shaders::mat4 randomRotation(uint32_t seed, uint32_t update) {
  std::seed_seq seq{seed, update, 0x9e3779b9u};
  std::mt19937 rng(seq);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = u(rng), u3 = u(rng);
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const double x = a * std::sin(2 * M_PI * u2), y = a * std::cos(2 * M_PI * u2), z = b * std::sin(2 * M_PI * u3),
               w = b * std::cos(2 * M_PI * u3);
  const float m[3][3] = {{float(1 - 2 * (y * y + z * z)), float(2 * (x * y + w * z)), float(2 * (x * z - w * y))},
                         {float(2 * (x * y - w * z)), float(1 - 2 * (x * x + z * z)), float(2 * (y * z + w * x))},
                         {float(2 * (x * z + w * y)), float(2 * (y * z - w * x)), float(1 - 2 * (x * x + y * y))}};
  shaders::mat4 r{};
  for (int c = 0; c < 3; ++c) r.c[c] = {m[c][0], m[c][1], m[c][2], 0.0f};
  r.c[3] = {0, 0, 0, 1};
  return r;
}

shaders::mat4 identity() {
  shaders::mat4 r{};
  r.c[0] = {1, 0, 0, 0};
  r.c[1] = {0, 1, 0, 0};
  r.c[2] = {0, 0, 1, 0};
  r.c[3] = {0, 0, 0, 1};
  return r;
}

}  // namespace

ProbeGrid sceneGrid(const scene::Scene& scene, const std::array<uint32_t, 3>& dims) {
  return cellCentredGrid(dims.data(), &scene.boundsMin.x, &scene.boundsMax.x);
}

// The probes near a triangle that moved between `before` and `after` (positions of the same
// triangles): the grid points in the box around its old and new corners, grown by `margin` cells.
std::vector<uint32_t> probesNearMoved(const ProbeGrid& grid, const std::vector<glm::vec3>& before,
                                      const std::vector<glm::vec3>& after, const std::vector<uint32_t>& indices,
                                      float margin) {
  std::vector<uint8_t> near(grid.count(), 0);
  glm::vec3 lo, cell;
  glm::ivec3 dims;
  for (int a = 0; a < 3; ++a) {
    lo[a] = grid.bounds.min[a];
    dims[a] = static_cast<int>(grid.dims[a]);
    cell[a] = grid.dims[a] > 1 ? probeCellSize(grid, a) : 0.0f;
  }
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const uint32_t v[3] = {indices[t], indices[t + 1], indices[t + 2]};
    if (before[v[0]] == after[v[0]] && before[v[1]] == after[v[1]] && before[v[2]] == after[v[2]]) continue;
    glm::vec3 bmin(INFINITY), bmax(-INFINITY);
    for (uint32_t i : v) {
      bmin = glm::min(bmin, glm::min(before[i], after[i]));
      bmax = glm::max(bmax, glm::max(before[i], after[i]));
    }
    glm::ivec3 from, to;
    for (int a = 0; a < 3; ++a) {
      if (cell[a] <= 0.0f) {
        from[a] = 0;
        to[a] = dims[a] - 1;
        continue;
      }
      const float f = std::ceil((bmin[a] - margin * cell[a] - lo[a]) / cell[a]),
                  c = std::floor((bmax[a] + margin * cell[a] - lo[a]) / cell[a]);
      if (!std::isfinite(f) || !std::isfinite(c)) {  // not expected (poses stay finite): every probe
        from[a] = 0;
        to[a] = dims[a] - 1;
        continue;
      }
      from[a] = static_cast<int>(std::clamp(f, 0.0f, static_cast<float>(dims[a] - 1)));
      to[a] = static_cast<int>(std::clamp(c, 0.0f, static_cast<float>(dims[a] - 1)));
    }
    for (int z = from.z; z <= to.z; ++z)
      for (int y = from.y; y <= to.y; ++y)
        for (int x = from.x; x <= to.x; ++x)
          near[static_cast<size_t>(x) + static_cast<size_t>(dims.x) * (static_cast<size_t>(y) + static_cast<size_t>(dims.y) * z)] = 1;
  }
  std::vector<uint32_t> out;
  for (uint32_t p = 0; p < grid.count(); ++p)
    if (near[p]) out.push_back(p);
  return out;
}

struct ProbeUpdater::Impl {
  VulkanDevice* d = nullptr;
  ProbeVolume volume;  // grid, samples, active mask, updates
  UpdaterOptions options;
  uint32_t samples = 0;
  std::vector<uint32_t> activeList;
  ClassifyStats classifyStats;
  GeometryStats geometryStats;
  std::vector<ProbeHistory> history;  // per probe: blend count and noise statistics
  std::vector<uint32_t> restarted;    // probes restarted by the update being blended
  // Per probe, how the update being blended restarted it (all kNoRestart between updates).
  static constexpr uint8_t kNoRestart = 0, kRestart = 1, kStrongRestart = 2;  // strong: moved by twice the threshold
  std::vector<uint8_t> restartKind;
  // The ray budget: per probe its view weight (empty = all seen), updates since it was traced,
  // and the samples of the last update.
  std::vector<float> viewWeights;
  std::vector<uint32_t> age, lastSamples;
  uint32_t maxSamples = 0;
  size_t geometryVertices = 0, geometryTriangles = 0;
  std::vector<glm::vec3> geometryPositions;
  std::vector<uint32_t> geometryIndices;

  RayTracingPass pass;
  GpuScene gpu;
  Buffer directions, classifyDirections, probeList, partials;
  Buffer levelDirections;  // with a budget: direction sets of 32, 64, … maxSamples, one after another

  // `perProbeSamples`: empty, or each listed probe's samples (a multiple of the lanes, ≤ maxSamples).
  void uploadProbeList(const std::vector<uint32_t>& list, const std::vector<uint32_t>& perProbeSamples = {}) {
    destroyBuffer(*d, probeList);
    destroyBuffer(*d, partials);
    std::vector<shaders::vec4> data(list.size());
    for (size_t i = 0; i < list.size(); ++i) {
      float p[3];
      volume.grid.position(list[i], p);
      if (!volume.offsets.empty())
        for (int a = 0; a < 3; ++a) p[a] += volume.offsets[static_cast<size_t>(list[i]) * 3 + a];
      float key;
      std::memcpy(&key, &list[i], sizeof key);  // the grid index as bits: the shader's RNG stream
      data[i] = {p[0], p[1], p[2], key};
    }
    for (uint32_t n : perProbeSamples) {  // the second section (probe_trace_shared.h)
      const uint32_t level = n / kLanes, first = kLanes * (level - 1) * level / 2;
      shaders::vec4 budget{};
      std::memcpy(&budget.x, &n, sizeof n);
      std::memcpy(&budget.y, &first, sizeof first);
      data.push_back(budget);
    }
    probeList = createBufferWithData(*d, data.data(), data.size() * sizeof(shaders::vec4), kStorage);
    partials = createBuffer(*d, list.size() * kLanes * PT_PARTIAL_FLOATS * sizeof(float), kStorage);
  }

  void dispatch(uint32_t count, uint32_t sampleCount, const Buffer& dirs, uint32_t mode, const shaders::mat4& rotation,
                uint32_t perProbeSamples = 0) {
    PtPushConstants push{};
    push.perProbeSamples = perProbeSamples;
    push.rotation = rotation;
    push.sampleCount = sampleCount;
    push.probeCount = count;
    push.lightCount = gpu.lightCount;
    push.emitterCount = gpu.emitterCount;
    push.emitterPower = gpu.emitterPower;
    push.maxBounces = std::clamp<uint32_t>(options.maxBounces, 1, PT_MAX_BOUNCES_LIMIT);
    push.seed = options.seed;
    push.updateIndex = volume.updates;
    push.mode = mode;
    push.indirectClamp = options.indirectClamp;
    const RayTracingInputs in{&gpu, &dirs, &probeList, &partials};
    runRayTracingPass(*d, pass, in, &push, kLanes, count);
  }

  // What the lanes of the i-th probe of the last classify dispatch saw, over `n` rays.
  ClassifyHits classifyHits(size_t i, uint32_t n) const {
    const float* part = static_cast<const float*>(partials.mapped);
    ClassifyHits h;
    h.backDistance = h.frontDistance = static_cast<float>(PT_CLASSIFY_FAR);
    float back = 0.0f;
    for (uint32_t lane = 0; lane < kLanes; ++lane) {
      const float* src = part + (i * kLanes + lane) * PT_PARTIAL_FLOATS;
      back += src[27];
      if (src[PT_CLASSIFY_BACK] < h.backDistance) {
        h.backDistance = src[PT_CLASSIFY_BACK];
        h.backDirection = glm::vec3(src[PT_CLASSIFY_BACK + 1], src[PT_CLASSIFY_BACK + 2], src[PT_CLASSIFY_BACK + 3]);
      }
      if (src[PT_CLASSIFY_FRONT] < h.frontDistance) {
        h.frontDistance = src[PT_CLASSIFY_FRONT];
        h.frontDirection = glm::vec3(src[PT_CLASSIFY_FRONT + 1], src[PT_CLASSIFY_FRONT + 2], src[PT_CLASSIFY_FRONT + 3]);
      }
    }
    h.backFraction = back / static_cast<float>(n);
    return h;
  }

  // Classify rays at every probe, then (relocating) again at the probes that moved, until every
  // probe is settled or stuck or the rounds are spent; inside geometry at the end = inactive.
  void classify() {
    const auto t0 = std::chrono::steady_clock::now();
    classifyStats = ClassifyStats{};
    std::vector<uint8_t>& active = volume.active;
    std::fill(active.begin(), active.end(), 1);
    std::vector<uint32_t> pending;  // probes still to classify: those that light some surface
    for (uint32_t p = 0; p < volume.count(); ++p) {
      if (options.surfaceProbesOnly && !nearSurface[p]) {
        active[p] = 0;
        ++classifyStats.idle;
      } else {
        pending.push_back(p);
      }
    }
    volume.offsets.clear();
    const bool relocating = options.classify && options.relocate;
    RelocationRule rule;
    rule.backFaceThreshold = options.backFaceThreshold;
    float smallest = 0.0f;
    for (int a = 0; a < 3; ++a) {
      const float cell = probeCellSize(volume.grid, a);
      rule.maxShift[a] = std::clamp(options.relocateMaxShift, 0.0f, 0.5f) * cell;
      if (cell > 0.0f) smallest = smallest > 0.0f ? std::min(smallest, cell) : cell;
    }
    rule.clearance = std::max(0.0f, options.relocateClearance) * smallest;
    if (relocating) volume.offsets.assign(static_cast<size_t>(volume.count()) * 3, 0.0f);
    const uint32_t n = roundUpLanes(options.classifySamples);
    for (uint32_t round = 0; options.classify && !pending.empty(); ++round) {
      uploadProbeList(pending);
      dispatch(static_cast<uint32_t>(pending.size()), n, classifyDirections, PT_MODE_CLASSIFY, identity());
      ++classifyStats.rounds;
      const bool last = !relocating || round >= options.relocateRounds;
      std::vector<uint32_t> moved;
      for (size_t i = 0; i < pending.size(); ++i) {
        const uint32_t p = pending[i];
        const ClassifyHits hits = classifyHits(i, n);
        const bool inside = hits.backFraction > options.backFaceThreshold;
        if (round == 0) classifyStats.insideAtGrid += inside ? 1u : 0u;
        float* o = relocating ? &volume.offsets[static_cast<size_t>(p) * 3] : nullptr;
        glm::vec3 offset = o ? glm::vec3(o[0], o[1], o[2]) : glm::vec3(0.0f);
        if (!last && relocationStep(hits, rule, offset) == RelocationStep::Moved) {
          std::vector<float> snapped = {offset.x, offset.y, offset.z};
          snapProbeOffsets(volume.grid, snapped);  // trace where viewers will put it
          if (!std::equal(snapped.begin(), snapped.end(), o)) {
            std::copy(snapped.begin(), snapped.end(), o);
            moved.push_back(p);
            continue;
          }
        }
        active[p] = inside ? 0 : 1;
        if (inside && o) std::fill_n(o, 3, 0.0f);  // no position in the allowed box is outside: off, unmoved
      }
      pending = std::move(moved);
    }
    activeList.clear();
    for (uint32_t p = 0; p < volume.count(); ++p) {
      if (active[p]) {
        activeList.push_back(p);
        continue;
      }
      std::fill_n(volume.probes.begin() + p * 27, 27, 0.0f);
      history[p] = ProbeHistory{};  // starts afresh if it becomes active again
      if (!volume.noise.empty()) volume.noise[p] = 0.0f;
      if (!volume.stillUpdates.empty()) volume.stillUpdates[p] = 0;
    }
    uploadProbeList(activeList);
    summarizeClassification(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }

  // After moved geometry: the probes of `near` classified again where they stand (one round, their
  // offsets kept, so a stream needs no new epoch) and restarted; the rest keep their state.
  void reclassify(const std::vector<uint32_t>& near) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<float> offsets = volume.offsets;
    classifyStats = ClassifyStats{};
    classifyStats.partial = true;
    classifyStats.nearMoved = static_cast<uint32_t>(near.size());
    std::vector<uint32_t> pending;
    for (uint32_t p : near) {
      if (options.surfaceProbesOnly && !nearSurface[p]) volume.active[p] = 0;
      else pending.push_back(p);
      history[p] = ProbeHistory{};  // its surroundings moved: the next estimate starts it afresh
      if (!volume.stillUpdates.empty()) volume.stillUpdates[p] = 0;
    }
    if (options.classify && !pending.empty()) {
      const uint32_t n = roundUpLanes(options.classifySamples);
      uploadProbeList(pending);
      dispatch(static_cast<uint32_t>(pending.size()), n, classifyDirections, PT_MODE_CLASSIFY, identity());
      classifyStats.rounds = 1;
      for (size_t i = 0; i < pending.size(); ++i)
        volume.active[pending[i]] = classifyHits(i, n).backFraction > options.backFaceThreshold ? 0 : 1;
    } else {
      for (uint32_t p : pending) volume.active[p] = 1;
    }
    activeList.clear();
    for (uint32_t p = 0; p < volume.count(); ++p) {
      if (volume.active[p]) {
        activeList.push_back(p);
        continue;
      }
      std::fill_n(volume.probes.begin() + p * 27, 27, 0.0f);
      history[p] = ProbeHistory{};
      if (!volume.noise.empty()) volume.noise[p] = 0.0f;
      if (!volume.stillUpdates.empty()) volume.stillUpdates[p] = 0;
    }
    uploadProbeList(activeList);
    summarizeClassification(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    volume.offsets = offsets;  // as before, even when every moved probe went inactive
  }

  void summarizeClassification(double milliseconds) {
    ClassifyStats& c = classifyStats;
    c.milliseconds = milliseconds;
    double sum = 0.0;
    for (uint32_t p = 0; p < volume.count(); ++p) {
      c.inactive += volume.active[p] == 0 ? 1u : 0u;
      if (volume.offsets.empty()) continue;
      const float* o = &volume.offsets[static_cast<size_t>(p) * 3];
      if (o[0] == 0.0f && o[1] == 0.0f && o[2] == 0.0f) continue;
      ++c.moved;
      sum += std::sqrt(static_cast<double>(o[0]) * o[0] + static_cast<double>(o[1]) * o[1] + static_cast<double>(o[2]) * o[2]);
      for (int a = 0; a < 3; ++a)
        c.maxOffsetCells = std::max(c.maxOffsetCells, std::fabs(o[a]) / static_cast<double>(probeCellSize(volume.grid, a)));
    }
    c.meanOffsetMetres = c.moved ? sum / c.moved : 0.0;
    if (c.moved == 0) volume.offsets.clear();  // nothing moved: every probe at its grid position, no bytes to send
  }

  // After every upload of materials: the emitters the raster client lights (area_lights.h).
  void markClientLit(const scene::Scene& s) {
    markClientLitMaterials(scene::extractAreaLights(s, options.areaLights).clientLitMaterial, gpu);
  }
  // Blends the estimates of the last trace dispatch (the probes of `list`, `traced[i]` samples each) into
  // the probes' histories.
  void blendTraced(const std::vector<uint32_t>& list, const std::vector<uint32_t>& traced, UpdateStats& stats);
  // UpdaterOptions::neighbourHistory for the probes restarted by this update.
  void shortenNeighbours();
  // What lights the scene besides its geometry, as of the last setScene (UpdaterOptions::changeHistory).
  std::vector<scene::Light> lights;
  std::vector<scene::Material> materials;
  std::vector<uint32_t> triangleMaterial;
  // `refit`: the same triangles, only moving ones moved: their acceleration structures are refitted
  // (refitSceneAccel) instead of built anew, when that holds.
  void setGeometry(const scene::Scene& s, bool refit = false) {
    const auto t0 = std::chrono::steady_clock::now();
    if (refit && refitSceneAccel(*d, s, geometryPositions, gpu.accel)) {
      uploadGpuSurfaces(*d, s, gpu);  // the moved normals, and the shading
    } else {
      uploadGpuScene(*d, s, gpu);
      ++geometryStats.builds;
    }
    geometryStats.refits = gpu.accel.refits;
    geometryStats.refitRebuilds = gpu.accel.rebuilds;
    geometryStats.lastMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    nearSurface = options.surfaceProbesOnly ? probesNearSurfaces(s, volume.grid) : std::vector<uint8_t>(volume.count(), 1);
    markClientLit(s);
    geometryPositions = s.positions;
    geometryIndices = s.indices;
  }
  SurfaceRecord surfaces;  // as of the last setScene
  std::vector<uint8_t> nearSurface;  // per probe: lights some surface of the last geometry (probe_surfaces.h)
  // Whether `s` lights the probes differently from the scene last set (its geometry aside), and
  // keeps what it would compare next time.
  bool shadingChanged(const scene::Scene& s) {
    const bool changed = s.lights != lights || s.materials != materials || s.triangleMaterial != triangleMaterial;
    lights = s.lights;
    materials = s.materials;
    triangleMaterial = s.triangleMaterial;
    return changed;
  }
};

ProbeUpdater::ProbeUpdater(VulkanContext& context, const scene::Scene& scene, const ProbeGrid& grid,
                           const UpdaterOptions& options)
    : impl_(std::make_unique<Impl>()) {
  requireRayTracing(context.device(), "the probe updater");
  if (scene.triangleCount() == 0) throw std::invalid_argument("scene " + scene.name + " has no triangles");
  if (grid.count() == 0) throw std::invalid_argument("probe grid has no probes");
  Impl& s = *impl_;
  s.d = &context.device();
  s.options = options;
  s.samples = roundUpLanes(options.samplesPerProbe);
  s.volume = makeProbeVolume(grid);
  s.volume.samplesPerProbe = s.samples;
  s.history.assign(grid.count(), ProbeHistory{});
  s.shadingChanged(scene);
  s.surfaces.changedBy(scene);
  s.age.assign(grid.count(), 0u);
  s.lastSamples.assign(grid.count(), 0u);
  createRayTracingPass(*s.d, kProbeTraceRgen, sizeof kProbeTraceRgen, sizeof(PtPushConstants), s.pass);
  const auto dirs = coherentFibonacci(s.samples);
  s.directions = createBufferWithData(*s.d, dirs.data(), dirs.size() * sizeof(shaders::vec4), kStorage);
  const auto cdirs = coherentFibonacci(roundUpLanes(options.classifySamples));
  s.classifyDirections = createBufferWithData(*s.d, cdirs.data(), cdirs.size() * sizeof(shaders::vec4), kStorage);
  if (options.raysPerUpdate > 0) {
    // Each probe's samples come from a set of its own size: the first m of a larger set are one
    // patch of the sphere (the sets are ordered along a curve).
    const uint32_t cap = options.maxSamplesPerProbe ? options.maxSamplesPerProbe : 8 * s.samples;
    s.maxSamples = std::max(s.samples, roundUpLanes(std::min(cap, 4096u)));
    std::vector<shaders::vec4> levels;
    for (uint32_t n = kLanes; n <= s.maxSamples; n += kLanes) {
      const auto set = coherentFibonacci(n);
      levels.insert(levels.end(), set.begin(), set.end());
    }
    s.levelDirections = createBufferWithData(*s.d, levels.data(), levels.size() * sizeof(shaders::vec4), kStorage);
  }
  s.setGeometry(scene);
  uploadGpuEnvironment(*s.d, options.environment.get(), options.environmentSampling, s.gpu);
  s.classify();
}

ProbeUpdater::~ProbeUpdater() {
  Impl& s = *impl_;
  destroyGpuScene(*s.d, s.gpu);
  for (Buffer* b : {&s.directions, &s.classifyDirections, &s.probeList, &s.partials, &s.levelDirections})
    destroyBuffer(*s.d, *b);
  destroyRayTracingPass(*s.d, s.pass);
}

void ProbeUpdater::setScene(const scene::Scene& scene) {
  Impl& s = *impl_;
  if (scene.triangleCount() == 0) throw std::invalid_argument("scene " + scene.name + " has no triangles");
  const bool sameTriangles = scene.indices == s.geometryIndices && scene.positions.size() == s.geometryPositions.size();
  const bool geometryChanged = !sameTriangles || scene.positions != s.geometryPositions;
  const bool surfacesChanged = s.surfaces.changedBy(scene);
  const bool shadingChanged = s.shadingChanged(scene);
  if (geometryChanged && sameTriangles) {
    // Moved geometry: only the probes around it are classified again and restarted.
    // A relocated probe stands up to relocateMaxShift of a cell from its grid point: the margin grows by that.
    const float margin = 1.0f + (s.volume.offsets.empty() ? 0.0f : std::clamp(s.options.relocateMaxShift, 0.0f, 0.5f));
    const std::vector<uint32_t> near =
        probesNearMoved(s.volume.grid, s.geometryPositions, scene.positions, scene.indices, margin);
    s.setGeometry(scene, s.options.refitMovingGeometry);
    s.reclassify(near);
  } else if (geometryChanged) {
    s.setGeometry(scene);
    s.classify();
  } else {
    if (surfacesChanged) uploadGpuSurfaces(*s.d, scene, s.gpu);  // and the shading
    else uploadGpuShading(*s.d, scene, s.gpu);
    s.markClientLit(scene);
  }
  // The light may have changed anywhere: no probe's history older than changeHistory updates is
  // trusted. Restarts alone would follow only changes a probe can tell from its noise.
  if ((geometryChanged || surfacesChanged || shadingChanged) && s.options.changeHistory > 0.0f &&
      s.options.rejectSigmas > 0.0f)
    for (ProbeHistory& h : s.history) shortenHistory(h, s.options.changeHistory);
  if (geometryChanged || surfacesChanged || shadingChanged)
    std::fill(s.volume.stillUpdates.begin(), s.volume.stillUpdates.end(), 0u);
}

UpdateStats ProbeUpdater::update() {
  Impl& s = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  UpdateStats stats;
  stats.activeProbes = static_cast<uint32_t>(s.activeList.size());
  s.lastSamples.assign(s.volume.count(), 0u);
  if (!s.activeList.empty() && s.options.raysPerUpdate == 0) {
    s.dispatch(static_cast<uint32_t>(s.activeList.size()), s.samples, s.directions, PT_MODE_TRACE,
               randomRotation(s.options.seed, s.volume.updates));
    s.blendTraced(s.activeList, std::vector<uint32_t>(s.activeList.size(), s.samples), stats);
  } else if (!s.activeList.empty()) {
    std::vector<ProbeNeed> needs(s.activeList.size());
    for (size_t i = 0; i < needs.size(); ++i) {
      const uint32_t p = s.activeList[i];
      const ProbeHistory& h = s.history[p];
      const float signal = coefficientLuminance(&s.volume.probes[static_cast<size_t>(p) * 27], 0);
      ProbeNeed& need = needs[i];
      need.viewWeight = s.viewWeights.empty() ? 1.0f : s.viewWeights[p];
      need.historyWeight = h.n;
      need.relativeVariance = h.n > 0.0f ? estimateVariance(h, 0) / std::max(signal * signal, 1e-12f) : 1.0f;
      need.suspect = h.pending;
      need.age = s.age[p];
    }
    RayBudgetRule rule;
    rule.rays = s.options.raysPerUpdate;
    rule.lane = kLanes;
    rule.nominalSamples = s.samples;
    rule.maxSamples = s.maxSamples;
    rule.refreshShare = s.options.refreshShare;
    rule.outOfViewWeight = s.options.outOfViewWeight;
    std::vector<uint32_t> given(needs.size());
    allocateRays(needs, rule, given.data());
    std::vector<uint32_t> list, samples;
    for (size_t i = 0; i < given.size(); ++i) {
      const uint32_t p = s.activeList[i];
      s.age[p] = given[i] ? 0u : s.age[p] + 1u;
      if (given[i] == 0) continue;
      list.push_back(p);
      samples.push_back(given[i]);
    }
    s.uploadProbeList(list, samples);  // the allocation gives at least one lane: never empty
    s.dispatch(static_cast<uint32_t>(list.size()), 0, s.levelDirections, PT_MODE_TRACE,
               randomRotation(s.options.seed, s.volume.updates), 1);
    s.blendTraced(list, samples, stats);
  }
  // One more update of each active probe's light holding still (setScene starts the count again).
  s.volume.stillUpdates.resize(s.volume.count(), 0);
  for (uint32_t p = 0; p < s.volume.count(); ++p) {
    uint32_t& still = s.volume.stillUpdates[p];
    still = s.volume.active[p] ? std::max(still, still + 1) : 0;  // saturates
  }
  ++s.volume.updates;
  stats.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return stats;
}

void ProbeUpdater::Impl::blendTraced(const std::vector<uint32_t>& list, const std::vector<uint32_t>& traced,
                                     UpdateStats& stats) {
  Impl& s = *this;
  // ĉ = (4π/S) Σ lanes, summed in a fixed order (deterministic). The lanes' partial sums are
  // independent estimates over interleaved subsets of the directions: their spread estimates
  // the variance of ĉ before any history exists.
  const float* part = static_cast<const float*>(s.partials.mapped);
  const HistoryOptions blend{s.options.minBlendWeight, s.options.rejectSigmas};
  s.volume.noise.resize(s.volume.count(), 0.0f);
  s.restartKind.resize(s.volume.count(), kNoRestart);
  for (size_t i = 0; i < list.size(); ++i) {
    const uint32_t p = list[i];
    const float scale = 4.0f * 3.14159265358979f / static_cast<float>(traced[i]);
    const float weight = static_cast<float>(traced[i]) / static_cast<float>(s.samples);  // 1 without a budget
    s.lastSamples[p] = traced[i];
    stats.paths += traced[i];
    ++stats.tracedProbes;
    float sum[27] = {};
    for (uint32_t lane = 0; lane < kLanes; ++lane) {
      const float* src = part + (i * kLanes + lane) * PT_PARTIAL_FLOATS;
      for (int k = 0; k < 27; ++k) sum[k] += src[k];
      stats.closestHitRays += static_cast<uint64_t>(src[28]);
      stats.shadowRays += static_cast<uint64_t>(src[29]);
      stats.droppedSamples += static_cast<uint64_t>(src[30]);
    }
    float fresh[27];
    bool finite = true;
    for (int k = 0; k < 27; ++k) {
      fresh[k] = sum[k] * scale;
      finite = finite && std::isfinite(fresh[k]);
    }
    if (!finite) continue;  // an overflowing estimate is dropped whole, the history kept
    float spread[kHistoryLuma] = {};
    for (uint32_t lane = 0; lane < kLanes; ++lane) {
      const float* src = part + (i * kLanes + lane) * PT_PARTIAL_FLOATS;
      for (int k = 0; k < kHistoryLuma; ++k) {
        const float dev = coefficientLuminance(src, k) * scale * static_cast<float>(kLanes) - coefficientLuminance(fresh, k);
        spread[k] += dev * dev;
      }
    }
    for (float& v : spread) v /= static_cast<float>(kLanes) * static_cast<float>(kLanes - 1);
    float* c = &s.volume.probes[static_cast<size_t>(p) * 27];
    // What a restart moves the probe by is weighed against the noise of the history it replaces.
    const float lumBefore = coefficientLuminance(c, 0);
    const float noiseBefore = estimateVariance(s.history[p], 0) * (1.0f / weight + s.history[p].varianceFactor);
    const BlendOutcome outcome = blendEstimate(s.history[p], c, fresh, spread, blend, weight);
    if (outcome == BlendOutcome::Restarted || outcome == BlendOutcome::RestartedFromAverage) {
      ++stats.restartedProbes;
      const float moved = coefficientLuminance(c, 0) - lumBefore;
      const float strong = 2.0f * s.options.rejectSigmas;
      s.restarted.push_back(p);
      s.restartKind[p] = moved * moved > strong * strong * noiseBefore ? kStrongRestart : kRestart;
    }
    s.volume.noise[p] = historyStandardError(s.history[p]);
  }
  shortenNeighbours();
}

void ProbeUpdater::Impl::shortenNeighbours() {
  Impl& s = *this;
  const uint32_t* n = s.volume.grid.dims;
  const auto at = [n](uint32_t p) { return std::array<uint32_t, 3>{p % n[0], (p / n[0]) % n[1], p / (n[0] * n[1])}; };
  // Whether another probe of p's 3×3×3 block restarted in this update.
  const auto anotherAround = [&](uint32_t p) {
    const std::array<uint32_t, 3> c = at(p);
    for (uint32_t z = c[2] ? c[2] - 1 : 0; z <= std::min(c[2] + 1, n[2] - 1); ++z)
      for (uint32_t y = c[1] ? c[1] - 1 : 0; y <= std::min(c[1] + 1, n[1] - 1); ++y)
        for (uint32_t x = c[0] ? c[0] - 1 : 0; x <= std::min(c[0] + 1, n[0] - 1); ++x) {
          const uint32_t q = x + n[0] * (y + n[1] * z);
          if (q != p && s.restartKind[q] != kNoRestart) return true;
        }
    return false;
  };
  if (s.options.neighbourHistory > 0.0f && s.options.rejectSigmas > 0.0f) {
    const uint32_t stride[3] = {1, n[0], n[0] * n[1]};
    for (uint32_t p : s.restarted) {
      // Only a restart that moved the probe by twice the rejection threshold, or one another
      // nearby agrees with: noise restarts a probe now and then, alone and barely past the
      // threshold; a change of the light moves it further, or several together.
      if (s.restartKind[p] != kStrongRestart && !anotherAround(p)) continue;
      const std::array<uint32_t, 3> c = at(p);
      for (int axis = 0; axis < 3; ++axis)
        for (int side = -1; side <= 1; side += 2) {
          if ((side < 0 && c[axis] == 0) || (side > 0 && c[axis] + 1 >= n[axis])) continue;
          const uint32_t q = side < 0 ? p - stride[axis] : p + stride[axis];
          if (!s.volume.active[q] || s.restartKind[q] != kNoRestart) continue;
          shortenHistory(s.history[q], s.options.neighbourHistory);
          s.volume.noise[q] = historyStandardError(s.history[q]);
        }
    }
  }
  for (uint32_t p : s.restarted) s.restartKind[p] = kNoRestart;
  s.restarted.clear();
}

void ProbeUpdater::setViewWeights(std::vector<float> weights) {
  if (!weights.empty() && weights.size() != impl_->volume.count())
    throw std::invalid_argument("view weights: " + std::to_string(weights.size()) + " for " +
                                std::to_string(impl_->volume.count()) + " probes");
  for (float w : weights)
    if (!(w >= 0.0f && w <= 1.0f)) throw std::invalid_argument("view weights: each must be in [0, 1]");
  impl_->viewWeights = std::move(weights);
}

const std::vector<uint32_t>& ProbeUpdater::lastSamples() const { return impl_->lastSamples; }

uint32_t ProbeUpdater::probeCount() const { return impl_->volume.count(); }
uint32_t ProbeUpdater::updates() const { return impl_->volume.updates; }
const ProbeVolume& ProbeUpdater::volume() const { return impl_->volume; }
const ProbeGrid& ProbeUpdater::grid() const { return impl_->volume.grid; }
const ClassifyStats& ProbeUpdater::classifyStats() const { return impl_->classifyStats; }
const GeometryStats& ProbeUpdater::geometryStats() const { return impl_->geometryStats; }

uint64_t ProbeUpdater::deviceBytes() const {
  const Impl& s = *impl_;
  uint64_t total = 0;
  for (const Buffer* b : {&s.directions, &s.classifyDirections, &s.probeList, &s.partials, &s.levelDirections, &s.gpu.triangleMaterial,
                          &s.gpu.materials, &s.gpu.lights, &s.gpu.emitters, &s.gpu.normals, &s.gpu.texcoords, &s.gpu.texels,
                          &s.gpu.textures, &s.gpu.environment, &s.gpu.environmentData, &s.gpu.accel.positions, &s.gpu.accel.indices,
                          &s.pass.sbt})
    total += b->size;
  return total + sceneAccelBytes(s.gpu.accel);
}

}  // namespace probecast::renderer
