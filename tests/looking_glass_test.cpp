// Looking Glass output: the visual.json parser and the GPU interleaver, the latter against an
// independent double-precision evaluation of the display formula written out here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/renderer/looking_glass.h"
#include "probecast/renderer/view_sets.h"
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

using nlohmann::json;

// ---- The reference: the Looking Glass formula, evaluated in double precision ---------------

// How close to a view boundary the GPU may disagree with this reference. The shader's phase is
// exact to a few 1e-8 on these panels (fixed point, see looking_glass.comp), so 1e-5 is ample; a
// window of 1e-4 would by itself cover 2 · 1e-4 · 48 ≈ 1% of all phases with 48 views and leave
// the "rare" check below no margin.
constexpr double kBoundaryWindow = 1e-5;

struct ExpectedView {
  int view = 0;
  bool ambiguous = false;  // the phase lies within kBoundaryWindow of a view boundary
};

// The cell of a pixel, written out from the pattern descriptions (not renderer::cellOfPixel).
int referenceCell(int mode, int cells, int x, int yUp) {
  int cell = 0;
  if (mode == 1) cell = (x % 2 == yUp % 2) ? 0 : 1;  // checkerboard, cell 0 at the bottom-left
  if (mode == 2) cell = yUp % 4;
  if (mode == 3) cell = (yUp + (x % 2 == 1 ? 2 : 0)) % 4;
  if (mode == 4) cell = x % 2;
  return cell % cells;
}

// Which view subpixel `channel` of the pixel at column x, row yUp (counted from the bottom) shows.
ExpectedView expectedView(const LookingGlassCalibration& c, int views, int x, int yUp, int channel) {
  const double w = c.screenW, h = c.screenH, slope = c.slope;
  const double pitchEff = double(c.pitch) * w / double(c.dpi) * std::cos(std::atan(1.0 / slope));
  const double tilt = h / (w * slope);
  const double subp = (c.flipSubp ? -1.0 : 1.0) / (3.0 * w);
  double u = (x + 0.5) / w, v = (yUp + 0.5) / h;
  if (c.subpixelCells.empty()) {
    u += channel * subp;
  } else {  // the subpixel's own place in its cell
    const LookingGlassSubpixelCell& cell =
        c.subpixelCells[referenceCell(c.cellPatternMode, static_cast<int>(c.subpixelCells.size()), x, yUp)];
    u += cell.dx[channel] / w;
    v += cell.dy[channel] / h;
  }
  double a = (u + v * tilt) * pitchEff - double(c.center);
  a -= std::floor(a);
  if (c.invView) a = 1.0 - a;
  ExpectedView e;
  e.view = std::min(views - 1, static_cast<int>(std::floor(a * views)));
  const double boundary = std::round(a * views) / views;  // nearest j / views, 0 and 1 included
  e.ambiguous = std::fabs(a - boundary) < kBoundaryWindow;
  return e;
}

// Tile contents: either flat (channel c of view k is 100·c + k) or a gradient whose bilinear
// interpolation is exact, 1000·k + 250·c + tx + 20·ty for texel (tx, ty), ty from the tile's top.
double tileValue(bool gradient, int view, int channel, double tx, double ty) {
  if (!gradient) return 100.0 * channel + view;
  return 1000.0 * view + 250.0 * channel + tx + 20.0 * ty;
}

int decodeView(bool gradient, int channel, float value) {
  if (!gradient) return static_cast<int>(std::lround(value - 100.0 * channel));
  return static_cast<int>(std::floor(value / 1000.0));
}

// The quilt as the renderer makes it: separate views put together by composeQuilt.
Image makeQuilt(int columns, int rows, int tileW, int tileH, bool gradient) {
  std::vector<Image> views;
  std::vector<ViewInfo> info;
  for (int k = 0; k < columns * rows; ++k) {
    Image view;
    view.width = static_cast<uint32_t>(tileW);
    view.height = static_cast<uint32_t>(tileH);
    for (int ty = 0; ty < tileH; ++ty)
      for (int tx = 0; tx < tileW; ++tx)
        for (int c = 0; c < 3; ++c) view.rgb.push_back(static_cast<float>(tileValue(gradient, k, c, tx, ty)));
    views.push_back(view);
    ViewInfo vi;
    vi.column = k % columns;
    vi.row = k / columns;
    info.push_back(vi);
  }
  return composeQuilt(views, info, columns, rows);
}

