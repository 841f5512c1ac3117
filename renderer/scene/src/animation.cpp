// Evaluates glTF animation (animation.h): samplers, the node tree, skins and morph targets.
#include "probecast/scene/animation.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "probecast/scene/scene.h"

namespace probecast::scene {
namespace {

glm::quat quatOf(const float* v) { return glm::quat(v[3], v[0], v[1], v[2]); }

void storeQuat(const glm::quat& q, float* out) {
  const float len = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  const glm::quat n = len > 0.0f && std::isfinite(len) ? q / len : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  out[0] = n.x;
  out[1] = n.y;
  out[2] = n.z;
  out[3] = n.w;
}

// Spherical interpolation from a to b by s along the shorter arc; nearly equal rotations blend
// linearly (the sine ratio loses precision there).
glm::quat slerpShortest(glm::quat a, glm::quat b, float s) {
  float d = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
  if (d < 0.0f) {
    b = -b;
    d = -d;
  }
  if (d > 0.9995f) return a * (1.0f - s) + b * s;
  const float angle = std::acos(std::min(d, 1.0f));
  const float sinAngle = std::sin(angle);
  const float wa = std::sin((1.0f - s) * angle) / sinAngle, wb = std::sin(s * angle) / sinAngle;
  return a * wa + b * wb;
}

glm::mat4 localMatrix(const RigNode& n) {
  if (n.hasMatrix) return n.matrix;
  return glm::translate(glm::mat4(1.0f), n.translation) * glm::mat4_cast(n.rotation) *
         glm::scale(glm::mat4(1.0f), n.scale);
}

// The nodes at `seconds`: the rest values with every channel's sample in place.
std::vector<RigNode> animatedNodes(const Rig& rig, double seconds) {
  std::vector<RigNode> nodes = rig.nodes;
  const float t = static_cast<float>(loopTime(rig, seconds));
  float value[4];
  std::vector<float> weights;
  for (const AnimationClip& clip : rig.clips) {
    for (const AnimationChannel& c : clip.channels) {
      const AnimationSampler& s = clip.samplers[c.sampler];
      RigNode& n = nodes[c.node];
      switch (c.path) {
        case AnimatedPath::Translation:
          sampleAnimation(s, t, false, value);
          n.translation = {value[0], value[1], value[2]};
          break;
        case AnimatedPath::Rotation:
          sampleAnimation(s, t, true, value);
          n.rotation = quatOf(value);
          break;
        case AnimatedPath::Scale:
          sampleAnimation(s, t, false, value);
          n.scale = {value[0], value[1], value[2]};
          break;
        case AnimatedPath::Weights:
          weights.assign(s.width, 0.0f);
          sampleAnimation(s, t, false, weights.data());
          n.weights = weights;
          break;
      }
    }
  }
  return nodes;
}

std::vector<glm::mat4> worldMatrices(const Rig& rig, const std::vector<RigNode>& nodes) {
  std::vector<glm::mat4> world(nodes.size(), glm::mat4(1.0f));
  for (uint32_t i : rig.order) {
    const glm::mat4 local = localMatrix(nodes[i]);
    world[i] = nodes[i].parent >= 0 ? world[static_cast<size_t>(nodes[i].parent)] * local : local;
  }
  return world;
}

glm::vec3 unitOr(const glm::vec3& v, const glm::vec3& fallback) {
  const float len = glm::length(v);
  return len > 0.0f && std::isfinite(len) ? v / len : fallback;
}

void posePrimitive(const Rig& rig, const RigPrimitive& p, const std::vector<RigNode>& nodes,
                   const std::vector<glm::mat4>& world, Scene& scene) {
  const std::vector<float>& weights = nodes[p.node].weights;
  std::vector<glm::mat4> joints;
  if (p.skin >= 0) {
    const RigSkin& skin = rig.skins[static_cast<size_t>(p.skin)];
    joints.resize(skin.joints.size());
    for (size_t j = 0; j < joints.size(); ++j) joints[j] = world[skin.joints[j]] * skin.inverseBind[j];
  }
  const glm::mat4& nodeWorld = world[p.node];
  const glm::mat3 nodeNormal = glm::transpose(glm::inverse(glm::mat3(nodeWorld)));
  for (uint32_t v = 0; v < p.vertexCount; ++v) {
    glm::vec3 pos = p.positions[v], nrm = p.normals[v];
    for (size_t k = 0; k < p.targetPositions.size() && k < weights.size(); ++k) {
      if (weights[k] == 0.0f) continue;
      if (!p.targetPositions[k].empty()) pos += weights[k] * p.targetPositions[k][v];
      if (k < p.targetNormals.size() && !p.targetNormals[k].empty()) nrm += weights[k] * p.targetNormals[k][v];
    }
    glm::mat4 m = nodeWorld;
    glm::mat3 nm = nodeNormal;
    if (p.skin >= 0) {
      m = glm::mat4(0.0f);
      for (int set = 0; set < 2; ++set) {
        if (p.joints[set].empty()) continue;
        for (int c = 0; c < 4; ++c) {
          const float w = p.weights[set][v][c];
          if (w != 0.0f) m += w * joints[p.joints[set][v][c]];
        }
      }
      nm = glm::transpose(glm::inverse(glm::mat3(m)));
    }
    // A pose that overflows (huge scales, tangents) keeps the vertex where it was.
    const glm::vec3 moved = glm::vec3(m * glm::vec4(pos, 1.0f));
    if (std::isfinite(moved.x + moved.y + moved.z)) scene.positions[p.firstVertex + v] = moved;
    if (p.normalsGiven) scene.normals[p.firstVertex + v] = unitOr(nm * nrm, glm::vec3(0.0f));
  }
  if (p.normalsGiven) return;
  // Flat normals accumulated per vertex, as the loader makes them for a primitive without NORMAL.
  std::vector<glm::vec3> acc(p.vertexCount, glm::vec3(0.0f));
  const glm::vec3* wp = &scene.positions[p.firstVertex];
  for (size_t t = 0; t + 2 < p.triangles.size(); t += 3) {
    const uint32_t a = p.triangles[t], b = p.triangles[t + 1], c = p.triangles[t + 2];
    const glm::vec3 fn = glm::cross(wp[b] - wp[a], wp[c] - wp[a]) * (p.flip ? -1.0f : 1.0f);
    acc[a] += fn;
    acc[b] += fn;
    acc[c] += fn;
  }
  for (uint32_t v = 0; v < p.vertexCount; ++v)
    scene.normals[p.firstVertex + v] = unitOr(acc[v], glm::vec3(0.0f, 1.0f, 0.0f));
}

}  // namespace

void sampleAnimation(const AnimationSampler& s, float t, bool rotation, float* out) {
  const uint32_t w = s.width;
  const size_t keys = s.input.size();
  const bool cubic = s.interpolation == Interpolation::CubicSpline;
  const size_t stride = cubic ? 3 * w : w;
  const auto value = [&](size_t k) { return s.output.data() + k * stride + (cubic ? w : 0); };
  const auto finish = [&](const float* v) {
    if (rotation) storeQuat(quatOf(v), out);
    else std::copy(v, v + w, out);
  };
  if (keys == 0 || w == 0) return;
  if (keys == 1 || !(t > s.input.front())) return finish(value(0));
  if (t >= s.input.back()) return finish(value(keys - 1));
  // The key interval [k, k + 1) that holds t.
  const size_t k = static_cast<size_t>(std::upper_bound(s.input.begin(), s.input.end(), t) - s.input.begin()) - 1;
  const float t0 = s.input[k], t1 = s.input[k + 1], dt = t1 - t0;
  const float u = dt > 0.0f ? (t - t0) / dt : 0.0f;
  if (s.interpolation == Interpolation::Step) return finish(value(k));
  if (!cubic) {
    if (rotation) return storeQuat(slerpShortest(quatOf(value(k)), quatOf(value(k + 1)), u), out);
    const float *a = value(k), *b = value(k + 1);
    for (uint32_t c = 0; c < w; ++c) out[c] = a[c] + u * (b[c] - a[c]);
    return;
  }
  // Cubic Hermite: the value and out-tangent of key k, the value and in-tangent of key k + 1,
  // tangents scaled by the interval's length.
  const float u2 = u * u, u3 = u2 * u;
  const float h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
  const float* v0 = value(k);
  const float* b0 = s.output.data() + k * stride + 2 * w;
  const float* v1 = value(k + 1);
  const float* a1 = s.output.data() + (k + 1) * stride;
  float r[64];
  float* dst = rotation ? r : out;
  for (uint32_t c = 0; c < w; ++c) dst[c] = h00 * v0[c] + h10 * dt * b0[c] + h01 * v1[c] + h11 * dt * a1[c];
  if (rotation) storeQuat(quatOf(r), out);
}

bool sceneAnimates(const Scene& scene) { return scene.rig && scene.rig->duration > 0.0f; }

double animationDuration(const Scene& scene) { return scene.rig ? scene.rig->duration : 0.0; }

double loopTime(const Rig& rig, double seconds) {
  if (!(rig.duration > 0.0f) || !std::isfinite(seconds)) return 0.0;
  const double d = rig.duration;
  const double t = seconds - std::floor(seconds / d) * d;
  return t >= d || t < 0.0 ? 0.0 : t;
}

std::vector<glm::mat4> nodeWorldMatrices(const Rig& rig, double seconds) {
  return worldMatrices(rig, animatedNodes(rig, seconds));
}

void poseScene(Scene& scene, double seconds) {
  if (!scene.rig) return;
  const Rig& rig = *scene.rig;
  const std::vector<RigNode> nodes = animatedNodes(rig, seconds);
  const std::vector<glm::mat4> world = worldMatrices(rig, nodes);
  for (const RigPrimitive& p : rig.primitives) posePrimitive(rig, p, nodes, world, scene);
  for (const Rig::Attached& a : rig.lights) {
    Light& l = scene.lights[a.index];
    const glm::vec3 at(world[a.node][3]);
    if (!std::isfinite(at.x + at.y + at.z)) continue;
    l.position = at;
    l.direction = unitOr(glm::vec3(world[a.node] * glm::vec4(0, 0, -1, 0)), glm::vec3(0, -1, 0));
  }
  for (const Rig::Attached& a : rig.cameras) {
    Camera& c = scene.cameras[a.index];
    const glm::vec3 at(world[a.node][3]);
    if (!std::isfinite(at.x + at.y + at.z)) continue;
    c.position = at;
    c.forward = unitOr(glm::vec3(world[a.node] * glm::vec4(0, 0, -1, 0)), glm::vec3(0, 0, -1));
    c.up = unitOr(glm::vec3(world[a.node] * glm::vec4(0, 1, 0, 0)), glm::vec3(0, 1, 0));
  }
}

}  // namespace probecast::scene
