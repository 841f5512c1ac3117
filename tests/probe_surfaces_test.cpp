// Which probes light a surface (UpdaterOptions::surfaceProbesOnly, renderer/src/probe_surfaces.h):
// the triangle-box test on cases worked by hand, the probes a wall or a small triangle reaches on a
// grid of unit spacing, and, on the real updater and raster, that the probes left idle light no
// pixel at all.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "probe_surfaces.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/scene/scene.h"
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

TEST(ProbeSurfaces, TriangleMeetsBoxOnHandWorkedCases) {
  const glm::vec3 centre(0.0f), half(1.0f);  // the box [-1, 1]³
  // Inside, and wholly beyond the x = 1 face.
  EXPECT_TRUE(triangleMeetsBox({0, 0, 0}, {0.5f, 0, 0}, {0, 0.5f, 0}, centre, half));
  EXPECT_FALSE(triangleMeetsBox({1.5f, -3, -3}, {1.5f, 3, -3}, {1.5f, 0, 3}, centre, half));
  // Its bounding box [0, s]³ overlaps the box's; the plane x + y + z = s passes the corner (1, 1, 1),
  // where x + y + z = 3, only when s < 3: the plane is the separating axis.
  EXPECT_FALSE(triangleMeetsBox({3.2f, 0, 0}, {0, 3.2f, 0}, {0, 0, 3.2f}, centre, half));
  EXPECT_TRUE(triangleMeetsBox({2.9f, 0, 0}, {0, 2.9f, 0}, {0, 0, 2.9f}, centre, half));
  // A large triangle around the box in the plane z = 0 cuts it; one in z = 1.01 does not.
  EXPECT_TRUE(triangleMeetsBox({-10, -10, 0}, {10, -10, 0}, {0, 10, 0}, centre, half));
  EXPECT_FALSE(triangleMeetsBox({-10, -10, 1.01f}, {10, -10, 1.01f}, {0, 10, 1.01f}, centre, half));
  // A segment (a triangle of no area) on the line x + y = 2.5 in z = 0: its bounding box overlaps
  // the box's and it has no plane, so only its edge crossed with z separates it (the box reaches
  // x + y = 2); on x + y = 1.5 it cuts the box.
  EXPECT_FALSE(triangleMeetsBox({0, 2.5f, 0}, {2.5f, 0, 0}, {2.5f, 0, 0}, centre, half));
  EXPECT_TRUE(triangleMeetsBox({0, 1.5f, 0}, {1.5f, 0, 0}, {1.5f, 0, 0}, centre, half));
  // Degenerate: a point (inside, outside) and a segment through the box.
  EXPECT_TRUE(triangleMeetsBox({0.2f, 0.2f, 0.2f}, {0.2f, 0.2f, 0.2f}, {0.2f, 0.2f, 0.2f}, centre, half));
  EXPECT_FALSE(triangleMeetsBox({1.2f, 0.2f, 0.2f}, {1.2f, 0.2f, 0.2f}, {1.2f, 0.2f, 0.2f}, centre, half));
  EXPECT_TRUE(triangleMeetsBox({-5, 0.5f, 0}, {5, 0.5f, 0}, {5, 0.5f, 0}, centre, half));
}

// A 4×4×4 grid of probes at 0, 1, 2, 3 on each axis.
ProbeGrid unitGrid() { return ProbeGrid{{4, 4, 4}, {{0, 0, 0}, {3, 3, 3}}}; }

std::vector<uint32_t> nearList(const scene::Scene& s) {
  const std::vector<uint8_t> near = probesNearSurfaces(s, unitGrid());
  std::vector<uint32_t> out;
  for (uint32_t p = 0; p < near.size(); ++p)
    if (near[p]) out.push_back(p);
  return out;
}

