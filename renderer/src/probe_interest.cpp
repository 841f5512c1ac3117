// Probes inside the subscribers' views (probe_interest.h).
#include "probecast/renderer/probe_interest.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "area_light_math.h"
#include "probecast/codec/sh.h"
#include "probecast/renderer/glossy_sh.h"

namespace probecast::renderer {
namespace {

bool finiteView(const View& v) {
  return std::all_of(std::begin(v.viewProj), std::end(v.viewProj), [](float f) { return std::isfinite(f); });
}

}  // namespace

std::vector<float> probeViewWeights(const ProbeGrid& grid, const std::vector<float>& offsets, std::span<const View> views) {
  std::vector<const View*> usable;
  for (const View& v : views)
    if (finiteView(v)) usable.push_back(&v);
  if (views.empty()) return {};
  const uint32_t count = grid.count();
  const bool moved = offsets.size() == static_cast<size_t>(count) * 3;
  float cell[3];
  for (int a = 0; a < 3; ++a) cell[a] = probeCellSize(grid, a);
  std::vector<float> weights(count, 0.0f);
  for (uint32_t p = 0; p < count; ++p) {
    float centre[3], lo[3], hi[3];
    grid.position(p, centre);
    for (int a = 0; a < 3; ++a) {
      const float c = centre[a] + (moved ? offsets[static_cast<size_t>(p) * 3 + a] : 0.0f);
      lo[a] = c - cell[a];
      hi[a] = c + cell[a];
    }
    for (const View* v : usable)
      if (boxIntersectsFrustum(v->viewProj, lo, hi)) {
        weights[p] = 1.0f;
        break;
      }
  }
  return weights;
}

}  // namespace probecast::renderer

