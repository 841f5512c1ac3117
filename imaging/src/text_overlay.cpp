// A status line over a frame: stb_easy_font turns text into quads, drawn here as filled boxes.
#include <algorithm>
#include <string>
#include <vector>

#include "probecast/imaging/image_io.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wshadow"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

namespace probecast::imaging {

int drawTextLine(std::vector<unsigned char>& rgba, int width, int height, int x, int y, const std::string& text,
                 int scale, const unsigned char rgb[3]) {
  static const unsigned char kWhite[3] = {235, 235, 235};
  if (!rgb) rgb = kWhite;
  scale = std::clamp(scale, 1, 16);
  if (width <= 0 || height <= 0 || rgba.size() < static_cast<size_t>(width) * static_cast<size_t>(height) * 4) return 0;
  const int band = (stb_easy_font_height(const_cast<char*>(text.c_str())) + 4) * scale;
  auto fill = [&](int x0, int y0, int x1, int y1, const unsigned char* c, float alpha) {
    x0 = std::max(x0, 0);
    y0 = std::max(y0, 0);
    x1 = std::min(x1, width);
    y1 = std::min(y1, height);
    for (int py = y0; py < y1; ++py)
      for (int px = x0; px < x1; ++px) {
        unsigned char* p = &rgba[(static_cast<size_t>(py) * static_cast<size_t>(width) + static_cast<size_t>(px)) * 4];
        for (int k = 0; k < 3; ++k)
          p[k] = static_cast<unsigned char>(alpha * static_cast<float>(c[k]) + (1.0f - alpha) * static_cast<float>(p[k]));
      }
  };
  static const unsigned char kBlack[3] = {0, 0, 0};
  fill(0, y, width, y + band, kBlack, 0.6f);
  // 4 vertices of 16 bytes (x, y, z floats and a colour) per quad; ample room for one line.
  std::vector<char> buffer(text.size() * 270 + 64);
  const int quads = stb_easy_font_print(0.0f, 0.0f, const_cast<char*>(text.c_str()), nullptr, buffer.data(),
                                        static_cast<int>(buffer.size()));
  for (int q = 0; q < quads; ++q) {
    const auto* v = reinterpret_cast<const float*>(buffer.data() + static_cast<size_t>(q) * 64);
    const float qx0 = v[0], qy0 = v[1], qx1 = v[8], qy1 = v[9];  // vertices 0 and 2: opposite corners
    fill(x + static_cast<int>(qx0 * static_cast<float>(scale)), y + 2 * scale + static_cast<int>(qy0 * static_cast<float>(scale)),
         x + static_cast<int>(qx1 * static_cast<float>(scale)), y + 2 * scale + static_cast<int>(qy1 * static_cast<float>(scale)),
         rgb, 1.0f);
  }
  return band;
}

}  // namespace probecast::imaging
