// Distant light around a scene: an equirectangular radiance map, or a uniform sky (a 1 × 1 map).
// Rays that leave the scene (misses) return it, next-event estimation importance-samples it, and
// the raster client draws it as background.
//
// Convention (the codec's, codec/equirect.h, one for the whole project): linear radiance, rows
// from the top, the top row looks up (+Y), u = 0 at the left edge. Pixel (u, v) in [0, 1)² looks
// along θ = π v from +Y and φ = 2π (u − 0.5):
//   map direction = (sin θ sin φ, cos θ, −sin θ cos φ)
// so the map's centre faces −Z, u = 0.75 faces +X, u = 0.25 faces −X and the left/right edge +Z:
// seen from inside (looking at −Z with +Y up), the image's right is the world's right, and
// azimuth runs clockwise seen from above as u grows.
// Rotation turns the map about +Y by `rotation` radians, counter-clockwise seen from above
// (right-handed): world = R_y(rotation) · map direction, R_y(a) (x, y, z) = (x cos a + z sin a, y,
// −x sin a + z cos a). +90° moves the map's centre from −Z to −X.
// Radiance is nearest-texel (piecewise constant per texel): the function the sampler's pdf follows.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace probecast::renderer {

struct Environment {
  std::string name;          // the file, or "sky"
  int width = 0;             // 0: no environment (misses are black)
  int height = 0;
  std::vector<float> rgb;    // width × height × 3, linear radiance with the intensity applied
  float rotation = 0.0f;     // radians about +Y
  bool empty() const { return width == 0; }
};

// Loads an .hdr (Radiance RGBE) or .exr map scaled by `intensity`, rotated by `rotationDegrees`
// about +Y. Returns false with a message naming the file for a missing or unreadable file, a map
// smaller than 2 × 1, a negative, NaN or infinite intensity or rotation, or a pixel that is not
// finite and non-negative (the first one is named).
bool loadEnvironment(const std::string& path, float intensity, float rotationDegrees, Environment& env,
                     std::string& error);
// A uniform sky of radiance `rgb` (each finite and ≥ 0).
bool makeUniformSky(const glm::vec3& rgb, Environment& env, std::string& error);

// Radiance arriving from world direction `dir` (unit): the texel it falls in; black when empty.
glm::vec3 environmentRadiance(const Environment& env, const glm::vec3& dir);
// World direction → map direction and back (R_y(−rotation) and R_y(rotation)).
glm::vec3 environmentToMap(const Environment& env, const glm::vec3& world);
glm::vec3 environmentToWorld(const Environment& env, const glm::vec3& map);

// The 2D sampling distribution over the map: a texel is chosen with probability ∝ its luminance
// × its solid angle (the sin θ factor, integrated exactly over the texel's band), by a marginal
// CDF over rows and a conditional CDF over the columns of each row; a direction is then uniform
// in solid angle within the texel, so its pdf is luminance(texel) / total.
struct EnvironmentDistribution {
  std::vector<float> rows;     // height entries, inclusive CDF, the last exactly 1 (empty map: none)
  std::vector<float> columns;  // height × width, each row an inclusive CDF ending at 1
  double total = 0.0;          // Σ luminance × solid angle (0: nothing to sample)
};
EnvironmentDistribution buildEnvironmentDistribution(const Environment& env);

}  // namespace probecast::renderer
