// Probe visibility in the raster client: distance moments made from the client's own geometry,
// and the leaks they stop (light through a thin wall, a box face darkened by probes inside it).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probe_visibility.h"  // kVisibilityProxyError
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

// The centre of texel (i, j) of an octahedral map of n² texels, as a unit direction (the map of
// raster.frag / probe_visibility.cpp: (x, y) / (|x| + |y| + |z|), folded for z < 0).
glm::vec3 octTexelDirection(int i, int j, int n) {
  const glm::vec2 e((static_cast<float>(i) + 0.5f) / static_cast<float>(n) * 2.0f - 1.0f,
                    (static_cast<float>(j) + 0.5f) / static_cast<float>(n) * 2.0f - 1.0f);
  glm::vec3 v(e.x, e.y, 1.0f - std::abs(e.x) - std::abs(e.y));
  if (v.z < 0.0f)
    v = {(1.0f - std::abs(e.y)) * (e.x >= 0.0f ? 1.0f : -1.0f), (1.0f - std::abs(e.x)) * (e.y >= 0.0f ? 1.0f : -1.0f), v.z};
  return glm::normalize(v);
}

// Distance from `p` inside the box [-1, 1]³ to its walls along the unit direction `d`.
float distanceToBoxWalls(const glm::vec3& p, const glm::vec3& d) {
  float t = 1e30f;
  for (int a = 0; a < 3; ++a)
    if (std::abs(d[a]) > 1e-6f) t = std::min(t, ((d[a] > 0.0f ? 1.0f : -1.0f) - p[a]) / d[a]);
  return t;
}

TEST(ProbeVisibility, MeanDistanceInAClosedBoxMatchesTheWallsPerDirection) {
  // One probe in builtin:closed-box (inner walls at ±1 m): E[r] toward each texel centre is the
  // distance to the walls that way, averaged over the texel's cos^50 lobe (a few % above the
  // central value on a flat wall, where 1/cos grows off-axis; below it near edges and corners,
  // where the distance peaks). 10 % everywhere, 3 % along the six axes. Then the same probe moved
  // by an offset of (0.5, 0, 0), half its cell: the cube is drawn from where the probe is,
  // not its grid point. The probe is the middle one of three along x (spacing 1 m).
  VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("closed-box");
  RasterRenderer raster(context, s, 16, 16);
  ProbeVolume v = makeProbeVolume(ProbeGrid{{3, 1, 1}, {{-1.0f, -0.5f, -0.5f}, {1.0f, 0.5f, 0.5f}}});
  for (const glm::vec3 probe : {glm::vec3(0.0f), glm::vec3(0.5f, 0.0f, 0.0f)}) {  // probe 1, at the origin
    v.offsets.assign(9, 0.0f);
    v.offsets[3] = probe.x;
    raster.setProbes(v);
    ASSERT_TRUE(raster.visibilityActive());
    const auto n = static_cast<int>(RasterRenderer::visibilityMapTexels());
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const glm::vec3 d = octTexelDirection(i, j, n);
        const glm::vec2 m = raster.probeMoments(1, d);
        const float expected = distanceToBoxWalls(probe, d);
        EXPECT_NEAR(m.x, expected, 0.1f * expected) << "probe " << probe.x << " texel " << i << "," << j;
        EXPECT_GE(m.y, m.x * m.x * 0.999f);  // E[r²] ≥ E[r]²
      }
    const glm::vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const glm::vec3& a : axes) {
      // The nearest texel's centre is up to half a texel off the axis: compare with the wall there.
      const float m = raster.probeMoments(1, a).x, expected = distanceToBoxWalls(probe, a);
      EXPECT_NEAR(m, expected, 0.03f * expected + 0.03f) << a.x << "," << a.y << "," << a.z;
    }
  }
  EXPECT_LT(raster.probeMoments(1, {1, 0, 0}).x, 0.6f);   // 0.5 m to the +x wall from x = 0.5
  EXPECT_GT(raster.probeMoments(1, {-1, 0, 0}).x, 1.4f);  // 1.5 m to the −x wall
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(ProbeVisibility, OffsetsOfTheWrongSizeNotFiniteOrAbsurdAreRefused) {
  VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("closed-box");
  RasterRenderer raster(context, s, 8, 8);
  ProbeVolume v = makeProbeVolume(ProbeGrid{{2, 2, 2}, {{-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}}});
  v.offsets.assign(5, 0.0f);
  EXPECT_THROW(raster.setProbes(v), std::invalid_argument);
  v.offsets.assign(24, 0.0f);
  v.offsets[7] = std::nanf("");
  EXPECT_THROW(raster.setProbes(v), std::invalid_argument);
  v.offsets[7] = 1e30f;  // finite, but a light-year off its cell
  EXPECT_THROW(raster.setProbes(v), std::invalid_argument);
  v.offsets[7] = 0.1f;
  EXPECT_NO_THROW(raster.setProbes(v));
  EXPECT_EQ(context.validationMessages(), 0u);
}