TEST(ProbeSurfaces, ATriangleReachesTheProbesOfTheCellsItCrosses) {
  const auto layerX = [](const std::vector<uint32_t>& list, uint32_t x) {
    return std::count_if(list.begin(), list.end(), [&](uint32_t p) { return p % 4 == x; });
  };
  {  // A wall x = 1.5 across the whole grid: the probes at x = 1 and x = 2, every y and z.
    scene::Scene s;
    scene::addQuad(s, {1.5f, -1, -1}, {1.5f, 4, -1}, {1.5f, 4, 4}, {1.5f, -1, 4}, 0);
    const std::vector<uint32_t> near = nearList(s);
    EXPECT_EQ(near.size(), 32u);
    EXPECT_EQ(layerX(near, 1), 16);
    EXPECT_EQ(layerX(near, 2), 16);
  }
  {  // A wall on the plane x = 1: the probes there; those at x = 0 and 2 weigh 0 on it.
    scene::Scene s;
    scene::addQuad(s, {1, -1, -1}, {1, 4, -1}, {1, 4, 4}, {1, -1, 4}, 0);
    const std::vector<uint32_t> near = nearList(s);
    EXPECT_EQ(near.size(), 16u);
    EXPECT_EQ(layerX(near, 1), 16);
  }
  {  // A small triangle inside the cell [0, 1]³: its eight corners.
    scene::Scene s;
    s.positions = {{0.4f, 0.4f, 0.5f}, {0.6f, 0.4f, 0.5f}, {0.5f, 0.6f, 0.5f}};
    s.indices = {0, 1, 2};
    const std::vector<uint32_t> near = nearList(s);
    ASSERT_EQ(near.size(), 8u);
    for (uint32_t p : near) EXPECT_TRUE(p % 4 <= 1 && (p / 4) % 4 <= 1 && p / 16 <= 1) << p;
  }
  {  // Beyond the grid (x = 5, y and z in the cell [1, 2]): the face probes it clamps to.
    scene::Scene s;
    s.positions = {{5, 1.2f, 1.2f}, {5, 1.8f, 1.2f}, {5, 1.5f, 1.8f}};
    s.indices = {0, 1, 2};
    const std::vector<uint32_t> near = nearList(s);
    ASSERT_EQ(near.size(), 4u);
    for (uint32_t p : near) EXPECT_TRUE(p % 4 == 3 && (p / 4) % 4 >= 1 && (p / 4) % 4 <= 2 && p / 16 >= 1 && p / 16 <= 2) << p;
  }
  {  // Absurd but finite: a floor y = 1.5 reaching ±10³⁰ m: the probes at y = 1 and 2.
    scene::Scene s;
    scene::addQuad(s, {-1e30f, 1.5f, -1e30f}, {-1e30f, 1.5f, 1e30f}, {1e30f, 1.5f, 1e30f}, {1e30f, 1.5f, -1e30f}, 0);
    const std::vector<uint32_t> near = nearList(s);
    EXPECT_EQ(near.size(), 32u);
    for (uint32_t p : near) EXPECT_TRUE((p / 4) % 4 == 1 || (p / 4) % 4 == 2) << p;
  }
  {  // Non-finite positions are skipped, not spread over the grid.
    scene::Scene s;
    s.positions = {{NAN, 0, 0}, {1, 1, 1}, {2, 2, 2}};
    s.indices = {0, 1, 2};
    EXPECT_TRUE(nearList(s).empty());
  }
}

class SurfaceProbes : public ::testing::Test {
 protected:
  void TearDown() override { EXPECT_EQ(context_.validationMessages(), 0u) << "Vulkan validation messages"; }
  VulkanContext context_{test::validatedContext()};
};

// The idle probes of the Cornell box's 8³ grid (the room's middle) get no rays, and no pixel of the
// scene camera's view changes when they are switched on with an absurd light.
TEST_F(SurfaceProbes, IdleProbesGetNoRaysAndLightNoPixel) {
  const scene::Scene s = test::builtinScene("cornell");
  const ProbeGrid g = sceneGrid(s, {8, 8, 8});
  UpdaterOptions o;
  o.samplesPerProbe = 32;
  ProbeUpdater idle(context_, s, g, o);
  o.surfaceProbesOnly = false;
  ProbeUpdater every(context_, s, g, o);
  const ClassifyStats& st = idle.classifyStats();
  EXPECT_GT(st.idle, 100u);  // 6³ probes in the room's middle, less those near the two boxes
  EXPECT_EQ(every.classifyStats().idle, 0u);
  const UpdateStats us = idle.update();
  EXPECT_EQ(us.paths, uint64_t{g.count() - st.inactive} * o.samplesPerProbe);
  EXPECT_LT(us.paths, every.update().paths);

  ProbeVolume lit = idle.volume();
  uint32_t switched = 0;
  for (uint32_t p = 0; p < g.count(); ++p) {
    if (lit.active[p] || !every.volume().active[p]) continue;
    lit.active[p] = 1;
    for (int c = 0; c < 3; ++c) lit.probes[static_cast<size_t>(p) * 27 + c] = 1000.0f;
    ++switched;
  }
  EXPECT_EQ(switched, st.idle);
  // Shading at pixel centres: with MSAA an edge pixel is shaded at its centre even where that lies
  // just past its triangle, so a few edge pixels may reach an idle probe (checked below).
  RasterOptions centres;
  centres.msaaSamples = 1;
  RasterRenderer raster(context_, s, 96, 64, centres);
  const CameraView cam = CameraView::fromScene(s);
  raster.setProbes(idle.volume());
  const Image off = raster.render(raster.viewProjection(cam), cam.position);
  raster.setProbes(lit);
  const Image on = raster.render(raster.viewProjection(cam), cam.position);
  EXPECT_EQ(on.rgb, off.rgb);
  {
    RasterRenderer msaa(context_, s, 96, 64);  // the default: 4× MSAA
    msaa.setProbes(idle.volume());
    const Image a = msaa.render(msaa.viewProjection(cam), cam.position);
    msaa.setProbes(lit);
    const Image b = msaa.render(msaa.viewProjection(cam), cam.position);
    size_t differing = 0;
    for (size_t p = 0; p < a.rgb.size() / 3; ++p)
      differing += a.rgb[p * 3] != b.rgb[p * 3] || a.rgb[p * 3 + 1] != b.rgb[p * 3 + 1] || a.rgb[p * 3 + 2] != b.rgb[p * 3 + 2];
    EXPECT_LT(differing, a.rgb.size() / 3 / 50) << "more than edge pixels reach idle probes";
  }
  // The test can fail: the same light on a probe that lights a surface shows.
  ProbeVolume wrong = idle.volume();
  for (uint32_t p = 0; p < g.count(); ++p)
    if (wrong.active[p]) {
      for (int c = 0; c < 3; ++c) wrong.probes[static_cast<size_t>(p) * 27 + c] = 1000.0f;
      break;
    }
  raster.setProbes(wrong);
  EXPECT_NE(raster.render(raster.viewProjection(cam), cam.position).rgb, off.rgb);
}

}  // namespace
}  // namespace probecast::renderer
