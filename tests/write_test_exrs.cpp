// Writes the test image into DIR in the named compressions (OpenEXR names, e.g. DWAB PIZ B44), as
// DIR/test_<NAME>.exr, for the command-line test of `probecast bench codec --envmaps DIR`; the name
// NONFINITE writes the image with NaN and infinite pixels (for compare and --environment checks).
#include <cmath>
#include <cstdio>
#include <limits>
#include <cstring>
#include <exception>

#include "exr_test_files.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: write_test_exrs DIR NAME...\n");
    return 2;
  }
  using namespace probecast::testing;
  const int width = 64, height = 32;
  const std::vector<float> image = exrTestImage(width, height);
  try {
    for (int i = 2; i < argc; ++i) {
      if (std::strcmp(argv[i], "NONFINITE") == 0) {  // uncompressed float, two NaN pixels and an infinite one
        std::vector<float> bad = image;
        bad[(3 * width + 5) * 3] = std::nanf("");
        bad[(7 * width + 1) * 3 + 2] = std::nanf("");
        bad[(9 * width + 9) * 3 + 1] = std::numeric_limits<float>::infinity();
        writeTestExr(std::string(argv[1]) + "/test_NONFINITE.exr", bad, width, height, 0, false);
        continue;
      }
      const ExrCompressionCase* found = nullptr;
      for (const ExrCompressionCase& c : exrCompressionCases())
        if (std::strcmp(c.name, argv[i]) == 0) found = &c;
      if (!found) {
        std::fprintf(stderr, "write_test_exrs: unknown compression %s\n", argv[i]);
        return 2;
      }
      const std::string path = std::string(argv[1]) + "/test_" + found->name + ".exr";
      writeTestExr(path, image, width, height, found->compression, found->half);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "write_test_exrs: %s\n", e.what());
    return 1;
  }
  return 0;
}
