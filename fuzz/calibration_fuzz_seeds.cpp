// Writes the seed corpus for calibration_fuzz into a folder: calibrations as displays write them
// ({"value": x} objects) and as people do (plain numbers), portrait and landscape, with subpixel
// cells as panels sold since 2024 have them.
#include <cstdio>
#include <fstream>
#include <string>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: calibration_fuzz_seeds OUTDIR\n");
    return 2;
  }
  const char* calibrations[] = {
      R"({"configVersion":"1.0","serial":"p","pitch":{"value":52.0},"slope":{"value":-7.2},"center":{"value":0.56},"viewCone":{"value":40.0},"invView":{"value":1.0},"verticalAngle":{"value":0.0},"DPI":{"value":324.0},"screenW":{"value":1536.0},"screenH":{"value":2048.0},"flipImageX":{"value":0.0},"flipImageY":{"value":0.0},"flipSubp":{"value":0.0}})",
      R"({"pitch":49.8,"slope":5.5,"center":-0.2,"DPI":283,"screenW":3840,"screenH":2160,"invView":0,"flipSubp":1,"flipImageX":1})",
      R"({"pitch":{"value":47.5},"slope":{"value":-5.0},"center":{"value":0.1},"DPI":{"value":338.0},"screenW":{"value":2560},"screenH":{"value":1600},"viewCone":{"value":35}})",
      R"({"configVersion":"3.0","serial":"LKG-H0001","pitch":{"value":44.7},"slope":{"value":-7.4},"center":{"value":0.0},"viewCone":{"value":50.0},"DPI":{"value":283.0},"screenW":{"value":2160},"screenH":{"value":3840},"CellPatternMode":{"value":4},"subpixelCells":[{"ROffsetX":-0.25,"ROffsetY":-0.3,"GOffsetX":-0.25,"GOffsetY":0.3,"BOffsetX":0.25,"BOffsetY":0.0},{"ROffsetX":0.25,"ROffsetY":-0.3,"GOffsetX":0.25,"GOffsetY":0.3,"BOffsetX":-0.25,"BOffsetY":0.0}]})",
  };
  int k = 0;
  for (const char* c : calibrations)
    std::ofstream(std::string(argv[1]) + "/calibration-" + std::to_string(k++), std::ios::binary) << c;
  return 0;
}