namespace probecast::renderer {
namespace {

struct ClipVertex {
  glm::vec4 clip;
  glm::vec3 world;
};

// The polygon's part in front of the near plane (Vulkan clip space: z > 0), Sutherland–Hodgman.
size_t clipNear(const ClipVertex* in, size_t n, ClipVertex* out) {
  size_t m = 0;
  for (size_t i = 0; i < n; ++i) {
    const ClipVertex& a = in[i];
    const ClipVertex& b = in[(i + 1) % n];
    const bool aIn = a.clip.z > 0.0f, bIn = b.clip.z > 0.0f;
    if (aIn) out[m++] = a;
    if (aIn != bIn) {
      const float t = a.clip.z / (a.clip.z - b.clip.z);
      out[m++] = {a.clip + t * (b.clip - a.clip), a.world + t * (b.world - a.world)};
    }
  }
  return m;
}

// The nearest surface at each pixel centre of a width × height view (Vulkan clip space: clipped at
// the near plane z = 0, nothing past the far one): its clip z/w in `depth` (+inf: none), its
// triangle and its world point. Every triangle counts as opaque.
void rasterizeNearest(const scene::Scene& scene, const glm::mat4& viewProj, uint32_t width, uint32_t height,
                      std::vector<float>& depth, std::vector<uint32_t>& nearest, std::vector<glm::vec3>& point) {
  const size_t pixels = static_cast<size_t>(width) * height;
  depth.assign(pixels, INFINITY);
  nearest.resize(pixels);
  point.resize(pixels);
  const uint32_t triangles = scene.triangleCount();
  for (uint32_t t = 0; t < triangles; ++t) {
    ClipVertex tri[3], poly[4];
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& p = scene.positions[scene.indices[3 * t + k]];
      tri[k] = {viewProj * glm::vec4(p, 1.0f), p};
    }
    const size_t n = clipNear(tri, 3, poly);
    for (size_t f = 1; f + 1 < n; ++f) {  // the clipped polygon as a fan
      const ClipVertex* c[3] = {&poly[0], &poly[f], &poly[f + 1]};
      if (!(c[0]->clip.w > 0.0f && c[1]->clip.w > 0.0f && c[2]->clip.w > 0.0f)) continue;  // not a projection
      glm::vec2 s[3];
      float invW[3], z[3];
      for (int k = 0; k < 3; ++k) {
        invW[k] = 1.0f / c[k]->clip.w;
        z[k] = c[k]->clip.z * invW[k];
        s[k] = {(c[k]->clip.x * invW[k] * 0.5f + 0.5f) * static_cast<float>(width),
                (c[k]->clip.y * invW[k] * 0.5f + 0.5f) * static_cast<float>(height)};
      }
      const float area = (s[1].x - s[0].x) * (s[2].y - s[0].y) - (s[2].x - s[0].x) * (s[1].y - s[0].y);
      if (!(std::fabs(area) > 0.0f) || !std::isfinite(area)) continue;
      const float x0 = std::max(0.0f, std::floor(std::min({s[0].x, s[1].x, s[2].x})));
      const float x1 = std::min(static_cast<float>(width) - 1.0f, std::ceil(std::max({s[0].x, s[1].x, s[2].x})));
      const float y0 = std::max(0.0f, std::floor(std::min({s[0].y, s[1].y, s[2].y})));
      const float y1 = std::min(static_cast<float>(height) - 1.0f, std::ceil(std::max({s[0].y, s[1].y, s[2].y})));
      for (float y = y0; y <= y1; y += 1.0f)
        for (float x = x0; x <= x1; x += 1.0f) {
          const glm::vec2 q(x + 0.5f, y + 0.5f);
          float b[3];
          for (int k = 0; k < 3; ++k) {
            const glm::vec2& e0 = s[(k + 1) % 3];
            const glm::vec2& e1 = s[(k + 2) % 3];
            b[k] = ((e1.x - e0.x) * (q.y - e0.y) - (q.x - e0.x) * (e1.y - e0.y)) / area;
          }
          if (b[0] < 0.0f || b[1] < 0.0f || b[2] < 0.0f) continue;
          const float zw = b[0] * z[0] + b[1] * z[1] + b[2] * z[2];  // z/w and 1/w are linear on the screen
          const size_t i = static_cast<size_t>(y) * width + static_cast<size_t>(x);
          if (!(zw < depth[i]) || zw > 1.0f) continue;  // hidden, or past the far plane
          const float inv = b[0] * invW[0] + b[1] * invW[1] + b[2] * invW[2];
          depth[i] = zw;
          nearest[i] = t;
          point[i] = (b[0] * invW[0] * c[0]->world + b[1] * invW[1] * c[1]->world + b[2] * invW[2] * c[2]->world) / inv;
        }
    }
  }
}

}  // namespace

std::vector<View> spreadViews(std::span<const View> views, size_t most) {
  const size_t n = std::min(views.size(), most);
  std::vector<View> out;
  for (size_t k = 0; k < n; ++k) out.push_back(views[k * views.size() / n]);
  return out;
}

glm::uvec2 footprintSampleSize(size_t views) {
  const double perView = static_cast<double>(kFootprintSamples) / static_cast<double>(std::max<size_t>(views, 1));
  const double height = std::max(1.0, std::floor(std::sqrt(perView / 1.6)));
  return {static_cast<uint32_t>(std::max(1.0, std::floor(height * 1.6))), static_cast<uint32_t>(height)};
}