// `measure` of a raster client of scene `s` with visibility off, then on.
template <class Measure>
std::array<double, 2> offAndOn(VulkanContext& context, const scene::Scene& s, uint32_t width, uint32_t height,
                               Measure measure) {
  std::array<double, 2> out{};
  for (int on = 0; on < 2; ++on) {
    RasterOptions ro;
    ro.visibility = on != 0;
    RasterRenderer raster(context, s, width, height, ro);
    out[static_cast<size_t>(on)] = measure(raster);
  }
  return out;
}

// Mean luminance of an image.
double imageMean(const Image& img) {
  double sum = 0.0;
  size_t count = 0;
  for (uint32_t y = 0; y < img.height; ++y)
    for (uint32_t x = 0; x < img.width; ++x) {
      const float* px = &img.rgb[(static_cast<size_t>(y) * img.width + x) * 3];
      sum += 0.2126 * px[0] + 0.7152 * px[1] + 0.0722 * px[2];
      ++count;
    }
  return sum / static_cast<double>(count);
}

TEST(ProbeVisibility, ThinWallDarkSideFloorStaysDark) {
  // builtin:thin-wall: the light is in the +x room and the 0.2 m wall at x = 0 closes the −x room
  // off, so its floor gets no light at all (the traced probes there are black). Mirror-image
  // views of the floor by the wall from each room: without visibility the probes of the lit room
  // light the dark floor through the wall (the cells across it blend both sides); with it, the
  // dark floor is ≤ 1 % of the lit one.
  VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("thin-wall");
  UpdaterOptions uo;
  uo.samplesPerProbe = 64;
  ProbeUpdater updater(context, s, sceneGrid(s, {8, 4, 4}), uo);
  updater.update();
  updater.update();
  const ProbeVolume volume = updater.volume();
  // Straight down from 1 m onto the floor x in [-0.6, -0.1] (the wall's foot at the image's edge).
  CameraView dark, lit;
  dark.position = {-0.35f, 1.0f, 0.0f};
  dark.forward = {0.0f, -1.0f, 0.0f};
  dark.up = {1.0f, 0.0f, 0.0f};
  dark.yfov = 0.5f;
  lit = dark;
  lit.position.x = -dark.position.x;
  lit.up.x = -dark.up.x;
  const std::array<double, 2> ratio = offAndOn(context, s, 48, 32, [&](RasterRenderer& raster) {
    raster.setProbes(volume);
    const double darkFloor = imageMean(raster.render(raster.viewProjection(dark), dark.position));
    const double litFloor = imageMean(raster.render(raster.viewProjection(lit), lit.position));
    EXPECT_GT(litFloor, 0.0);
    return darkFloor / litFloor;
  });
  std::printf("thin-wall dark floor / lit floor: visibility off %.4f, on %.4f\n", ratio[0], ratio[1]);
  EXPECT_LE(ratio[1], 0.01);
  EXPECT_GT(ratio[0], 0.02);  // the leak visibility removes
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(ProbeVisibility, BoxFaceIsNotDarkenedByProbesInsideTheBox) {
  // A box of half-size 0.6 m floating in constant light L from every direction, probes 0.5 m
  // apart; the 27 probes inside it hold nothing but are active (as if classification missed
  // them). The face towards the camera at z = 0.6 sits between the inside layer z = 0.5
  // (trilinear weight 0.8) and the outside layer z = 1.0: without visibility it shows about 20 %
  // of its light; with visibility it matches a volume that is L everywhere within 5 % (what is
  // left comes from inside probes 0.1 m from the face seeing it at a grazing angle).
  VulkanContext context(test::validatedContext());
  scene::Scene s;
  scene::Material white;
  white.baseColor = glm::vec3(0.8f);
  s.materials.push_back(white);
  scene::addBox(s, {0.0f, 0.0f, 0.0f}, {0.6f, 0.6f, 0.6f}, 0.0f, 0);
  scene::finalizeScene(s);
  const ProbeGrid grid{{7, 7, 7}, {{-1.5f, -1.5f, -1.5f}, {1.5f, 1.5f, 1.5f}}};
  ProbeVolume full = makeProbeVolume(grid);
  for (uint32_t p = 0; p < grid.count(); ++p) full.probes[p * 27] = full.probes[p * 27 + 1] = full.probes[p * 27 + 2] = 3.5449077f;
  ProbeVolume hollow = full;
  int inside = 0;
  for (uint32_t p = 0; p < grid.count(); ++p) {
    float pos[3];
    grid.position(p, pos);
    if (std::abs(pos[0]) < 0.6f && std::abs(pos[1]) < 0.6f && std::abs(pos[2]) < 0.6f) {
      for (int c = 0; c < 27; ++c) hollow.probes[p * 27 + c] = 0.0f;
      ++inside;
    }
  }
  ASSERT_EQ(inside, 27);
  CameraView cam;
  cam.position = {0.0f, 0.0f, 3.0f};
  cam.forward = {0.0f, 0.0f, -1.0f};
  cam.yfov = 0.4f;  // the face fills the centre of the image
  // Mean of the central 50 % of the image: all of it the face at z = 0.6.
  const auto faceMean = [](const Image& img) {
    double sum = 0.0;
    size_t count = 0;
    for (uint32_t y = img.height / 4; y < img.height * 3 / 4; ++y)
      for (uint32_t x = img.width / 4; x < img.width * 3 / 4; ++x) {
        sum += img.rgb[(static_cast<size_t>(y) * img.width + x) * 3 + 1];
        ++count;
      }
    return sum / static_cast<double>(count);
  };
  const std::array<double, 2> ratio = offAndOn(context, s, 32, 32, [&](RasterRenderer& raster) {
    raster.setProbes(full);
    const double expected = faceMean(raster.render(raster.viewProjection(cam), cam.position));
    raster.setProbes(hollow);
    return faceMean(raster.render(raster.viewProjection(cam), cam.position)) / expected;
  });
  std::printf("box face with hollow probes / full: visibility off %.4f, on %.4f\n", ratio[0], ratio[1]);
  EXPECT_NEAR(ratio[1], 1.0, 0.05);
  EXPECT_LT(ratio[0], 0.5);  // the darkening visibility removes
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(ProbeVisibility, OuterFaceOfACeilingAboveEveryProbeGetsNoProbeLight) {
  // A ceiling quad at y = 1 above a grid that ends at y = 0.8, every probe holding constant light
  // L (as the probes inside the demo's room do). Seen from below, its face is lit by the probes in
  // front of it; seen from above (the light field's top row of eyes), every probe lies behind its
  // plane, so nothing any probe holds reaches it: the reference leaves it black. Without the rule
  // the backface floor's small weights were renormalised and lit it fully.
  VulkanContext context(test::validatedContext());
  scene::Scene s;
  scene::Material white;
  white.baseColor = glm::vec3(0.8f);
  s.materials.push_back(white);
  scene::addQuad(s, {-1.0f, 1.0f, -1.0f}, {1.0f, 1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}, {-1.0f, 1.0f, 1.0f}, 0);
  scene::finalizeScene(s);
  const ProbeGrid grid{{5, 5, 5}, {{-1.0f, -1.0f, -1.0f}, {1.0f, 0.8f, 1.0f}}};
  ProbeVolume volume = makeProbeVolume(grid);
  for (uint32_t p = 0; p < grid.count(); ++p) volume.probes[p * 27] = volume.probes[p * 27 + 1] = volume.probes[p * 27 + 2] = 3.5449077f;
  CameraView above;
  above.position = {0.0f, 3.0f, 0.0f};
  above.forward = {0.0f, -1.0f, 0.0f};
  above.up = {0.0f, 0.0f, -1.0f};
  above.yfov = 0.3f;  // the quad fills the image
  CameraView below = above;
  below.position.y = 0.0f;
  below.forward.y = 1.0f;
  below.yfov = 1.2f;
  RasterOptions ro;
  ro.visibility = true;
  RasterRenderer raster(context, s, 32, 32, ro);
  raster.setProbes(volume);
  const double outer = imageMean(raster.render(raster.viewProjection(above), above.position));
  const double inner = imageMean(raster.render(raster.viewProjection(below), below.position));
  std::printf("ceiling seen from above %.4f, from below %.4f\n", outer, inner);
  EXPECT_GT(inner, 0.5);  // L · albedo = 0.8 where fully lit
  EXPECT_LT(outer, 0.01 * inner);
  EXPECT_EQ(context.validationMessages(), 0u);
}

// Every texel (E[r], E[r²]) of every probe of a raster client's current volume.
std::vector<glm::vec2> allMoments(const RasterRenderer& raster, uint32_t probes) {
  std::vector<glm::vec2> out;
  const auto n = static_cast<int>(RasterRenderer::visibilityMapTexels());
  for (uint32_t p = 0; p < probes; ++p)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) out.push_back(raster.probeMoments(p, octTexelDirection(i, j, n)));
  return out;
}

TEST(ProbeVisibility, CullingToTheReachKeepsTheMomentsAndDrawsAFraction) {
  // builtin:hall (20 m × 20 m, ≈100k triangles) seen by 8 probes 2 m apart in its middle: reach
  // 1.5 × 3.46 m + 0.5 m = 5.7 m. Culled and unculled builds under the same reach give the same
  // moments, bit for bit (only triangles wholly beyond reach, or outside a face, are skipped), while
  // drawing a fraction of the triangles. Against no reach at all (the build before the limit), a
  // texel is the same or, where its lobe took in surfaces (or open directions) beyond reach, nearer:
  // no mean beyond the reach.
  VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("hall");
  const ProbeVolume v = makeProbeVolume(ProbeGrid{{2, 2, 2}, {{-1.0f, 1.5f, -1.0f}, {1.0f, 3.5f, 1.0f}}});
  std::vector<glm::vec2> moments[3];
  uint64_t triangles[3] = {};
  for (int k = 0; k < 3; ++k) {
    RasterOptions ro;
    ro.visibilityCulling = k == 0;
    ro.visibilityReach = k == 2 ? 0.0f : 1.0f;
    RasterRenderer raster(context, s, 8, 8, ro);
    raster.setProbes(v);
    ASSERT_TRUE(raster.visibilityActive());
    moments[k] = allMoments(raster, v.count());
    triangles[k] = raster.timings().visibilityTriangles;
  }
  std::printf("hall, 8 probes: %llu triangles drawn culled, %llu unculled\n",
              static_cast<unsigned long long>(triangles[0]), static_cast<unsigned long long>(triangles[1]));
  // Without a reach nothing is simplified or culled: every face draws every triangle. Under a
  // reach the still geometry is simplified (a proxy within kVisibilityProxyError of the reach), and culling draws
  // a fraction of that.
  EXPECT_EQ(triangles[2], 8ull * 6 * s.triangleCount());
  EXPECT_LT(triangles[1], triangles[2]);
  EXPECT_EQ(triangles[1] % 48, 0u);  // the same proxy on every face
  EXPECT_LT(triangles[0] * 5, triangles[1]);
  const float reach = 1.5f * std::sqrt(12.0f) + 0.25f * 2.0f;
  // The reach-limited builds draw the proxy, the unlimited one the exact geometry: a mean distance
  // agrees within the proxy's error (a fraction of the reach) or, where the reach cut it, is
  // nearer. A few lobes mix a near edge with what lies behind it, and an edge the proxy moved
  // moves their mean by more than the error, either way: at most 4 % of the texels.
  const float proxyError = kVisibilityProxyError * reach;
  size_t same = 0, farther = 0;
  for (size_t t = 0; t < moments[0].size(); ++t) {
    EXPECT_EQ(moments[0][t], moments[1][t]) << "texel " << t;
    EXPECT_LE(moments[0][t].x, reach * 1.0001f) << "texel " << t;
    if (std::abs(moments[0][t].x - moments[2][t].x) <= proxyError)
      ++same;
    else if (!(moments[0][t].x < moments[2][t].x && moments[0][t].y < moments[2][t].y))
      ++farther;
  }
  std::printf("hall: %zu texels farther than without a reach by more than the proxy's error\n", farther);
  EXPECT_LE(farther, moments[0].size() / 25);
  std::printf("hall: %zu of %zu texels as without a reach (within the proxy's error)\n", same, moments[0].size());
  EXPECT_GT(same, moments[0].size() / 4);
  EXPECT_LT(same, moments[0].size());  // some directions do reach past 5.7 m
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(ProbeVisibility, CutOutQuadBlocksWhereKeptAndNotWhereCutAway) {
  // builtin:closed-box split at x = 0.5 by two Mask quads: the z < 0 half kept (alpha 1), the z > 0
  // half cut away (alpha 0). From the probe at the origin, (1, 0, −0.5) meets the kept half at
  // 0.56 m; (1, 0, 0.5) passes the cut-away half to the wall at 1.12 m.
  VulkanContext context(test::validatedContext());
  scene::Scene s = test::builtinScene("closed-box");
  scene::Material kept;
  kept.alphaMode = scene::AlphaMode::Mask;
  scene::Material cut = kept;
  cut.alpha = 0.0f;
  s.materials.push_back(kept);
  s.materials.push_back(cut);
  const auto keptId = static_cast<uint32_t>(s.materials.size() - 2), cutId = keptId + 1;
  scene::addQuad(s, {0.5f, -1, -1}, {0.5f, -1, 0}, {0.5f, 1, 0}, {0.5f, 1, -1}, keptId);
  scene::addQuad(s, {0.5f, -1, 0}, {0.5f, -1, 1}, {0.5f, 1, 1}, {0.5f, 1, 0}, cutId);
  scene::finalizeScene(s);
  RasterRenderer raster(context, s, 8, 8);
  ProbeVolume v = makeProbeVolume(ProbeGrid{{3, 1, 1}, {{-1.0f, -0.5f, -0.5f}, {1.0f, 0.5f, 0.5f}}});
  raster.setProbes(v);
  ASSERT_TRUE(raster.visibilityActive());
  const float blocked = raster.probeMoments(1, {1.0f, 0.0f, -0.5f}).x;
  const float open = raster.probeMoments(1, {1.0f, 0.0f, 0.5f}).x;
  std::printf("cut-out quad: %.3f m where kept, %.3f m where cut away\n", blocked, open);
  EXPECT_NEAR(blocked, 0.559f, 0.06f);
  EXPECT_NEAR(open, 1.118f, 0.1f);
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(ProbeVisibility, ReachThatIsNegativeNotFiniteOrAbsurdIsRefused) {
  VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("closed-box");
  for (const float reach : {-1.0f, std::nanf(""), INFINITY, 1e30f}) {
    RasterOptions ro;
    ro.visibilityReach = reach;
    EXPECT_THROW(RasterRenderer(context, s, 8, 8, ro), std::invalid_argument) << reach;
  }
  EXPECT_EQ(context.validationMessages(), 0u);
}

}  // namespace
}  // namespace probecast::renderer
