// Equirectangular environment maps: loading, and the projection to SH and brute-force irradiance
// of probecast/codec/equirect.h on an EnvMap.
//
// Convention: lat-long, linear radiance, the top row is +Y (up), u = 0 at the left edge.
// Pixel (u, v) in [0, 1)² looks along θ = π v from +Y, φ = 2π (u − 0.5):
//   direction = (sin θ sin φ, cos θ, −sin θ cos φ)
// so the map's centre is −Z and u = 0.75 is +X.
#pragma once

#include <string>
#include <vector>

#include "probecast/codec/sh.h"

namespace probecast::bench {

struct EnvMap {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // width * height * 3, row-major from the top row
};

// Loads .hdr (stb_image) or .exr (imaging::readExr: OpenEXR, any compression; R, G, B or Y).
// On failure returns false and sets `error`.
bool loadEnvMap(const std::string& path, EnvMap& map, std::string& error);

// Direction of the centre of pixel (x, y).
void envMapDirection(const EnvMap& map, int x, int y, float dir[3]);
// Solid angle of a pixel in row y.
float envMapPixelSolidAngle(const EnvMap& map, int y);

// Solid-angle-weighted box downsample by an integer factor (keeps the integral of radiance).
EnvMap downsample(const EnvMap& map, int factor);

// Float L2 SH of the map's radiance (summed in double). `rotationY` rotates the map about +Y (radians).
void projectToSh(const EnvMap& map, float probe[kProbeFloats], float rotationY = 0.0f);

// True irradiance E(n) = ∫ L(ω) max(0, n·ω) dω at each normal (3 floats per normal).
void bruteForceIrradiance(const EnvMap& map, const std::vector<float>& normals, std::vector<float>& irradiance);

// Equal-area spherical Fibonacci set of `count` unit vectors (3 floats each).
std::vector<float> fibonacciSphere(int count);

// Built-in maps (no files needed): a sunny sky over ground, and a dim room with a bright window.
std::vector<EnvMap> builtinEnvMaps();

}  // namespace probecast::bench
