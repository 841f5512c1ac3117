// glTF animation in probecast's own types: the node tree, animation clips (translation, rotation,
// scale and morph-weight channels with LINEAR, STEP and CUBICSPLINE samplers), skins and morph
// targets of the primitives that move. loadGltf fills a Scene's rig; poseScene moves the scene's
// vertices, lights and cameras to a scene time.
//
// The scene clock: every clip plays at once from scene time 0, and the scene loops over the
// longest clip (its last key time): the pose at time t is the pose at t mod duration. Before a
// clip's first key and after its last, a channel holds the first or last value (glTF's rule).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace probecast::scene {

struct Scene;

enum class Interpolation : uint8_t { Linear = 0, Step = 1, CubicSpline = 2 };
enum class AnimatedPath : uint8_t { Translation = 0, Rotation = 1, Scale = 2, Weights = 3 };

struct AnimationSampler {
  Interpolation interpolation = Interpolation::Linear;
  std::vector<float> input;   // key times, seconds, strictly increasing
  // Per key `width` floats; CUBICSPLINE keys hold in-tangent, value, out-tangent (3 × width).
  std::vector<float> output;
  uint32_t width = 0;  // 3 (translation, scale), 4 (rotation x, y, z, w) or the morph target count
};

// The sampler's value at time `t` into out[0, width). `rotation`: LINEAR interpolates quaternions
// on the sphere (the shorter arc) and every rotation result is normalised, as glTF specifies.
void sampleAnimation(const AnimationSampler& sampler, float t, bool rotation, float* out);

struct AnimationChannel {
  uint32_t sampler = 0;  // in the clip
  uint32_t node = 0;     // in Rig::nodes
  AnimatedPath path = AnimatedPath::Translation;
};

struct AnimationClip {
  std::string name;
  std::vector<AnimationSampler> samplers;
  std::vector<AnimationChannel> channels;
  float end = 0.0f;  // the last key time of any sampler
};

struct RigNode {
  int32_t parent = -1;
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
  bool hasMatrix = false;  // a node given as a matrix (glTF forbids animating it)
  glm::mat4 matrix{1.0f};
  std::vector<float> weights;  // morph weights: the node's, else its mesh's defaults
};

struct RigSkin {
  std::vector<uint32_t> joints;          // nodes
  std::vector<glm::mat4> inverseBind;    // one per joint
};

// A primitive whose vertices move: its rest data in object space and where its vertices are in
// Scene::positions / normals.
struct RigPrimitive {
  uint32_t node = 0;
  int32_t skin = -1;
  uint32_t firstVertex = 0, vertexCount = 0;
  std::vector<glm::vec3> positions, normals;  // object space (normals unit, or recomputed: normalsGiven false)
  bool normalsGiven = true;
  bool flip = false;                  // the node mirrored at load: the scene's winding is reversed
  std::vector<uint32_t> triangles;    // local indices as the file gives them (for recomputed normals)
  std::vector<glm::uvec4> joints[2];  // JOINTS_0, JOINTS_1 (indices into the skin's joints)
  std::vector<glm::vec4> weights[2];  // WEIGHTS_0, WEIGHTS_1
  std::vector<std::vector<glm::vec3>> targetPositions, targetNormals;  // morph target deltas
};

struct Rig {
  std::vector<RigNode> nodes;
  std::vector<uint32_t> order;  // nodes, parents before children
  std::vector<RigSkin> skins;
  std::vector<AnimationClip> clips;
  std::vector<RigPrimitive> primitives;  // the ones that move (skinned, morphed, or below an animated node)
  struct Attached {
    uint32_t node = 0;
    uint32_t index = 0;  // in Scene::lights or Scene::cameras
  };
  std::vector<Attached> lights, cameras;  // the ones below an animated node
  float duration = 0.0f;  // the longest clip's end; 0: nothing plays
};

// Whether the scene has geometry or lights that move with time.
bool sceneAnimates(const Scene& scene);
// The animation's length, seconds (0 when nothing plays).
double animationDuration(const Scene& scene);
// Scene time → the time within the loop, [0, duration).
double loopTime(const Rig& rig, double seconds);
// Moves the scene's moving vertices (and their normals), lights and cameras to scene time
// `seconds`. Counts, triangle order, texture coordinates and bounds (which already hold every
// pose, see loadGltf) stay as they are. A scene without a rig is left alone.
void poseScene(Scene& scene, double seconds);
// The world matrix of every node at scene time `seconds`.
std::vector<glm::mat4> nodeWorldMatrices(const Rig& rig, double seconds);

}  // namespace probecast::scene