std::vector<ViewSample> sampleViewSurfaces(const scene::Scene& scene, const ProbeGrid& grid,
                                           std::span<const uint8_t> active, std::span<const float> offsets,
                                           std::span<const View> views, uint32_t width, uint32_t height) {
  std::vector<ViewSample> samples;
  if (width == 0 || height == 0) return samples;
  const uint32_t count = grid.count();
  const bool moved = offsets.size() == static_cast<size_t>(count) * 3 &&
                     std::all_of(offsets.begin(), offsets.end(), [](float x) { return std::isfinite(x); });
  float spacing = 0.0f;  // the smallest probe spacing, as the raster client takes it
  for (int a = 0; a < 3; ++a)
    if (grid.dims[a] > 1) spacing = spacing > 0.0f ? std::min(spacing, probeCellSize(grid, a)) : probeCellSize(grid, a);
  if (!(spacing > 0.0f)) spacing = 1.0f;
  const size_t pixels = static_cast<size_t>(width) * height;
  std::vector<float> depth;  // clip z/w of the nearest surface (+inf: none)
  std::vector<uint32_t> nearest;
  std::vector<glm::vec3> point;
  const glm::vec3 lo(grid.bounds.min[0], grid.bounds.min[1], grid.bounds.min[2]);
  const glm::vec3 hi(grid.bounds.max[0], grid.bounds.max[1], grid.bounds.max[2]);
  const glm::ivec3 dims(static_cast<int>(grid.dims[0]), static_cast<int>(grid.dims[1]), static_cast<int>(grid.dims[2]));
  for (const View& v : views) {
    if (!finiteView(v)) continue;
    glm::mat4 viewProj;
    std::copy(std::begin(v.viewProj), std::end(v.viewProj), &viewProj[0][0]);
    const glm::vec3 eye(v.eye[0], v.eye[1], v.eye[2]);
    rasterizeNearest(scene, viewProj, width, height, depth, nearest, point);
    // Each covered pixel's eight probes, weighted as the raster client weighs them without visibility.
    for (size_t i = 0; i < pixels; ++i) {
      if (!(depth[i] < INFINITY)) continue;
      const uint32_t t = nearest[i];
      const glm::vec3& a = scene.positions[scene.indices[3 * t]];
      glm::vec3 ng = glm::cross(scene.positions[scene.indices[3 * t + 1]] - a, scene.positions[scene.indices[3 * t + 2]] - a);
      const float len = glm::length(ng);
      if (!(len > 0.0f)) continue;
      ng /= len;
      if (glm::dot(ng, eye - point[i]) < 0.0f) ng = -ng;  // the side the view sees
      const glm::vec3 g = glm::clamp((point[i] - lo) / glm::max(hi - lo, glm::vec3(1e-6f)) * glm::vec3(dims - 1),
                                     glm::vec3(0.0f), glm::vec3(dims - 1));
      const glm::ivec3 base = glm::min(glm::ivec3(glm::floor(g)), glm::max(dims - 2, glm::ivec3(0)));
      const glm::vec3 alpha = glm::clamp(g - glm::vec3(base), glm::vec3(0.0f), glm::vec3(1.0f));
      float w[8];
      uint32_t index[8];
      float total = 0.0f;
      bool anyInFront = false;
      for (int k = 0; k < 8; ++k) {
        const glm::ivec3 off(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        const glm::vec3 t3 = glm::mix(glm::vec3(1.0f) - alpha, alpha, glm::vec3(off));
        const glm::ivec3 idx = glm::min(base + off, dims - 1);
        index[k] = static_cast<uint32_t>(idx.x + dims.x * (idx.y + dims.y * idx.z));
        w[k] = 0.0f;
        const float trilinear = t3.x * t3.y * t3.z;
        if (!(trilinear > 0.0f) || (!active.empty() && !active[index[k]])) continue;
        float at[3];
        grid.position(index[k], at);
        glm::vec3 probe(at[0], at[1], at[2]);
        if (moved) probe += glm::vec3(offsets[index[k] * 3], offsets[index[k] * 3 + 1], offsets[index[k] * 3 + 2]);
        const glm::vec3 toProbe = probe - point[i];
        const float d = glm::length(toProbe);
        const float facing = d > 1e-6f ? (glm::dot(toProbe / d, ng) + 1.0f) * 0.5f : 1.0f;
        anyInFront = anyInFront || glm::dot(toProbe, ng) > -1e-3f * spacing;
        w[k] = (facing * facing + 0.2f) * trilinear;
        total += w[k];
      }
      // Every probe behind the surface's plane: the raster client lights the point with none.
      if (!(total > 0.0f) || !anyInFront) continue;
      ViewSample& sample = samples.emplace_back();
      sample.point = point[i];
      sample.normal = ng;
      sample.toEye = glm::normalize(eye - point[i]);
      sample.material = t < scene.triangleMaterial.size() ? scene.triangleMaterial[t] : 0;
      for (int k = 0; k < 8; ++k) {
        sample.probes[k] = index[k];
        sample.weights[k] = w[k] / total;
      }
    }
  }
  return samples;
}

std::vector<float> probeViewFootprints(std::span<const ViewSample> samples, uint32_t probeCount) {
  std::vector<float> footprint(probeCount, 0.0f);
  for (const ViewSample& s : samples)
    for (int k = 0; k < 8; ++k)
      if (s.weights[k] > 0.0f && s.probes[k] < probeCount) footprint[s.probes[k]] += s.weights[k] * s.weights[k];
  return footprint;
}

std::vector<float> probeViewFootprints(const scene::Scene& scene, const ProbeGrid& grid, std::span<const uint8_t> active,
                                       std::span<const View> views, uint32_t width, uint32_t height) {
  if (views.empty()) return {};
  return probeViewFootprints(sampleViewSurfaces(scene, grid, active, {}, views, width, height), grid.count());
}

}  // namespace probecast::renderer

