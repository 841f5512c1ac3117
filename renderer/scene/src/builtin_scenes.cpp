// Scenes generated in code, so the binary runs with no files.
#include <cmath>

#include <glm/gtc/constants.hpp>

#include "probecast/scene/scene.h"

namespace probecast::scene {
namespace {

uint32_t addMaterial(Scene& s, const std::string& name, glm::vec3 color, glm::vec3 emission = glm::vec3(0.0f)) {
  Material m;
  m.name = name;
  m.baseColor = color;
  m.emission = emission;
  s.materials.push_back(m);
  return static_cast<uint32_t>(s.materials.size() - 1);
}

// Cornell box proportions: interior x[-1, 1], y[0, 2], z[-1, 1], open towards +Z.
void makeCornell(float t, Scene& s) {
  const uint32_t white = addMaterial(s, "white", glm::vec3(0.73f));
  const uint32_t red = addMaterial(s, "red", glm::vec3(0.63f, 0.065f, 0.05f));
  const uint32_t green = addMaterial(s, "green", glm::vec3(0.14f, 0.45f, 0.091f));
  const uint32_t panel = addMaterial(s, "ceiling-panel", glm::vec3(0.78f), glm::vec3(8.0f, 6.5f, 4.5f));
  const float y0 = 0.0f, y1 = 2.0f, x0 = -1.0f, x1 = 1.0f, z0 = -1.0f, z1 = 1.0f;
  addQuad(s, {x0, y0, z1}, {x1, y0, z1}, {x1, y0, z0}, {x0, y0, z0}, white);  // floor, normal +Y
  addQuad(s, {x0, y1, z0}, {x1, y1, z0}, {x1, y1, z1}, {x0, y1, z1}, white);  // ceiling, normal −Y
  addQuad(s, {x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0}, white);  // back, normal +Z
  addQuad(s, {x0, y0, z1}, {x0, y0, z0}, {x0, y1, z0}, {x0, y1, z1}, red);    // left, normal +X
  addQuad(s, {x1, y0, z0}, {x1, y0, z1}, {x1, y1, z1}, {x1, y1, z0}, green);  // right, normal −X
  const float p = 0.25f, py = y1 - 0.002f;
  addQuad(s, {-p, py, -p}, {p, py, -p}, {p, py, p}, {-p, py, p}, panel);      // emissive panel, normal −Y
  addBox(s, {0.33f, 0.3f, 0.35f}, {0.3f, 0.3f, 0.3f}, -0.29f, white);         // short box
  addBox(s, {-0.35f, 0.6f, -0.3f}, {0.3f, 0.6f, 0.3f}, 0.29f, white);         // tall box
  // A warm point light circling under the ceiling: t moves it once around.
  Light light;
  light.type = LightType::Point;
  const float a = glm::two_pi<float>() * t;
  light.position = {0.6f * std::cos(a), 1.7f, 0.6f * std::sin(a)};
  light.color = {1.0f, 0.9f, 0.75f};
  light.intensity = 3.0f;
  s.lights.push_back(light);
  Camera cam;
  cam.name = "front";
  cam.position = {0.0f, 1.0f, 3.9f};
  cam.forward = {0.0f, 0.0f, -1.0f};
  cam.yfov = 0.6911f;
  s.cameras.push_back(cam);
}

// A closed box x, y, z in [-1, 1] lit by a point light; probes inside are active, probes inside
// its solid walls are not (walls have thickness via a second, outer box).
void makeClosedBox(float t, Scene& s) {
  const uint32_t white = addMaterial(s, "white", glm::vec3(0.7f));
  const float a = -1.0f, b = 1.0f;
  addQuad(s, {a, a, b}, {b, a, b}, {b, a, a}, {a, a, a}, white);  // floor +Y
  addQuad(s, {a, b, a}, {b, b, a}, {b, b, b}, {a, b, b}, white);  // ceiling −Y
  addQuad(s, {a, a, a}, {b, a, a}, {b, b, a}, {a, b, a}, white);  // back +Z
  addQuad(s, {b, a, b}, {a, a, b}, {a, b, b}, {b, b, b}, white);  // front −Z
  addQuad(s, {a, a, b}, {a, a, a}, {a, b, a}, {a, b, b}, white);  // left +X
  addQuad(s, {b, a, a}, {b, a, b}, {b, b, b}, {b, b, a}, white);  // right −X
  addBox(s, {0.0f, 0.0f, 0.0f}, {1.2f, 1.2f, 1.2f}, 0.0f, white);  // outer shell, faces outward
  Light light;
  light.position = {0.5f * std::cos(glm::two_pi<float>() * t), 0.5f, 0.0f};
  light.intensity = 2.0f;
  s.lights.push_back(light);
}

// Two rooms x in [-2, 2], y in [0, 2], z in [-1, 1], split at x = 0 by a solid wall 0.2 m thick;
// a point light in the +x room. Probes inside the wall must not leak darkness into the lit room
// (nor light into the dark one). The camera looks at the wall from the lit room.
void makeThinWall(float t, Scene& s) {
  const uint32_t white = addMaterial(s, "white", glm::vec3(0.7f));
  const uint32_t tint = addMaterial(s, "tint", glm::vec3(0.7f, 0.5f, 0.35f));
  const float x0 = -2.0f, x1 = 2.0f, y0 = 0.0f, y1 = 2.0f, z0 = -1.0f, z1 = 1.0f;
  addQuad(s, {x0, y0, z1}, {x1, y0, z1}, {x1, y0, z0}, {x0, y0, z0}, white);  // floor +Y
  addQuad(s, {x0, y1, z0}, {x1, y1, z0}, {x1, y1, z1}, {x0, y1, z1}, white);  // ceiling −Y
  addQuad(s, {x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0}, white);  // back +Z
  addQuad(s, {x1, y0, z1}, {x0, y0, z1}, {x0, y1, z1}, {x1, y1, z1}, white);  // front −Z
  addQuad(s, {x0, y0, z1}, {x0, y0, z0}, {x0, y1, z0}, {x0, y1, z1}, white);  // left +X
  addQuad(s, {x1, y0, z0}, {x1, y0, z1}, {x1, y1, z1}, {x1, y1, z0}, tint);   // right −X
  addBox(s, {0.0f, 1.0f, 0.0f}, {0.1f, 1.0f, 1.0f}, 0.0f, white);             // the wall, faces outward
  Light light;
  light.position = {1.2f + 0.3f * std::cos(glm::two_pi<float>() * t), 1.5f, 0.3f * std::sin(glm::two_pi<float>() * t)};
  light.intensity = 3.0f;
  s.lights.push_back(light);
  Camera cam;
  cam.name = "lit-room";
  cam.position = {1.95f, 1.0f, 0.0f};
  cam.forward = {-1.0f, 0.0f, 0.0f};
  cam.yfov = 1.2f;
  s.cameras.push_back(cam);
}

// A closed 20 m × 6 m × 20 m hall: a finely tessellated floor and 4,600 blocks (≈100k triangles in
// all), four point lights under the ceiling. For performance figures on a realistic triangle count.
void makeHall(float t, Scene& s) {
  const uint32_t floorMat = addMaterial(s, "floor", glm::vec3(0.6f, 0.58f, 0.55f));
  const uint32_t wallMat = addMaterial(s, "wall", glm::vec3(0.75f));
  const uint32_t blockMat = addMaterial(s, "block", glm::vec3(0.5f, 0.55f, 0.7f));
  const uint32_t warmMat = addMaterial(s, "warm-block", glm::vec3(0.8f, 0.45f, 0.3f));
  const float h = 10.0f, top = 6.0f;
  const int tiles = 150;  // 150 × 150 floor quads = 45,000 triangles
  for (int i = 0; i < tiles; ++i)
    for (int k = 0; k < tiles; ++k) {
      const float x0 = -h + 2 * h * static_cast<float>(i) / tiles, x1 = -h + 2 * h * static_cast<float>(i + 1) / tiles;
      const float z0 = -h + 2 * h * static_cast<float>(k) / tiles, z1 = -h + 2 * h * static_cast<float>(k + 1) / tiles;
      addQuad(s, {x0, 0, z1}, {x1, 0, z1}, {x1, 0, z0}, {x0, 0, z0}, floorMat);
    }
  addQuad(s, {-h, top, -h}, {h, top, -h}, {h, top, h}, {-h, top, h}, wallMat);
  addQuad(s, {-h, 0, -h}, {h, 0, -h}, {h, top, -h}, {-h, top, -h}, wallMat);
  addQuad(s, {h, 0, h}, {-h, 0, h}, {-h, top, h}, {h, top, h}, wallMat);
  addQuad(s, {-h, 0, h}, {-h, 0, -h}, {-h, top, -h}, {-h, top, h}, wallMat);
  addQuad(s, {h, 0, -h}, {h, 0, h}, {h, top, h}, {h, top, -h}, wallMat);
  uint32_t state = 12345u;
  auto next = [&]() {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) / 16777216.0f;
  };
  for (int b = 0; b < 4600; ++b) {
    const glm::vec3 size(0.05f + 0.15f * next(), 0.1f + 0.9f * next(), 0.05f + 0.15f * next());
    const glm::vec3 c(-h + 0.5f + (2 * h - 1) * next(), size.y, -h + 0.5f + (2 * h - 1) * next());
    addBox(s, c, size, 6.2831853f * next(), b % 7 == 0 ? warmMat : blockMat);
  }
  for (int k = 0; k < 4; ++k) {
    Light l;
    const float a = glm::two_pi<float>() * (t + 0.25f * static_cast<float>(k));
    l.position = {5.0f * std::cos(a), 5.0f, 5.0f * std::sin(a)};
    l.intensity = 40.0f;
    s.lights.push_back(l);
  }
}

}  // namespace

std::vector<std::string> builtinSceneNames() { return {"cornell", "closed-box", "thin-wall", "hall"}; }

bool makeBuiltinScene(const std::string& name, float t, Scene& scene, std::string& error) {
  scene = Scene{};
  scene.name = "builtin:" + name;
  if (name == "cornell") makeCornell(t, scene);
  else if (name == "closed-box") makeClosedBox(t, scene);
  else if (name == "thin-wall") makeThinWall(t, scene);
  else if (name == "hall") makeHall(t, scene);
  else {
    error = "unknown built-in scene '" + name + "' (have: cornell, closed-box, thin-wall, hall)";
    return false;
  }
  finalizeScene(scene);
  return true;
}

bool loadScene(const std::string& spec, double seconds, Scene& scene, std::string& error,
               const PackagedFiles* packaged) {
  const std::string prefix = "builtin:";
  if (spec.rfind(prefix, 0) == 0) {
    double t = std::isfinite(seconds) ? seconds - std::floor(seconds) : 0.0;
    if (t >= 1.0) t = 0.0;
    return makeBuiltinScene(spec.substr(prefix.size()), static_cast<float>(t), scene, error);
  }
  return loadGltf(spec, scene, error, seconds, packaged);
}

}  // namespace probecast::scene
