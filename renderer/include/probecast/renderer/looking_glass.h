// Looking Glass light-field display output: the display's calibration (its `visual.json`) and the
// interleaver that turns a quilt of views into the panel's native, subpixel-interleaved image.
//
// A Looking Glass panel sits under a slanted lenticular sheet, so each red, green and blue
// subpixel is seen from one direction only. The interleaver decides, per subpixel, which view of
// the quilt that direction belongs to, and copies that view's matching colour channel.
//
// Derived values (computed from the calibration in double precision):
//   pitchEff = pitch · screenW / DPI · cos(atan(1 / slope))   lenticules across the screen width
//   tilt     = screenH / (screenW · slope)                     horizontal lens shift per unit of v
//   subp     = 1 / (3 · screenW), negated when flipSubp        one subpixel in u
//   center   = as given                                        phase offset
//
// Per output pixel (x, y), x from the left and y from the BOTTOM of the screen (the display's own
// shaders use GL texture coordinates with v pointing up):
//   u = (x + 0.5) / screenW,  v = (y + 0.5) / screenH
// and per subpixel i = 0, 1, 2 (R, G, B), on panels whose subpixels sit in a row (all sold before
// 2024, and any calibration without `subpixelCells`):
//   a = (u + i·subp + v·tilt) · pitchEff − center
// Panels sold since 2024 place their subpixels in cells (`subpixelCells`: per cell, each subpixel's
// offset (dx, dy) from the pixel centre in pixels, y up) that repeat in a pattern
// (`CellPatternMode`, see cellOfPixel()); the phase then takes the subpixel's own position:
//   a = (u + dx/screenW + (v + dy/screenH) · tilt) · pitchEff − center
// and in both cases:
//   a = a − floor(a)                       (fractional part, in [0, 1))
//   if invView: a = 1 − a
//   k = min(N − 1, floor(a · N))           N = columns · rows views
// and channel i of the output pixel is channel i of view k sampled at (u, v), with u → 1 − u under
// flipImageX and v → 1 − v under flipImageY. The returned Image stores rows from the top as every
// renderer Image does: its row r is y = screenH − 1 − r, so it goes to the panel as is.
//
// Quilt layout (the one renderer::composeQuilt makes): view k sits in tile column k mod columns
// and tile row k div columns counted from the BOTTOM of the quilt, so view 0 is the bottom-left
// tile and the last view the top-right one; inside a tile the view is upright (its top row at the
// tile's top). In the quilt Image (rows from the top) view k's tile starts at pixel
//   x0 = (k mod columns) · tileW,  y0 = (rows − 1 − k div columns) · tileH.
// A view is sampled bilinearly at texel position (u·tileW − 0.5, (1 − v)·tileH − 0.5), clamped to
// its tile's texel centres, so neighbouring tiles never bleed into it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "probecast/renderer/reference_camera.h"
#include "probecast/renderer/vulkan_context.h"