LookingGlassCalibration portraitCalibration() {
  // A Looking Glass Portrait's numbers on a smaller panel (the formula is the same).
  LookingGlassCalibration c;
  c.pitch = 52.0f;
  c.slope = -7.2f;
  c.center = 0.56f;
  c.dpi = 324.0f;
  c.screenW = 96;
  c.screenH = 128;
  c.invView = true;
  return c;
}

// Interleaves a synthetic quilt on the GPU and compares every subpixel with the reference.
void checkAgainstReference(const LookingGlassCalibration& cal, int columns, int rows, int tileW, int tileH,
                           bool gradient) {
  VulkanContext context(test::validatedContext());
  const Image quilt = makeQuilt(columns, rows, tileW, tileH, gradient);
  const Image panel = interleaveQuilt(context, quilt, columns, rows, cal);
  ASSERT_EQ(panel.width, static_cast<uint32_t>(cal.screenW));
  ASSERT_EQ(panel.height, static_cast<uint32_t>(cal.screenH));
  ASSERT_EQ(panel.rgb.size(), static_cast<size_t>(cal.screenW) * cal.screenH * 3);

  const int views = columns * rows;
  int ambiguous = 0, mismatches = 0;
  for (int r = 0; r < cal.screenH; ++r) {
    const int yUp = cal.screenH - 1 - r;  // the Image is stored from the top
    for (int x = 0; x < cal.screenW; ++x) {
      // Where the view is sampled: (u, v), flipped as asked, as a clamped texel position.
      double u = (x + 0.5) / cal.screenW, v = (yUp + 0.5) / cal.screenH;
      if (cal.flipImageX) u = 1.0 - u;
      if (cal.flipImageY) v = 1.0 - v;
      const double tx = std::clamp(u * tileW - 0.5, 0.0, tileW - 1.0);
      const double ty = std::clamp((1.0 - v) * tileH - 0.5, 0.0, tileH - 1.0);
      for (int c = 0; c < 3; ++c) {
        const ExpectedView e = expectedView(cal, views, x, yUp, c);
        const float got = panel.rgb[(static_cast<size_t>(r) * cal.screenW + x) * 3 + c];
        if (e.ambiguous) {
          // float against double may land on either side: it must still be a neighbouring view.
          ++ambiguous;
          const int seen = decodeView(gradient, c, got);
          const int step = ((seen - e.view) % views + views) % views;
          EXPECT_TRUE(step == 0 || step == 1 || step == views - 1)
              << "pixel (" << x << ", " << r << ") channel " << c << ": view " << seen << ", expected near "
              << e.view;
          continue;
        }
        const double want = tileValue(gradient, e.view, c, tx, ty);
        if (std::fabs(got - want) > 0.02) {
          if (++mismatches <= 10)
            ADD_FAILURE() << "pixel (" << x << ", " << r << ") channel " << c << ": got " << got << ", expected "
                          << want << " (view " << e.view << ")";
        }
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  const int subpixels = cal.screenW * cal.screenH * 3;
  EXPECT_LT(ambiguous, subpixels / 100) << ambiguous << " of " << subpixels << " subpixels sit on a view boundary";
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(LookingGlass, PortraitQuiltInterleavesToTheKnownAnswer) {
  // 8 × 6 flat-coloured tiles: each subpixel must carry exactly its view's channel.
  checkAgainstReference(portraitCalibration(), 8, 6, 16, 12, /*gradient=*/false);
}

TEST(LookingGlass, ForwardViewOrderFlippedSubpixelsAndMirroredImageFollowTheCalibration) {
  // Landscape numbers (positive slope) with views left to right, BGR subpixels and a mirrored
  // image; gradient tiles make the mirroring visible.
  LookingGlassCalibration cal;
  cal.pitch = 49.8f;
  cal.slope = 5.04f;
  cal.center = 0.18f;
  cal.dpi = 338.0f;
  cal.screenW = 128;
  cal.screenH = 80;
  cal.invView = false;
  cal.flipSubp = true;
  cal.flipImageX = true;
  checkAgainstReference(cal, 5, 9, 16, 10, /*gradient=*/true);
}

TEST(LookingGlass, FlipImageYSamplesViewsUpsideDown) {
  LookingGlassCalibration cal = portraitCalibration();
  cal.flipImageY = true;
  checkAgainstReference(cal, 8, 6, 16, 12, /*gradient=*/true);
}

TEST(LookingGlass, UnflippedGradientQuiltSamplesEachViewUpright) {
  checkAgainstReference(portraitCalibration(), 8, 6, 12, 16, /*gradient=*/true);
}

// Cells as panels sold since 2024 have them: red and green on one row, blue on the other, the
// pair mirrored from one cell to the next (offsets in pixels, y up); more cells shift further.
std::vector<LookingGlassSubpixelCell> testCells(int count) {
  std::vector<LookingGlassSubpixelCell> cells;
  for (int k = 0; k < count; ++k) {
    const double side = k % 2 == 0 ? -1.0 : 1.0;
    LookingGlassSubpixelCell cell;
    cell.dx[0] = -0.3 + 0.05 * k;
    cell.dy[0] = 0.25 * side;
    cell.dx[1] = 0.3 - 0.05 * k;
    cell.dy[1] = 0.25 * side;
    cell.dx[2] = 0.02 * k;
    cell.dy[2] = -0.25 * side;
    cells.push_back(cell);
  }
  return cells;
}

TEST(LookingGlass, EveryCellPatternInterleavesToTheKnownAnswer) {
  for (int mode = 0; mode <= 4; ++mode) {
    for (const int count : {2, 4, 6}) {  // six cells: the patterns reach only the first four
      SCOPED_TRACE("CellPatternMode " + std::to_string(mode) + ", " + std::to_string(count) + " cells");
      LookingGlassCalibration cal = portraitCalibration();
      cal.subpixelCells = testCells(count);
      cal.cellPatternMode = mode;
      checkAgainstReference(cal, 11, 6, 8, 10, /*gradient=*/false);
    }
  }
  // Cells replace the row of subpixels: flipSubp no longer applies, the mirrored image still does.
  LookingGlassCalibration cal = portraitCalibration();
  cal.subpixelCells = testCells(2);
  cal.cellPatternMode = 4;
  cal.flipSubp = true;
  cal.flipImageX = true;
  checkAgainstReference(cal, 7, 7, 12, 12, /*gradient=*/true);
}

TEST(LookingGlass, CellsMoveSubpixelsToOtherViews) {
  // The cells matter: the same panel interleaved as if its subpixels were in a row differs.
  VulkanContext context(test::validatedContext());
  LookingGlassCalibration cal = portraitCalibration();
  const Image quilt = makeQuilt(11, 6, 8, 10, /*gradient=*/false);
  const Image row = interleaveQuilt(context, quilt, 11, 6, cal);
  cal.subpixelCells = testCells(2);
  cal.cellPatternMode = 2;
  const Image cells = interleaveQuilt(context, quilt, 11, 6, cal);
  size_t differ = 0;
  for (size_t i = 0; i < row.rgb.size(); ++i) differ += row.rgb[i] != cells.rgb[i];
  EXPECT_GT(differ, row.rgb.size() / 4) << differ << " of " << row.rgb.size();
}

// The whole panel at its real size, every subpixel against the reference: a Portrait (subpixels in
// a row), and 16" Spatial panels in both orientations with their cell patterns.
TEST(LookingGlass, PanelsAtTheirRealSizeMatchTheFormula) {
  LookingGlassCalibration portrait = portraitCalibration();
  portrait.screenW = 1536;
  portrait.screenH = 2048;
  LookingGlassCalibration landscape;
  landscape.pitch = 44.8;
  landscape.slope = -6.93;
  landscape.center = 0.47;
  landscape.dpi = 283.0;
  landscape.screenW = 3840;
  landscape.screenH = 2160;
  landscape.subpixelCells = testCells(2);
  landscape.cellPatternMode = 2;
  LookingGlassCalibration tall = landscape;
  tall.slope = -7.41;
  tall.center = -0.12;
  tall.screenW = 2160;
  tall.screenH = 3840;
  tall.cellPatternMode = 4;
  checkAgainstReference(portrait, 8, 6, 4, 4, /*gradient=*/false);
  checkAgainstReference(landscape, 7, 7, 4, 4, /*gradient=*/false);
  checkAgainstReference(tall, 11, 6, 4, 4, /*gradient=*/false);
}

// Bounded memory: with buffers of at most 40,000 bytes the quilt goes up 2 of its 6 tile rows at a
// time and the panel comes back 34 rows at a time (12 passes); the panel is the one made in a
// single pass, bit for bit. A single row of tiles over the limit is refused by name.
TEST(LookingGlass, BandsWithinABufferLimitGiveThePanelOfOnePass) {
  VulkanContext context(test::validatedContext());
  const LookingGlassCalibration cal = portraitCalibration();
  const Image quilt = makeQuilt(8, 6, 16, 12, /*gradient=*/true);
  const Image whole = interleaveQuilt(context, quilt, 8, 6, cal);
  const Image banded = interleaveQuilt(context, quilt, 8, 6, cal, 40000);
  ASSERT_EQ(banded.rgb.size(), whole.rgb.size());
  EXPECT_TRUE(banded.rgb == whole.rgb);
  try {
    interleaveQuilt(context, quilt, 8, 6, cal, 10000);  // a row of tiles is 18,432 bytes
    ADD_FAILURE() << "a limit below one row of tiles was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("one row of quilt tiles (18432 bytes) exceeds"), std::string::npos) << e.what();
  }
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(LookingGlass, InterleaverRefusesQuiltsThatDoNotSplitIntoTiles) {
  VulkanContext context(test::validatedContext());
  const LookingGlassCalibration cal = portraitCalibration();
  const Image quilt = makeQuilt(8, 6, 16, 12, false);
  EXPECT_THROW(interleaveQuilt(context, quilt, 7, 6, cal), std::invalid_argument);  // 128 px in 7 columns
  EXPECT_THROW(interleaveQuilt(context, quilt, 0, 6, cal), std::invalid_argument);
  Image truncated = quilt;
  truncated.rgb.pop_back();
  EXPECT_THROW(interleaveQuilt(context, truncated, 8, 6, cal), std::invalid_argument);
  LookingGlassCalibration flat = cal;
  flat.slope = 0.0f;
  EXPECT_THROW(interleaveQuilt(context, quilt, 8, 6, flat), std::invalid_argument);
}

// ---- visual.json ------------------------------------------------------------------------------

const char* kPortraitVisualJson = R"({
  "configVersion": "1.0",
  "serial": "LKG-P00042",
  "pitch": {"value": 52.58737564086914},
  "slope": {"value": -7.196136474609375},
  "center": {"value": 0.4321881234645844},
  "viewCone": {"value": 40.0},
  "invView": {"value": 1.0},
  "verticalAngle": {"value": 0.0},
  "DPI": {"value": 324.0},
  "screenW": {"value": 1536.0},
  "screenH": {"value": 2048.0},
  "flipImageX": {"value": 0.0},
  "flipImageY": {"value": 0.0},
  "flipSubp": {"value": 0.0}
})";

TEST(LookingGlass, ParsesAFullVisualJson) {
  const LookingGlassCalibration c = parseLookingGlassCalibration(kPortraitVisualJson);
  EXPECT_DOUBLE_EQ(c.pitch, 52.58737564086914);  // as stated, not rounded to float
  EXPECT_DOUBLE_EQ(c.slope, -7.196136474609375);
  EXPECT_DOUBLE_EQ(c.center, 0.4321881234645844);
  EXPECT_DOUBLE_EQ(c.dpi, 324.0);
  EXPECT_FLOAT_EQ(c.viewCone, 40.0f);
  EXPECT_FLOAT_EQ(c.verticalAngle, 0.0f);
  EXPECT_EQ(c.screenW, 1536);
  EXPECT_EQ(c.screenH, 2048);
  EXPECT_TRUE(c.invView);
  EXPECT_FALSE(c.flipImageX);
  EXPECT_FALSE(c.flipImageY);
  EXPECT_FALSE(c.flipSubp);
  EXPECT_EQ(c.serial, "LKG-P00042");
  EXPECT_EQ(c.configVersion, "1.0");
  EXPECT_EQ(c.quiltColumns, 8);
  EXPECT_EQ(c.quiltRows, 6);
}

TEST(LookingGlass, AcceptsPlainNumbersAndDefaultsTheOptionalFields) {
  const LookingGlassCalibration c = parseLookingGlassCalibration(
      R"({"pitch": 49.8, "slope": 5.04, "center": -0.25, "DPI": 283, "screenW": 3840, "screenH": 2160,
          "flipImageX": {"value": 1}, "flipSubp": true, "someFutureField": {"value": 3}})");
  EXPECT_DOUBLE_EQ(c.pitch, 49.8);
  EXPECT_DOUBLE_EQ(c.slope, 5.04);
  EXPECT_DOUBLE_EQ(c.center, -0.25);
  EXPECT_DOUBLE_EQ(c.dpi, 283.0);
  EXPECT_EQ(c.screenW, 3840);
  EXPECT_EQ(c.screenH, 2160);
  EXPECT_FLOAT_EQ(c.viewCone, 40.0f);
  EXPECT_TRUE(c.invView);
  EXPECT_TRUE(c.flipImageX);
  EXPECT_FALSE(c.flipImageY);
  EXPECT_TRUE(c.flipSubp);
  EXPECT_EQ(c.quiltColumns, 5);
  EXPECT_EQ(c.quiltRows, 9);
}

// The message of the std::invalid_argument that parsing `text` throws ("" when it does not).
std::string refusal(const std::string& text) {
  try {
    parseLookingGlassCalibration(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(LookingGlass, MissingRequiredFieldIsNamed) {
  for (const char* field : {"pitch", "slope", "center", "DPI", "screenW", "screenH"}) {
    json j = json::parse(kPortraitVisualJson);
    j.erase(field);
    const std::string message = refusal(j.dump());
    EXPECT_NE(message.find("missing required field \"" + std::string(field) + "\""), std::string::npos)
        << field << ": " << message;
  }
}

TEST(LookingGlass, RefusesBadValuesWithMessagesNamingTheField) {
  struct Case {
    const char* field;
    json value;
    const char* says;
  };
  const Case cases[] = {
      {"pitch", {{"value", "NaN"}}, "\"pitch\" must be a number"},
      {"center", "0.5", "\"center\" must be a number"},
      {"slope", {{"value", nullptr}}, "\"slope\" must be a number"},
      {"DPI", {{"val", 324}}, "\"DPI\" is an object without \"value\""},
      {"screenW", {{"value", 0}}, "\"screenW\" must be a whole number of pixels in 1..16384"},
      {"screenH", 20000, "\"screenH\" must be a whole number of pixels in 1..16384"},
      {"screenW", 1536.5, "\"screenW\" must be a whole number"},
      {"DPI", {{"value", -1}}, "\"DPI\" must be a finite number > 0"},
      {"pitch", 0, "\"pitch\" must be a finite number > 0"},
      {"pitch", 1e300, "\"pitch\" must be a finite number > 0 and at most 100000"},  // absurd but finite
      {"slope", 0, "\"slope\" must be finite with |slope| in"},
      {"slope", -1e6, "\"slope\" must be finite with |slope| in"},
      {"invView", {{"value", 2}}, "\"invView\" must be 0 or 1"},
      {"viewCone", -5, "\"viewCone\" must be in (0, 180)"},
  };
  for (const Case& c : cases) {
    json j = json::parse(kPortraitVisualJson);
    j[c.field] = c.value;
    const std::string message = refusal(j.dump());
    EXPECT_NE(message.find(c.says), std::string::npos) << c.field << " = " << c.value.dump() << ": " << message;
  }
  // JSON has no NaN or infinity literals, and a broken file is refused as a whole.
  EXPECT_NE(refusal(R"({"pitch": NaN, "slope": -7, "center": 0, "DPI": 324, "screenW": 8, "screenH": 8})")
                .find("malformed JSON"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"pitch": 1e999, "slope": -7, "center": 0, "DPI": 324, "screenW": 8, "screenH": 8})")
                .find("malformed JSON"),
            std::string::npos);
  EXPECT_NE(refusal(std::string(kPortraitVisualJson).substr(0, 80)).find("malformed JSON"), std::string::npos);
  EXPECT_NE(refusal("").find("malformed JSON"), std::string::npos);
  EXPECT_NE(refusal("[1, 2]").find("expected a JSON object"), std::string::npos);
}

TEST(LookingGlass, LoadsAFileAndPutsItsPathInFrontOfRefusals) {
  const std::string good = std::string(PROBECAST_TEST_TMP) + "/looking_glass_visual.json";
  const std::string bad = std::string(PROBECAST_TEST_TMP) + "/looking_glass_bad_visual.json";
  std::ofstream(good) << kPortraitVisualJson;
  std::ofstream(bad) << R"({"pitch": 52, "slope": -7, "center": 0, "DPI": 324, "screenW": 1536})";
  EXPECT_EQ(loadLookingGlassCalibration(good).screenH, 2048);
  try {
    loadLookingGlassCalibration(bad);
    ADD_FAILURE() << "a file without screenH was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(bad), std::string::npos) << message;
    EXPECT_NE(message.find("\"screenH\""), std::string::npos) << message;
  }
  EXPECT_THROW(loadLookingGlassCalibration(std::string(PROBECAST_TEST_TMP) + "/no_such_visual.json"),
               std::runtime_error);
  std::remove(good.c_str());
  std::remove(bad.c_str());
}

// A 16" Spatial landscape panel's file as the display reports it (numbers made up, layout real).
const char* kSpatialVisualJson = R"({
  "configVersion": "3.0",
  "serial": "LKG-J01234",
  "pitch": {"value": 44.71},
  "slope": {"value": -6.91},
  "center": {"value": 0.48},
  "viewCone": {"value": 50.0},
  "invView": {"value": 1.0},
  "verticalAngle": {"value": 0.0},
  "DPI": {"value": 283.0},
  "screenW": {"value": 3840.0},
  "screenH": {"value": 2160.0},
  "flipImageX": {"value": 0.0},
  "flipImageY": {"value": 0.0},
  "flipSubp": {"value": 0.0},
  "CellPatternMode": {"value": 2},
  "subpixelCells": [
    {"ROffsetX": -0.31, "ROffsetY": 0.25, "GOffsetX": 0.28, "GOffsetY": 0.25, "BOffsetX": 0.0, "BOffsetY": -0.25},
    {"ROffsetX": -0.31, "ROffsetY": -0.25, "GOffsetX": 0.28, "GOffsetY": -0.25, "BOffsetX": 0.0, "BOffsetY": 0.25}
  ]
})";

TEST(LookingGlass, ParsesSubpixelCellsAndTheModelsViewSet) {
  const LookingGlassCalibration c = parseLookingGlassCalibration(kSpatialVisualJson);
  ASSERT_EQ(c.subpixelCells.size(), 2u);
  EXPECT_EQ(c.cellPatternMode, 2);
  EXPECT_DOUBLE_EQ(c.subpixelCells[0].dx[0], -0.31);
  EXPECT_DOUBLE_EQ(c.subpixelCells[0].dy[1], 0.25);
  EXPECT_DOUBLE_EQ(c.subpixelCells[1].dy[2], 0.25);
  EXPECT_DOUBLE_EQ(c.subpixelCells[1].dx[1], 0.28);
  EXPECT_EQ(c.model, "Looking Glass 16\" Spatial (landscape)");
  EXPECT_EQ(c.quiltColumns, 7);
  EXPECT_EQ(c.quiltRows, 7);
  EXPECT_EQ(c.viewHeight, 857);
  EXPECT_FLOAT_EQ(c.viewCone, 50.0f);
  // An empty list is a panel with its subpixels in a row.
  json j = json::parse(kSpatialVisualJson);
  j["subpixelCells"] = json::array();
  EXPECT_TRUE(parseLookingGlassCalibration(j.dump()).subpixelCells.empty());
}

TEST(LookingGlass, RefusesBadCellsByName) {
  struct Case {
    const char* field;
    json value;
    const char* says;
  };
  json tooMany = json::array();
  for (int k = 0; k < 65; ++k) tooMany.push_back(json::parse(kSpatialVisualJson)["subpixelCells"][0]);
  json missing = json::parse(kSpatialVisualJson)["subpixelCells"];
  missing[1].erase("BOffsetY");
  json far = json::parse(kSpatialVisualJson)["subpixelCells"];
  far[0]["GOffsetX"] = 12.0;
  json text = json::parse(kSpatialVisualJson)["subpixelCells"];
  text[0]["ROffsetY"] = "0.25";
  const Case cases[] = {
      {"CellPatternMode", 5, "\"CellPatternMode\" must be a whole number in 0..4"},
      {"CellPatternMode", {{"value", 1.5}}, "\"CellPatternMode\" must be a whole number in 0..4"},
      {"CellPatternMode", -1, "\"CellPatternMode\" must be a whole number in 0..4"},
      {"subpixelCells", "cells", "\"subpixelCells\" must be an array"},
      {"subpixelCells", json::array({1}), "subpixelCells[0]: expected an object"},
      {"subpixelCells", missing, "subpixelCells[1]: missing required field \"BOffsetY\""},
      {"subpixelCells", far, "\"subpixelCells\" offsets must be finite and within 4 pixels"},
      {"subpixelCells", text, "subpixelCells[0]: field \"ROffsetY\" must be a number"},
      {"subpixelCells", tooMany, "\"subpixelCells\" must hold at most 64 cells"},
  };
  for (const Case& c : cases) {
    json j = json::parse(kSpatialVisualJson);
    j[c.field] = c.value;
    const std::string message = refusal(j.dump());
    EXPECT_NE(message.find(c.says), std::string::npos) << c.field << " = " << c.value.dump() << ": " << message;
  }
}

TEST(LookingGlass, ModelsBySerialAndCellsByPattern) {
  struct Case {
    const char* serial;
    int w, h, columns, rows, viewHeight;
  };
  const Case cases[] = {
      {"LKG-P01234", 1536, 2048, 8, 6, 560},  {"LKG-E05678", 1440, 2560, 11, 6, 682},
      {"LKG-H00001", 2160, 3840, 11, 6, 1000}, {"LKG-J00002", 3840, 2160, 7, 7, 857},
      {"LKG-K00003", 4320, 7680, 11, 6, 1364}, {"LKG-L00004", 7680, 4320, 7, 7, 1170},
      {"LKG-4K1234", 3840, 2160, 5, 9, 455},  {"LKG-2K0042", 2560, 1600, 5, 9, 227},
      {"", 1080, 1920, 8, 6, 560},            {"my-own-panel", 1920, 1080, 5, 9, 560},
  };
  for (const Case& c : cases) {
    const LookingGlassModel m = lookingGlassModel(c.serial, c.w, c.h);
    EXPECT_EQ(m.columns, c.columns) << c.serial;
    EXPECT_EQ(m.rows, c.rows) << c.serial;
    EXPECT_EQ(m.viewHeight, c.viewHeight) << c.serial;
  }
  EXPECT_EQ(lookingGlassModel("LKG-E05678", 1440, 2560).name, "Looking Glass Go");
  // Pixel (x, y from the bottom) → cell, per pattern, for two cells and for four.
  EXPECT_EQ(cellOfPixel(0, 2, 5, 3), 0);
  EXPECT_EQ(cellOfPixel(1, 2, 0, 0), 0);
  EXPECT_EQ(cellOfPixel(1, 2, 1, 0), 1);
  EXPECT_EQ(cellOfPixel(1, 2, 1, 1), 0);
  EXPECT_EQ(cellOfPixel(2, 4, 9, 6), 2);
  EXPECT_EQ(cellOfPixel(2, 2, 9, 7), 1);
  EXPECT_EQ(cellOfPixel(3, 4, 1, 3), 1);  // (3 + 2) mod 4
  EXPECT_EQ(cellOfPixel(3, 4, 2, 3), 3);
  EXPECT_EQ(cellOfPixel(4, 2, 7, 0), 1);
  EXPECT_EQ(cellOfPixel(4, 2, 8, 5), 0);
  EXPECT_EQ(cellOfPixel(2, 3, 0, 3), 0);  // 3 mod 3
}

TEST(LookingGlass, DefaultQuiltLayoutFollowsThePanelShape) {
  const QuiltLayout portrait = defaultQuiltLayout(1536, 2048);
  EXPECT_EQ(portrait.columns, 8);
  EXPECT_EQ(portrait.rows, 6);
  const QuiltLayout wide = defaultQuiltLayout(3840, 2160);
  EXPECT_EQ(wide.columns, 5);
  EXPECT_EQ(wide.rows, 9);
  const QuiltLayout small = defaultQuiltLayout(2560, 1600);
  EXPECT_EQ(small.columns, 5);
  EXPECT_EQ(small.rows, 9);
}

}  // namespace
}  // namespace probecast::renderer
