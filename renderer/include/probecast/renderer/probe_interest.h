// Which probes viewers can see: the weight the updater's ray budget gives each probe for being
// inside some subscriber's view (ProbeUpdater::setViewWeights), and how much of the views each
// probe lights (the noise rule's view weights, StreamEncoder::setViewWeights).
#pragma once

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "probecast/codec/priority.h"
#include "probecast/codec/probe_offsets.h"
#include "probecast/codec/probe_volume.h"
#include "probecast/scene/area_lights.h"
#include "probecast/scene/scene.h"

namespace probecast::renderer {

// Per probe (grid order): 1 when the box it shades (its position, plus `offsets` when not empty,
// grown by one cell on every side: its trilinear support) meets the frustum of any of `views`,
// else 0. Empty when there are no views: nobody's interest is known, every probe counts alike.
// A view with non-finite numbers sees nothing.
std::vector<float> probeViewWeights(const ProbeGrid& grid, const std::vector<float>& offsets, std::span<const View> views);

// At most `most` of `views`, evenly spread over the list. The producer samples kFootprintViews of
// its subscribers' views: each costs a pass over the triangles, and neighbouring views show mostly
// the same probes.
std::vector<View> spreadViews(std::span<const View> views, size_t most);
constexpr size_t kFootprintViews = 16;
// The sample grid per view (16:10) for `views` views that keeps their samples together near
// kFootprintSamples: 256 × 160 for one view, 64 × 40 for sixteen. Walls seen at a grazing angle
// and thin ledges cover few pixels; too coarse a grid misses the probes that light them.
constexpr uint32_t kFootprintSamples = 40960;
glm::uvec2 footprintSampleSize(size_t views);

// The surfaces views show: one sample per pixel centre that some triangle covers, found by a
// depth-buffered rasterisation of the scene's triangles on the CPU (Vulkan clip space, as View
// holds it: clipped at the near plane z = 0, nothing past the far one), with the probes that light
// it as the raster client weighs them without visibility: the eight probes of its grid cell,
// trilinear × backface ((cos + 1)/2)² + 0.2 (towards each probe where it was traced: its grid
// position plus `offsets`, xyz per probe, when they are given and finite), the inactive ones left
// out, normalised to sum 1. A point whose probes all lie behind its surface's plane is left out,
// as the client lights it with none of them. A view with non-finite numbers sees nothing.
struct ViewSample {
  glm::vec3 point{0.0f};
  glm::vec3 normal{0.0f, 1.0f, 0.0f};  // the triangle's geometric normal, on the viewer's side
  glm::vec3 toEye{0.0f, 1.0f, 0.0f};   // unit direction to the view's eye
  uint32_t material = 0;               // Scene::triangleMaterial of the triangle (0 when the scene has none)
  uint32_t probes[8] = {};
  float weights[8] = {};               // sum 1 (a sample no active probe lights is left out)
};
std::vector<ViewSample> sampleViewSurfaces(const scene::Scene& scene, const ProbeGrid& grid,
                                           std::span<const uint8_t> active, std::span<const float> offsets,
                                           std::span<const View> views, uint32_t width = 64, uint32_t height = 40);

// Per probe (grid order): how much of the views' pixels it lights, Σ over the samples of its
// normalised weight squared (what an error in that probe adds to the views' squared error, per
// unit of the pixel's irradiance).
std::vector<float> probeViewFootprints(std::span<const ViewSample> samples, uint32_t probeCount);
// The same from the scene and the views (sampleViewSurfaces). Empty when there are no views.
std::vector<float> probeViewFootprints(const scene::Scene& scene, const ProbeGrid& grid, std::span<const uint8_t> active,
                                       std::span<const View> views, uint32_t width = 64, uint32_t height = 40);

// What a viewer adds to the probes' light at a surface, and how it turns probes into light there,
// for probeViewSensitivity.
struct SurfaceMaterial {
  glm::vec3 diffuse{0.8f};           // base colour × (1 − metallic) × its texture's mean (linear)
  glm::vec3 specular{0.04f};         // F0 = mix(0.04, base colour × texture mean, metallic)
  glm::vec3 emission{0.0f};          // emission × its texture's mean
  glm::vec2 lobe{0.0f};              // the GGX lobe's band 1 and 2 scales at its roughness (glossy_sh.h)
  float roughness = 1.0f;
};
struct SurfaceLighting {
  std::vector<SurfaceMaterial> materials;  // per scene material
  // The material of index `m`; past the list, glTF's default (0.8 grey, rough, not metallic).
  SurfaceMaterial material(uint32_t m) const { return m < materials.size() ? materials[m] : SurfaceMaterial{}; }
  std::vector<scene::Light> lights; // punctual
  scene::AreaLightSet areaLights;   // client area lights (empty: none)
  std::vector<float> envBrdf;       // (A, B) over [roughness][n·v], envBrdfSize² texel centres (glossy_sh.h)
  int envBrdfSize = 0;
};
// Textures are averaged on a grid of at most 64 × 64 texels.
SurfaceLighting surfaceLighting(const scene::Scene& scene, const scene::AreaLightOptions& areaLights);

// Per sample: what a viewer adds there to the probes' light, as its raster client shades it: the
// material's emission, the Lambertian part of its punctual lights, in shadow where the light's own
// view of the scene (a depth rasterisation on the CPU: six 192² cube faces for point and spot
// lights, one 512² orthographic view over the scene for directional ones, 3 × 3 texels averaged)
// finds a nearer surface, and of its client area lights, unshadowed. Worked out again when the
// samples or the lights change; the probes' light changes every update.
std::vector<glm::vec3> sampleDirectLight(const scene::Scene& scene, std::span<const ViewSample> samples,
                                         const SurfaceLighting& lighting);

// Per probe (grid order): how much the views change, after the plain gamma 2.2 that images are
// scored in, when that probe alone is made 20 % brighter: Σ over the samples and RGB of
// (g′(L) · 0.2 · ŵ · I_p)², with g(L) = L^(1/2.2), ŵ the probe's weight at the sample, I_p the
// light the raster client takes from the probe there (diffuse ρ/π · E_p(n) plus the split-sum
// glossy term toward the reflected view direction, each clamped at 0) and L the sample's radiance
// as the client shades it: `direct` (sampleDirectLight, one per sample; left out when the sizes
// differ) + Σ ŵ I. A dim surface counts for more than a bright one, as gamma makes it; a probe's
// own brightness counts squared. `probes`: kProbeFloats per probe, the light viewers hold.
// Non-finite coefficients count as 0; a material past the list counts as SurfaceLighting::material
// says.
std::vector<float> probeViewSensitivity(std::span<const ViewSample> samples, std::span<const glm::vec3> direct,
                                        const SurfaceLighting& lighting, std::span<const float> probes,
                                        uint32_t probeCount);

// The weights a stream is given are a slow moving average of probeViewSensitivity: `held` ←
// (1 − rate) · held + rate · `fresh`, or `fresh` itself when `held` is empty or of another size.
// A non-finite or negative fresh weight leaves that probe's as it was. The producer blends at
// kViewWeightBlend: worked out anew every update from the updater's noisy volume, the weights
// moved a probe's threshold up and down from one update to the next and the held light strayed
// (bench adaptive, seeds 1–5: 0.23 dB lost unblended, 0.07 dB blended, at the same bytes).
constexpr float kViewWeightBlend = 1.0f / 32.0f;
void blendViewWeights(std::vector<float>& held, std::span<const float> fresh, float rate = kViewWeightBlend);

}  // namespace probecast::renderer
