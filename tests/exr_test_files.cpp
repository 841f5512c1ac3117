#include "exr_test_files.h"

#include <cmath>

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <half.h>

namespace probecast::testing {

const std::vector<ExrCompressionCase>& exrCompressionCases() {
  // Lossy tolerances: about twice the worst error measured on exrTestImage (37×19 and 64×32), relative
  // to the half-rounded values: B44/B44A 0.045 (at the bright patch's edges), DWAA/DWAB 0.019 (default
  // level 45); PXR24 keeps 15 of float's 23 mantissa bits (≤ 2⁻¹⁶ after rounding, 1.3e-5 measured).
  static const std::vector<ExrCompressionCase> cases = {
      {"NO", Imf::NO_COMPRESSION, false, 0.0f},       {"RLE", Imf::RLE_COMPRESSION, false, 0.0f},
      {"ZIPS", Imf::ZIPS_COMPRESSION, false, 0.0f},   {"ZIP", Imf::ZIP_COMPRESSION, false, 0.0f},
      {"PIZ", Imf::PIZ_COMPRESSION, false, 0.0f},     {"PXR24", Imf::PXR24_COMPRESSION, false, 1e-4f},
      {"B44", Imf::B44_COMPRESSION, true, 0.1f},      {"B44A", Imf::B44A_COMPRESSION, true, 0.1f},
      {"DWAA", Imf::DWAA_COMPRESSION, true, 0.04f},   {"DWAB", Imf::DWAB_COMPRESSION, true, 0.04f},
  };
  return cases;
}

std::vector<float> exrTestImage(int width, int height) {
  std::vector<float> rgb(static_cast<size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float u = (static_cast<float>(x) + 0.5f) / static_cast<float>(width);
      const float v = (static_cast<float>(y) + 0.5f) / static_cast<float>(height);
      float* p = &rgb[(static_cast<size_t>(y) * width + x) * 3];
      p[0] = 0.05f + 2.0f * u * u;
      p[1] = 0.01f + 1.5f * v;
      p[2] = 0.2f + 0.8f * (0.5f + 0.5f * std::sin(6.0f * u + 3.0f * v));
      if (x >= width / 2 && y < height / 3) p[0] = p[1] = p[2] = 6.0f;  // a bright patch with sharp edges
    }
  return rgb;
}

std::vector<float> roundToHalf(const std::vector<float>& rgb) {
  std::vector<float> out(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) out[i] = static_cast<float>(half(rgb[i]));
  return out;
}

void writeTestExr(const std::string& path, const std::vector<float>& rgb, int width, int height, int compression,
                  bool halfPixels, bool luminanceOnly, bool withAlpha, int dataX, int dataY) {
  const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(width - 1, height - 1));
  const Imath::Box2i data(Imath::V2i(dataX, dataY), Imath::V2i(dataX + width - 1, dataY + height - 1));
  Imf::Header header(display, data);
  header.compression() = static_cast<Imf::Compression>(compression);
  const Imf::PixelType type = halfPixels ? Imf::HALF : Imf::FLOAT;
  const size_t pixels = static_cast<size_t>(width) * height;
  std::vector<float> floats;
  std::vector<half> halves;
  if (halfPixels) {
    halves.resize(rgb.size());
    for (size_t i = 0; i < rgb.size(); ++i) halves[i] = half(rgb[i]);
  }
  std::vector<float> alphaF(pixels, 1.0f);
  std::vector<half> alphaH(pixels, half(1.0f));
  const size_t elem = halfPixels ? sizeof(half) : sizeof(float);
  char* base = halfPixels ? reinterpret_cast<char*>(halves.data())
                          : reinterpret_cast<char*>(const_cast<float*>(rgb.data()));
  const ptrdiff_t origin = (static_cast<ptrdiff_t>(dataY) * width + dataX) * static_cast<ptrdiff_t>(3 * elem);
  base -= origin;
  Imf::FrameBuffer fb;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < (luminanceOnly ? 1 : 3); ++c) {
    const char* name = luminanceOnly ? "Y" : names[c];
    header.channels().insert(name, Imf::Channel(type));
    fb.insert(name, Imf::Slice(type, base + c * elem, 3 * elem, 3 * elem * width));
  }
  if (withAlpha) {
    header.channels().insert("A", Imf::Channel(type));
    char* a = halfPixels ? reinterpret_cast<char*>(alphaH.data()) : reinterpret_cast<char*>(alphaF.data());
    a -= (static_cast<ptrdiff_t>(dataY) * width + dataX) * static_cast<ptrdiff_t>(elem);
    fb.insert("A", Imf::Slice(type, a, elem, elem * width));
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(fb);
  file.writePixels(height);
}

}  // namespace probecast::testing