namespace probecast::renderer {
namespace {

// The mean linear colour of an sRGB texture, over a grid of at most 64 × 64 texels.
glm::vec3 meanLinear(const scene::Texture& t) {
  if (t.width == 0 || t.height == 0 || t.rgba.size() < static_cast<size_t>(t.width) * t.height * 4) return glm::vec3(1.0f);
  float decode[256];
  for (int i = 0; i < 256; ++i) {
    const float c = static_cast<float>(i) / 255.0f;
    decode[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
  }
  const uint32_t stepX = std::max(1u, t.width / 64), stepY = std::max(1u, t.height / 64);
  glm::dvec3 sum(0.0);
  size_t n = 0;
  for (uint32_t y = stepY / 2; y < t.height; y += stepY)
    for (uint32_t x = stepX / 2; x < t.width; x += stepX) {
      const uint8_t* texel = &t.rgba[(static_cast<size_t>(y) * t.width + x) * 4];
      sum += glm::dvec3(decode[texel[0]], decode[texel[1]], decode[texel[2]]);
      ++n;
    }
  return n ? glm::vec3(sum / static_cast<double>(n)) : glm::vec3(1.0f);
}

// As the raster client's table (raster_client.cpp), sampled with bilinear filtering.
constexpr int kEnvBrdfSize = 32;

glm::vec2 envBrdfAt(const SurfaceLighting& l, float nv, float roughness) {
  const int n = l.envBrdfSize;
  if (n <= 0 || l.envBrdf.size() < static_cast<size_t>(n) * n * 2) return glm::vec2(0.0f);
  const float x = std::clamp(nv * static_cast<float>(n) - 0.5f, 0.0f, static_cast<float>(n - 1));
  const float y = std::clamp(roughness * static_cast<float>(n) - 0.5f, 0.0f, static_cast<float>(n - 1));
  const int x0 = std::min(static_cast<int>(x), n - 1), y0 = std::min(static_cast<int>(y), n - 1);
  const int x1 = std::min(x0 + 1, n - 1), y1 = std::min(y0 + 1, n - 1);
  const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
  const auto at = [&](int i, int j) { return glm::vec2(l.envBrdf[(j * n + i) * 2], l.envBrdf[(j * n + i) * 2 + 1]); };
  return glm::mix(glm::mix(at(x0, y0), at(x1, y0), fx), glm::mix(at(x0, y1), at(x1, y1), fx), fy);
}

}  // namespace

SurfaceLighting surfaceLighting(const scene::Scene& scene, const scene::AreaLightOptions& areaLights) {
  SurfaceLighting out;
  std::vector<glm::vec3> textureMean(scene.textures.size());
  for (size_t i = 0; i < scene.textures.size(); ++i) textureMean[i] = meanLinear(scene.textures[i]);
  const auto texture = [&](int32_t index) {
    return index >= 0 && static_cast<size_t>(index) < textureMean.size() ? textureMean[index] : glm::vec3(1.0f);
  };
  const renderer::GgxLobeFit fit = renderer::ggxLobeFit();
  for (const scene::Material& m : scene.materials) {
    const glm::vec3 base = m.baseColor * texture(m.baseColorTexture);
    const std::array<double, 3> g = fit.evaluate(m.roughness);
    out.materials.push_back({base * (1.0f - m.metallic), glm::mix(glm::vec3(0.04f), base, m.metallic),
                             m.emission * texture(m.emissiveTexture),
                             glm::vec2(static_cast<float>(g[1]), static_cast<float>(g[2])), m.roughness});
  }
  out.envBrdfSize = kEnvBrdfSize;
  out.envBrdf = renderer::envBrdfTable(kEnvBrdfSize, 256);
  out.lights = scene.lights;
  out.areaLights = scene::extractAreaLights(scene, areaLights);
  return out;
}

namespace {

// A punctual light's own view of the scene, for shadows: the distance from the light to the
// nearest surface at each texel of six cube faces (point and spot lights) or of one orthographic
// view over the scene's bounds (directional lights, the distance along the light's direction).
struct LightDepth {
  bool directional = false;
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f, -1.0f, 0.0f};
  glm::mat4 viewProj[6];
  std::vector<float> distance[6];
  uint32_t size = 0;
  float texel = 0.0f;  // world size of a texel (directional), or per metre of distance (cube faces)
};

LightDepth lightDepth(const scene::Scene& scene, const scene::Light& l) {
  LightDepth d;
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& p : scene.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  if (scene.positions.empty()) lo = hi = glm::vec3(0.0f);
  const glm::vec3 centre = 0.5f * (lo + hi);
  const float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
  std::vector<float> depth;
  std::vector<uint32_t> nearest;
  std::vector<glm::vec3> point;
  const auto keep = [&](int f) {
    d.distance[f].assign(depth.size(), INFINITY);
    for (size_t i = 0; i < depth.size(); ++i)
      if (depth[i] < INFINITY)
        d.distance[f][i] = d.directional ? glm::dot(point[i] - d.origin, d.direction) : glm::length(point[i] - d.origin);
  };
  if (l.type == scene::LightType::Directional) {
    d.directional = true;
    d.direction = glm::normalize(l.direction);
    d.origin = centre - d.direction * (2.0f * radius);
    const glm::vec3 up = std::fabs(d.direction.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    d.size = 512;
    d.texel = 2.0f * radius / static_cast<float>(d.size);
    d.viewProj[0] = glm::orthoRH_ZO(-radius, radius, -radius, radius, 0.0f, 4.0f * radius) *
                    glm::lookAt(d.origin, centre, up);
    rasterizeNearest(scene, d.viewProj[0], d.size, d.size, depth, nearest, point);
    keep(0);
    return d;
  }
  d.origin = l.position;
  d.size = 192;
  d.texel = 2.0f / static_cast<float>(d.size);
  const float reach = glm::length(l.position - centre) + radius;
  const glm::vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const glm::vec3 ups[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
  for (int f = 0; f < 6; ++f) {
    d.viewProj[f] = glm::perspectiveRH_ZO(glm::half_pi<float>(), 1.0f, 1e-4f * reach, 2.0f * reach) *
                    glm::lookAt(l.position, l.position + axes[f], ups[f]);
    rasterizeNearest(scene, d.viewProj[f], d.size, d.size, depth, nearest, point);
    keep(f);
  }
  return d;
}

// The fraction of 3 × 3 texels around x's texel whose nearest surface is no nearer the light than
// x (less a bias of a few texels' size): 1 lit, 0 in shadow.
float lightVisibility(const LightDepth& d, const glm::vec3& x) {
  int face = 0;
  float along;
  if (d.directional) {
    along = glm::dot(x - d.origin, d.direction);
  } else {
    const glm::vec3 v = x - d.origin, a = glm::abs(v);
    face = a.x >= a.y && a.x >= a.z ? (v.x > 0 ? 0 : 1) : a.y >= a.z ? (v.y > 0 ? 2 : 3) : (v.z > 0 ? 4 : 5);
    along = glm::length(v);
  }
  const glm::vec4 clip = d.viewProj[face] * glm::vec4(x, 1.0f);
  if (!(clip.w > 0.0f)) return 1.0f;
  const float n = static_cast<float>(d.size);
  const float px = (clip.x / clip.w * 0.5f + 0.5f) * n, py = (clip.y / clip.w * 0.5f + 0.5f) * n;
  if (!(px >= 0.0f && px < n && py >= 0.0f && py < n)) return 1.0f;  // outside what the light's view holds
  const float bias = 3.0f * (d.directional ? d.texel : d.texel * along) + 1e-4f * along;
  int lit = 0, all = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int tx = static_cast<int>(px) + dx, ty = static_cast<int>(py) + dy;
      if (tx < 0 || ty < 0 || tx >= static_cast<int>(d.size) || ty >= static_cast<int>(d.size)) continue;
      ++all;
      lit += d.distance[face][static_cast<size_t>(ty) * d.size + static_cast<size_t>(tx)] >= along - bias;
    }
  return all ? static_cast<float>(lit) / static_cast<float>(all) : 1.0f;
}

}  // namespace

std::vector<glm::vec3> sampleDirectLight(const scene::Scene& scene, std::span<const ViewSample> samples,
                                         const SurfaceLighting& lighting) {
  std::vector<glm::vec3> out(samples.size(), glm::vec3(0.0f));
  std::vector<LightDepth> depths;
  for (const scene::Light& l : lighting.lights) depths.push_back(lightDepth(scene, l));
  for (size_t i = 0; i < samples.size(); ++i) {
    const ViewSample& s = samples[i];
    const SurfaceMaterial m = lighting.material(s.material);
    const glm::vec3 rho = m.diffuse;
    glm::vec3 radiance = m.emission;
    // The Lambertian part of the raster client's sum over its lights.
    for (size_t k = 0; k < lighting.lights.size(); ++k) {
      const scene::Light& l = lighting.lights[k];
      glm::vec3 e = l.color * l.intensity;
      glm::vec3 wi;
      if (l.type == scene::LightType::Directional) {
        wi = -l.direction;
      } else {
        const glm::vec3 toLight = l.position - s.point;
        const float d2 = std::max(glm::dot(toLight, toLight), 1e-8f);
        const float dist = std::sqrt(d2);
        wi = toLight / dist;
        e /= d2;
        if (l.range > 0.0f) e *= std::pow(std::clamp(1.0f - std::pow(dist / l.range, 4.0f), 0.0f, 1.0f), 2.0f);
        if (l.type == scene::LightType::Spot) {
          const float lo = std::cos(l.outerConeAngle), hi = std::cos(l.innerConeAngle);
          const float x = std::clamp((glm::dot(-wi, l.direction) - lo) / std::max(hi - lo, 1e-6f), 0.0f, 1.0f);
          e *= x * x * (3.0f - 2.0f * x);
        }
      }
      const float cosine = glm::dot(s.normal, wi);
      if (cosine > 0.0f && std::isfinite(cosine)) radiance += rho / kPi * cosine * e * lightVisibility(depths[k], s.point);
    }
    for (const scene::AreaLight& a : lighting.areaLights.lights)
      for (size_t c = 0; c + 2 < a.corners.size(); c += 3)
        radiance += rho / kPi * a.radiance *
                    arealight::triangleCosineSolidAngle(s.point, s.normal, a.corners[c], a.corners[c + 1], a.corners[c + 2]);
    if (std::isfinite(radiance.x) && std::isfinite(radiance.y) && std::isfinite(radiance.z)) out[i] = radiance;
  }
  return out;
}

std::vector<float> probeViewSensitivity(std::span<const ViewSample> samples, std::span<const glm::vec3> direct,
                                        const SurfaceLighting& lighting, std::span<const float> probes,
                                        uint32_t probeCount) {
  std::vector<float> sensitivity(probeCount, 0.0f);
  const size_t usable = std::min<size_t>(probeCount, probes.size() / kProbeFloats);
  for (size_t i = 0; i < samples.size(); ++i) {
    const ViewSample& s = samples[i];
    const SurfaceMaterial m = lighting.material(s.material);
    const glm::vec3 rho = m.diffuse;
    const glm::vec2 lobe = m.lobe;
    glm::vec3 radiance(0.0f);  // emission and direct light, then the probes' light
    const float nv = std::clamp(glm::dot(s.normal, s.toEye), 0.0f, 1.0f);
    const glm::vec2 ab = envBrdfAt(lighting, nv, m.roughness);
    const glm::vec3 glossyScale = m.specular * ab.x + ab.y;
    const glm::vec3 r = glm::reflect(-s.toEye, s.normal);
    if (direct.size() == samples.size()) radiance += direct[i];
    // The probes' diffuse light, each probe's part of it.
    glm::vec3 part[8];
    for (int k = 0; k < 8; ++k) {
      part[k] = glm::vec3(0.0f);
      if (!(s.weights[k] > 0.0f) || s.probes[k] >= usable) continue;
      const float* c = probes.data() + static_cast<size_t>(s.probes[k]) * kProbeFloats;
      if (!std::all_of(c, c + kProbeFloats, [](float x) { return std::isfinite(x); })) continue;
      float e[3], basis[kShCoeffs];
      shEvalIrradiance(c, s.normal.x, s.normal.y, s.normal.z, e);
      // Prefiltered radiance toward r: band l scaled by the lobe's g_l (g_0 = 1).
      shEvalBasis(r.x, r.y, r.z, basis);
      glm::vec3 prefiltered(0.0f);
      for (int j = 0; j < kShCoeffs; ++j) {
        const float g = shBand(j) == 0 ? 1.0f : shBand(j) == 1 ? lobe.x : lobe.y;
        prefiltered += g * basis[j] * glm::vec3(c[3 * j], c[3 * j + 1], c[3 * j + 2]);
      }
      part[k] = s.weights[k] * (rho / kPi * glm::max(glm::vec3(e[0], e[1], e[2]), glm::vec3(0.0f)) +
                                glm::max(prefiltered, glm::vec3(0.0f)) * glossyScale);
      radiance += part[k];
    }
    // g′(L) = L^(1/2.2 − 1) / 2.2; each part is at most L, so g′ · part stays finite as L → 0.
    glm::vec3 slope(0.0f);
    for (int c = 0; c < 3; ++c)
      if (radiance[c] > 0.0f && std::isfinite(radiance[c])) slope[c] = std::pow(radiance[c], 1.0f / 2.2f - 1.0f) / 2.2f;
    for (int k = 0; k < 8; ++k) {
      const glm::vec3 change = slope * 0.2f * part[k];
      const float squared = glm::dot(change, change);
      if (squared > 0.0f && std::isfinite(squared)) sensitivity[s.probes[k]] += squared;
    }
  }
  return sensitivity;
}

void blendViewWeights(std::vector<float>& held, std::span<const float> fresh, float rate) {
  if (held.size() != fresh.size()) {
    held.assign(fresh.begin(), fresh.end());
    for (float& w : held)
      if (!(std::isfinite(w) && w >= 0.0f)) w = 0.0f;
    return;
  }
  const float keep = 1.0f - rate;
  for (size_t p = 0; p < held.size(); ++p)
    if (std::isfinite(fresh[p]) && fresh[p] >= 0.0f) held[p] = keep * held[p] + rate * fresh[p];
}

}  // namespace probecast::renderer
