#version 460
// Looking Glass interleaver: one invocation per panel pixel picks, for each of its R, G and B
// subpixels, the quilt view seen through the lenticular sheet from that subpixel and copies that
// view's matching channel. The formula and the quilt layout are documented in
// renderer/include/probecast/renderer/looking_glass.h.
//
// The lens phase a = (u + i·subp + v·tilt)·pitchEff − center (or, with subpixel cells, the
// subpixel's own offset in place of i·subp) is only needed modulo 1, and u, v are affine in the
// integer pixel position, so the host hands over the per-pixel and per-row steps, each cell's
// per-subpixel offsets and the phase at pixel (0, 0) as unsigned 0.32 fixed-point fractions of a
// lenticule.
// Unsigned wrap-around is then exactly "mod 1", and the phase error stays below (x + y + 3)·2^-33
// (under 4e-6 on a 16K panel), where a float phase of hundreds of lenticules would lose ~1e-4.

layout(local_size_x = 8, local_size_y = 8) in;

// Keep in step with LookingGlassPush in renderer/src/looking_glass.cpp.
layout(push_constant) uniform Push {
  ivec2 screen;  // panel size in pixels
  ivec2 tile;    // size of one view in the quilt, pixels
  int columns;   // quilt tiles across
  int rows;      // quilt tiles down
  int views;     // columns · rows
  uint flags;    // bit 0 invView, bit 1 flipImageX, bit 2 flipImageY, bits 3-5 the cell pattern,
                 // bits 6-8 the number of cells (1..4)
  uvec4 phase;   // 0.32 fixed point: x per pixel right, y per pixel up, (z unused), w at pixel (0, 0)
  // This pass's share (bounded buffers: renderer/src/looking_glass.cpp): the quilt's tile rows
  // [bandTop, bandTop + bandRows) counted from its top are in Quilt, and the panel's pixel rows
  // [panelTop, panelTop + panelRows) in Panel; subpixels whose view lies elsewhere are left.
  int bandTop;
  int bandRows;
  int panelTop;
  int panelRows;
  uint cellPhase[12];  // 0.32 fixed point: cell c's subpixel i at [3c + i], from the pixel's phase
} pc;

// Both buffers hold RGB floats, row-major from the top, three floats per pixel: a band of the
// quilt's tile rows, and a band of the panel's rows.
layout(std430, set = 0, binding = 0) readonly buffer Quilt { float quilt[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Panel { float panel[]; };

const uint kInvView = 1u;
const uint kFlipX = 2u;
const uint kFlipY = 4u;

// The cell of the pixel at column x, row y from the bottom (renderer::cellOfPixel).
uint cellOf(uint x, uint y) {
  const uint pattern = (pc.flags >> 3) & 7u;
  const uint count = max((pc.flags >> 6) & 7u, 1u);
  uint cell = 0u;
  if (pattern == 1u) cell = (x + y) % 2u;
  else if (pattern == 2u) cell = y % 4u;
  else if (pattern == 3u) cell = (y + 2u * (x % 2u)) % 4u;
  else if (pattern == 4u) cell = x % 2u;
  return cell % count;
}

float quiltTexel(ivec2 origin, ivec2 t, int channel) {
  const uint quiltWidth = uint(pc.columns * pc.tile.x);
  const uint index = (uint(origin.y + t.y - pc.bandTop * pc.tile.y) * quiltWidth + uint(origin.x + t.x)) * 3u +
                     uint(channel);
  return quilt[index];
}

// One channel of view `view` at (u, v), v up, bilinear between the four nearest texels of its own
// tile (positions clamped to the tile's texel centres so no neighbouring view leaks in).
float sampleView(uint view, vec2 uv, int channel) {
  const int column = int(view) % pc.columns;
  const int rowUp = int(view) / pc.columns;  // tile rows count from the bottom of the quilt
  const ivec2 origin = ivec2(column * pc.tile.x, (pc.rows - 1 - rowUp) * pc.tile.y);
  // Tiles store the view upright, rows from the top, so v = 1 is texel row 0.
  const vec2 p = clamp(vec2(uv.x * float(pc.tile.x), (1.0 - uv.y) * float(pc.tile.y)) - 0.5, vec2(0.0),
                       vec2(pc.tile - 1));
  const ivec2 t0 = ivec2(p);  // p ≥ 0, so truncation is floor
  const ivec2 t1 = min(t0 + 1, pc.tile - 1);
  const vec2 f = p - vec2(t0);
  const float c00 = quiltTexel(origin, t0, channel);
  const float c10 = quiltTexel(origin, ivec2(t1.x, t0.y), channel);
  const float c01 = quiltTexel(origin, ivec2(t0.x, t1.y), channel);
  const float c11 = quiltTexel(origin, t1, channel);
  // a + (b − a)·t rather than mix(): equal neighbours give back the texel exactly.
  const float top = c00 + (c10 - c00) * f.x;
  const float bottom = c01 + (c11 - c01) * f.x;
  return top + (bottom - top) * f.y;
}

void main() {
  const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy) + ivec2(0, pc.panelTop);
  if (pixel.x >= pc.screen.x || pixel.y >= min(pc.screen.y, pc.panelTop + pc.panelRows)) return;
  const uint yUp = uint(pc.screen.y - 1 - pixel.y);  // the output is stored from the top
  vec2 uv = (vec2(float(pixel.x), float(yUp)) + 0.5) / vec2(pc.screen);
  if ((pc.flags & kFlipX) != 0u) uv.x = 1.0 - uv.x;
  if ((pc.flags & kFlipY) != 0u) uv.y = 1.0 - uv.y;

  const uint base = uint(pixel.x) * pc.phase.x + yUp * pc.phase.y + pc.phase.w;
  const uint cell = cellOf(uint(pixel.x), yUp);
  const uint out0 = (uint(pixel.y - pc.panelTop) * uint(pc.screen.x) + uint(pixel.x)) * 3u;
  for (int i = 0; i < 3; ++i) {
    uint a = base + pc.cellPhase[cell * 3u + uint(i)];  // the fractional phase, wrapped by uint arithmetic
    // 1 − a in 0.32 fixed point (one unit off, which only moves exact view boundaries).
    if ((pc.flags & kInvView) != 0u) a = ~a;
    // view = floor(a · views): the high word of the 64-bit product.
    uint view, low;
    umulExtended(a, uint(pc.views), view, low);
    const int tileRow = pc.rows - 1 - int(view) / pc.columns;  // from the quilt's top
    if (tileRow < pc.bandTop || tileRow >= pc.bandTop + pc.bandRows) continue;
    panel[out0 + uint(i)] = sampleView(view, uv, i);
  }
}
