// Looking Glass calibration files (visual.json): parsed and checked without Vulkan, so the fuzz
// build can take this file alone.
#include "looking_glass_calibration.h"

#include <cmath>
#include <cstddef>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace probecast::renderer {
namespace {

using nlohmann::json;

constexpr int kMaxScreenSide = 16384;
constexpr double kMinAbsSlope = 0.01;  // a lens sheet this flat would need a near-infinite tilt
constexpr double kMaxAbsSlope = 1000.0;
constexpr int kMaxCellPattern = 4;
constexpr size_t kMaxCells = 64;
constexpr double kMaxCellOffset = 4.0;  // pixels; real panels move subpixels by about a third

std::string show(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// A JSON value for an error message, cut short so a huge value cannot flood it.
std::string showJson(const json& v) {
  std::string text = v.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

std::string quoted(const char* field) { return std::string("\"") + field + "\""; }

// The field's value with an optional {"value": ...} wrapper taken off; null when absent.
const json* fieldValue(const json& root, const char* field, const std::string& where) {
  const auto it = root.find(field);
  if (it == root.end()) return nullptr;
  if (it->is_object()) {
    const auto inner = it->find("value");
    if (inner == it->end())
      throw std::invalid_argument(where + "field " + quoted(field) + " is an object without \"value\"");
    return &*inner;
  }
  return &*it;
}

// A finite number from the field, or `fallback` when it is absent and not required.
double numberField(const json& root, const char* field, bool required, double fallback, const std::string& where) {
  const json* v = fieldValue(root, field, where);
  if (!v) {
    if (required) throw std::invalid_argument(where + "missing required field " + quoted(field));
    return fallback;
  }
  if (!v->is_number())
    throw std::invalid_argument(where + "field " + quoted(field) + " must be a number (got " + showJson(*v) + ")");
  const double d = v->get<double>();
  if (!std::isfinite(d))
    throw std::invalid_argument(where + "field " + quoted(field) + " must be finite (got " + show(d) + ")");
  return d;
}

int pixelsField(const json& root, const char* field, const std::string& where) {
  const double d = numberField(root, field, true, 0.0, where);
  if (d != std::floor(d) || d < 1 || d > kMaxScreenSide)
    throw std::invalid_argument(where + "field " + quoted(field) + " must be a whole number of pixels in 1.." +
                                std::to_string(kMaxScreenSide) + " (got " + show(d) + ")");
  return static_cast<int>(d);
}

// Calibration files write flags as 0.0 / 1.0; JSON booleans are taken as well.
bool flagField(const json& root, const char* field, bool fallback, const std::string& where) {
  const json* v = fieldValue(root, field, where);
  if (v && v->is_boolean()) return v->get<bool>();
  const double d = numberField(root, field, false, fallback ? 1.0 : 0.0, where);
  if (d != 0.0 && d != 1.0)
    throw std::invalid_argument(where + "field " + quoted(field) + " must be 0 or 1 (got " + show(d) + ")");
  return d == 1.0;
}

std::string textField(const json& root, const char* field) {
  const auto it = root.find(field);
  if (it == root.end()) return {};
  const json& v = it->is_object() && it->contains("value") ? (*it)["value"] : *it;
  return v.is_string() ? v.get<std::string>() : v.dump();
}
const char* const kCellKeys[6] = {"ROffsetX", "ROffsetY", "GOffsetX", "GOffsetY", "BOffsetX", "BOffsetY"};

// subpixelCells: absent, null or an empty array for panels whose subpixels sit in a row.
std::vector<LookingGlassSubpixelCell> cellsField(const json& root, const std::string& where) {
  const json* v = fieldValue(root, "subpixelCells", where);
  std::vector<LookingGlassSubpixelCell> cells;
  if (!v || v->is_null()) return cells;
  if (!v->is_array())
    throw std::invalid_argument(where + "field \"subpixelCells\" must be an array (got " + showJson(*v) + ")");
  if (v->size() > kMaxCells)
    throw std::invalid_argument(where + "field \"subpixelCells\" must hold at most " + std::to_string(kMaxCells) +
                                " cells (got " + std::to_string(v->size()) + ")");
  for (size_t k = 0; k < v->size(); ++k) {
    const json& entry = (*v)[k];
    const std::string at = where + "subpixelCells[" + std::to_string(k) + "]: ";
    if (!entry.is_object()) throw std::invalid_argument(at + "expected an object, got " + showJson(entry));
    LookingGlassSubpixelCell cell;
    for (int i = 0; i < 3; ++i) {
      cell.dx[i] = numberField(entry, kCellKeys[2 * i], true, 0.0, at);
      cell.dy[i] = numberField(entry, kCellKeys[2 * i + 1], true, 0.0, at);
    }
    cells.push_back(cell);
  }
  return cells;
}

int cellPatternField(const json& root, const std::string& where) {
  const double d = numberField(root, "CellPatternMode", false, 0.0, where);
  if (d != std::floor(d) || d < 0 || d > kMaxCellPattern)
    throw std::invalid_argument(where + "field \"CellPatternMode\" must be a whole number in 0.." +
                                std::to_string(kMaxCellPattern) + " (got " + show(d) + ")");
  return static_cast<int>(d);
}
}  // namespace

// The checks both the parser and the interleaver rely on, on the values as stored.
void checkLookingGlassCalibration(const LookingGlassCalibration& c, const std::string& where) {
  const auto field = [&](const char* name, const std::string& rule, double got) {
    throw std::invalid_argument(where + "field " + quoted(name) + " " + rule + " (got " + show(got) + ")");
  };
  if (c.screenW < 1 || c.screenW > kMaxScreenSide)
    field("screenW", "must be in 1.." + std::to_string(kMaxScreenSide), c.screenW);
  if (c.screenH < 1 || c.screenH > kMaxScreenSide)
    field("screenH", "must be in 1.." + std::to_string(kMaxScreenSide), c.screenH);
  // Real panels: a few hundred pixels and some tens of lenticules per inch.
  constexpr double kMaxPerInch = 1e5;
  if (!std::isfinite(c.dpi) || c.dpi <= 0 || c.dpi > kMaxPerInch)
    field("DPI", "must be a finite number > 0 and at most " + show(kMaxPerInch), c.dpi);
  if (!std::isfinite(c.pitch) || c.pitch <= 0 || c.pitch > kMaxPerInch)
    field("pitch", "must be a finite number > 0 and at most " + show(kMaxPerInch), c.pitch);
  if (!std::isfinite(c.slope) || std::fabs(c.slope) < kMinAbsSlope || std::fabs(c.slope) > kMaxAbsSlope)
    field("slope", "must be finite with |slope| in [" + show(kMinAbsSlope) + ", " + show(kMaxAbsSlope) + "]",
          c.slope);
  if (!std::isfinite(c.center)) field("center", "must be finite", c.center);
  if (!std::isfinite(c.viewCone) || c.viewCone <= 0 || c.viewCone >= 180)
    field("viewCone", "must be in (0, 180) degrees", c.viewCone);
  if (!std::isfinite(c.verticalAngle)) field("verticalAngle", "must be finite", c.verticalAngle);
  if (c.cellPatternMode < 0 || c.cellPatternMode > kMaxCellPattern)
    field("CellPatternMode", "must be a whole number in 0.." + std::to_string(kMaxCellPattern), c.cellPatternMode);
  if (c.subpixelCells.size() > kMaxCells)
    field("subpixelCells", "must hold at most " + std::to_string(kMaxCells) + " cells",
          static_cast<double>(c.subpixelCells.size()));
  for (const LookingGlassSubpixelCell& cell : c.subpixelCells)
    for (int i = 0; i < 3; ++i)
      for (const double d : {cell.dx[i], cell.dy[i]})
        if (!std::isfinite(d) || std::fabs(d) > kMaxCellOffset)
          field("subpixelCells", "offsets must be finite and within " + show(kMaxCellOffset) + " pixels", d);
}


int cellOfPixel(int mode, int cellCount, int x, int y) {
  if (cellCount < 1) return 0;
  int cell = 0;
  switch (mode) {
    case 1: cell = (x + y) % 2; break;
    case 2: cell = y % 4; break;
    case 3: cell = (y + 2 * (x % 2)) % 4; break;
    case 4: cell = x % 2; break;
    default: break;
  }
  return cell % cellCount;
}

LookingGlassModel lookingGlassModel(const std::string& serial, int screenW, int screenH) {
  struct Known {
    const char* prefix;
    const char* name;
    int columns, rows, viewHeight;
  };
  // Longer prefixes first where one begins another.
  static const Known kKnown[] = {
      {"LKG-2K", "Looking Glass 8.9\"", 5, 9, 227},
      {"LKG-4K", "Looking Glass 15.6\"", 5, 9, 455},
      {"LKG-8K", "Looking Glass 8K", 5, 9, 910},
      {"LKG-P", "Looking Glass Portrait", 8, 6, 560},
      {"LKG-A", "Looking Glass 16\" (2nd generation)", 5, 9, 455},
      {"LKG-B", "Looking Glass 32\" (2nd generation)", 5, 9, 910},
      {"LKG-D", "Looking Glass 65\"", 8, 9, 910},
      {"LKG-E", "Looking Glass Go", 11, 6, 682},
      {"LKG-F", "Looking Glass kiosk", 11, 6, 682},
      {"LKG-H", "Looking Glass 16\" Spatial (portrait)", 11, 6, 1000},
      {"LKG-J", "Looking Glass 16\" Spatial (landscape)", 7, 7, 857},
      {"LKG-K", "Looking Glass 32\" Spatial (portrait)", 11, 6, 1364},
      {"LKG-L", "Looking Glass 32\" Spatial (landscape)", 7, 7, 1170},
  };
  for (const Known& k : kKnown)
    if (serial.rfind(k.prefix, 0) == 0) return {k.name, k.columns, k.rows, k.viewHeight};
  const QuiltLayout layout = defaultQuiltLayout(screenW, screenH);
  return {screenH > screenW ? "portrait display" : "landscape display", layout.columns, layout.rows, 560};
}

QuiltLayout defaultQuiltLayout(int screenW, int screenH) {
  if (screenH > screenW) return {8, 6};  // portrait panels
  if (screenW >= 3840) return {5, 9};    // the 4K/8K class
  return {5, 9};                         // smaller landscape panels use the same layout
}

LookingGlassCalibration parseLookingGlassCalibration(const std::string& jsonText) {
  const std::string where = "visual.json: ";
  const json root = json::parse(jsonText, nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded()) throw std::invalid_argument(where + "malformed JSON");
  if (!root.is_object()) throw std::invalid_argument(where + "expected a JSON object, got " + showJson(root));

  LookingGlassCalibration c;
  c.pitch = numberField(root, "pitch", true, 0.0, where);
  c.slope = numberField(root, "slope", true, 0.0, where);
  c.center = numberField(root, "center", true, 0.0, where);
  c.dpi = numberField(root, "DPI", true, 0.0, where);
  c.screenW = pixelsField(root, "screenW", where);
  c.screenH = pixelsField(root, "screenH", where);
  c.viewCone = static_cast<float>(numberField(root, "viewCone", false, 40.0, where));
  c.verticalAngle = static_cast<float>(numberField(root, "verticalAngle", false, 0.0, where));
  c.invView = flagField(root, "invView", true, where);
  c.flipImageX = flagField(root, "flipImageX", false, where);
  c.flipImageY = flagField(root, "flipImageY", false, where);
  c.flipSubp = flagField(root, "flipSubp", false, where);
  c.serial = textField(root, "serial");
  c.configVersion = textField(root, "configVersion");
  c.subpixelCells = cellsField(root, where);
  c.cellPatternMode = cellPatternField(root, where);
  checkLookingGlassCalibration(c, where);
  const LookingGlassModel model = lookingGlassModel(c.serial, c.screenW, c.screenH);
  c.model = model.name;
  c.quiltColumns = model.columns;
  c.quiltRows = model.rows;
  c.viewHeight = model.viewHeight;
  return c;
}

LookingGlassCalibration loadLookingGlassCalibration(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open the Looking Glass calibration");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw std::runtime_error(path + ": cannot read the Looking Glass calibration");
  try {
    return parseLookingGlassCalibration(text.str());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
}

}  // namespace probecast::renderer