namespace probecast::renderer {

// Where one pixel's red, green and blue subpixels sit, in pixels from its centre (x right, y up).
struct LookingGlassSubpixelCell {
  double dx[3] = {0.0, 0.0, 0.0};  // R, G, B
  double dy[3] = {0.0, 0.0, 0.0};
};

// The cell a pixel takes (x from the left, y from the bottom) under a calibration's
// CellPatternMode: 0 every pixel cell 0; 1 a checkerboard, (x + y) mod 2; 2 rows, y mod 4;
// 3 rows offset by two on odd columns, (y + 2·(x mod 2)) mod 4; 4 columns, x mod 2. The cell is
// then taken modulo the number of cells, so a pattern never reads past them. (The modes as the
// display vendor's current runtime numbers them.)
int cellOfPixel(int mode, int cellCount, int x, int y);

// A display model's usual view set, by the serial's prefix where it names a known model.
struct LookingGlassModel {
  std::string name;     // "Looking Glass Go", ... or "portrait display"/"landscape display"
  int columns = 0;      // quilt layout
  int rows = 0;
  int viewHeight = 0;   // pixels: the model's native quilt height divided by its rows
};

// Known models by serial prefix: Portrait (LKG-P, 8 × 6 of 560 high), Go (LKG-E, 11 × 6 of 682),
// 16" Spatial portrait (LKG-H, 11 × 6 of 1000) and landscape (LKG-J, 7 × 7 of 857), 32" Spatial
// portrait (LKG-K, 11 × 6 of 1364) and landscape (LKG-L, 7 × 7 of 1170), the kiosk (LKG-F, as
// Go), 65" (LKG-D, 8 × 9 of 910), and the first two generations (LKG-2K, -4K, -8K, -A, -B: 5 × 9
// of 227, 455 or 910). Any other serial: 8 × 6 on a portrait panel, 5 × 9 on a landscape one,
// 560 pixels high.
LookingGlassModel lookingGlassModel(const std::string& serial, int screenW, int screenH);

struct LookingGlassCalibration {
  // Required in visual.json.
  // Kept as the file states them (double): the lens phase reaches hundreds of lenticules across a
  // panel, where float32 would move view boundaries by ~1e-4 of a lenticule.
  double pitch = 0.0;   // lenticules per inch
  double slope = 0.0;   // lens slant: pixels down per pixel across along a lens line, signed
  double center = 0.0;  // phase of the lens sheet against the pixels
  double dpi = 0.0;     // the `DPI` field: pixels per inch
  int screenW = 0;      // native panel size in pixels
  int screenH = 0;
  // Optional; defaults as listed.
  float viewCone = 40.0f;      // degrees seen across the views (for the cameras, not the interleaver)
  float verticalAngle = 0.0f;  // kept for completeness; not used by the interleaver
  bool invView = true;         // views run right to left across a lenticule
  bool flipImageX = false;
  bool flipImageY = false;
  bool flipSubp = false;  // BGR subpixel order instead of RGB
  std::string serial;         // picks the display model's view set (lookingGlassModel)
  std::string configVersion;  // informational
  // Panels sold since 2024: the subpixel cells and the pattern they repeat in (empty: subpixels
  // in a row, the formula with subp).
  std::vector<LookingGlassSubpixelCell> subpixelCells;
  int cellPatternMode = 0;
  // The model's view set and view height (lookingGlassModel of serial and screen size).
  std::string model;
  int viewHeight = 0;
  // The quilt layout to render for this display: the model's after parsing. Callers may change
  // it; interleaveQuilt() takes the layout of the quilt it is given.
  int quiltColumns = 0;
  int quiltRows = 0;
};

struct QuiltLayout {
  int columns = 0;
  int rows = 0;
};

// The quilt a display of this size is usually fed: portrait panels (screenH > screenW, e.g. the
// Looking Glass Portrait) take 8 columns × 6 rows = 48 views; landscape panels take 5 × 9 = 45
// views, both those 3840 or more pixels wide (the 4K/8K class) and smaller ones.
QuiltLayout defaultQuiltLayout(int screenW, int screenH);

// Parses the text of a visual.json. Each numeric field may be a plain number or an object
// {"value": number}. Required: pitch, slope, center, DPI, screenW, screenH; optional: viewCone (40),
// invView (1), flipImageX (0), flipImageY (0), flipSubp (0), verticalAngle (0), serial,
// configVersion, subpixelCells (an array of at most 64 objects with ROffsetX, ROffsetY, GOffsetX,
// GOffsetY, BOffsetX, BOffsetY, each in [-4, 4] pixels) and CellPatternMode (0..4); unknown fields
// are ignored. Throws std::invalid_argument, naming the field, for malformed JSON, a missing
// required field, a non-numeric or non-finite value, screenW or screenH not an integer in
// 1..16384, DPI ≤ 0, pitch ≤ 0, |slope| outside [0.01, 1000] (zero included), viewCone outside
// (0, 180), a flag other than 0 or 1, or a cell or pattern outside the rules above.
LookingGlassCalibration parseLookingGlassCalibration(const std::string& jsonText);

// Reads and parses a visual.json file: std::runtime_error when it cannot be read,
// std::invalid_argument (with the path in front) when its contents are refused.
LookingGlassCalibration loadLookingGlassCalibration(const std::string& path);

// Interleaves a quilt (laid out as above, columns × rows equal tiles) into the panel image of
// cal.screenW × cal.screenH pixels, linear RGB, rows from the top, on the GPU (a compute shader).
// Throws std::invalid_argument when the quilt does not split into columns × rows tiles of at
// least one pixel or its pixel data has the wrong size, or when the calibration fails the range
// checks parseLookingGlassCalibration() applies. Memory is bounded: the quilt is uploaded a band of
// tile rows at a time and the panel read back a band of pixel rows at a time, each within the
// device's storage-buffer range (or `bufferLimit` bytes when smaller and not 0), so any panel and
// view set the calibration checks allow works on any device; std::runtime_error only when a
// single row of tiles or of the panel is larger than that.
Image interleaveQuilt(VulkanContext& context, const Image& quilt, int columns, int rows,
                      const LookingGlassCalibration& cal, uint64_t bufferLimit = 0);

}  // namespace probecast::renderer
