// Equirectangular (lat-long) radiance maps: pixel directions, SH projection and brute-force
// irradiance, on plain float arrays (what `probecast bench codec` and the Python module measure).
//
// Convention: linear radiance, rgb = width × height × 3 floats, row-major from the top row, which
// is +Y (up), u = 0 at the left edge. Pixel (u, v) in [0, 1)² looks along θ = π v from +Y,
// φ = 2π (u − 0.5):  direction = (sin θ sin φ, cos θ, −sin θ cos φ), so the map's centre is −Z and
// u = 0.75 is +X. SH as sh.h (no Condon-Shortley phase, 27 floats coefficient-major RGB).
#pragma once

#include <vector>

#include "probecast/codec/sh.h"

namespace probecast {

// Direction of the centre of pixel (x, y).
void equirectDirection(int width, int height, int x, int y, float dir[3]);
// The pixel whose solid angle holds unit direction `dir` (the inverse of equirectDirection):
// θ = acos(y), φ = atan2(x, −z), column ⌊(φ/2π + 0.5) W⌋, row ⌊θ/π H⌋, both clamped into the map.
void equirectPixel(int width, int height, const float dir[3], int& x, int& y);
// Solid angle of a pixel in row y, steradians (exact band area 2π/W · (cos θ0 − cos θ1)).
float equirectPixelSolidAngle(int width, int height, int y);

// Solid-angle-weighted box downsample by an integer factor (keeps the integral of radiance);
// the result is max(1, width / factor) × max(1, height / factor).
std::vector<float> equirectDownsample(const float* rgb, int width, int height, int factor, int& outWidth,
                                      int& outHeight);

// Float L2 SH of the map's incident radiance (summed in double). `rotationY` rotates the map about
// +Y (radians).
void equirectProjectSh(const float* rgb, int width, int height, float probe[kProbeFloats], float rotationY = 0.0f);

// True irradiance E(n) = ∫ L(ω) max(0, n·ω) dω at `count` unit normals (3 floats each; not
// divided by π), into `irradiance` (3 floats per normal).
void equirectIrradiance(const float* rgb, int width, int height, const float* normals, size_t count,
                        float* irradiance);

// Equal-area spherical Fibonacci set of `count` unit vectors (3 floats each).
std::vector<float> fibonacciSphere(int count);

}  // namespace probecast
