#include "probecast/imaging/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfRgbaFile.h>
#include <stb_image.h>
#include <stb_image_write.h>

namespace probecast::imaging {

namespace {

// Larger images are refused before anything is allocated (a header is untrusted input).
constexpr int64_t kMaxExrPixels = int64_t{1} << 28;

// Copies the data window (dw, `src`: rgb floats) into the display window (`rgb`), black where the
// data window has no pixels.
void cropToDisplayWindow(const Imath::Box2i& dw, const Imath::Box2i& disp, const std::vector<float>& src,
                         std::vector<float>& rgb) {
  const int64_t dataW = int64_t{dw.max.x} - dw.min.x + 1;
  const int64_t dispW = int64_t{disp.max.x} - disp.min.x + 1;
  const int x0 = std::max(dw.min.x, disp.min.x), x1 = std::min(dw.max.x, disp.max.x);
  const int y0 = std::max(dw.min.y, disp.min.y), y1 = std::min(dw.max.y, disp.max.y);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x)
      for (int c = 0; c < 3; ++c)
        rgb[static_cast<size_t>(((int64_t{y} - disp.min.y) * dispW + (int64_t{x} - disp.min.x)) * 3 + c)] =
            src[static_cast<size_t>(((int64_t{y} - dw.min.y) * dataW + (int64_t{x} - dw.min.x)) * 3 + c)];
}

// Reads the data window of `file` as rgb floats: R, G, B (a missing one reads 0), or Y as grey.
// Luminance/chroma files (Y, RY, BY: half by definition) go through the RGBA interface.
bool readDataWindow(const std::string& path, Imf::InputFile& file, const Imath::Box2i& dw, size_t pixels,
                    std::vector<float>& src, std::string& error) {
  const Imf::ChannelList& channels = file.header().channels();
  const bool hasRgb = channels.findChannel("R") || channels.findChannel("G") || channels.findChannel("B");
  const bool hasY = channels.findChannel("Y") != nullptr;
  const bool hasChroma = channels.findChannel("RY") || channels.findChannel("BY");
  if (!hasRgb && !hasY) return error = path + ": EXR has no R, G, B or Y channel", false;
  src.assign(pixels * 3, 0.0f);
  const int64_t dataW = int64_t{dw.max.x} - dw.min.x + 1;
  // FrameBuffer slices are addressed by absolute pixel coordinates: shift the base pointer.
  char* base = reinterpret_cast<char*>(src.data()) -
               (int64_t{dw.min.y} * dataW + dw.min.x) * static_cast<int64_t>(3 * sizeof(float));
  const size_t xStride = 3 * sizeof(float), yStride = static_cast<size_t>(dataW) * xStride;
  if (hasRgb) {
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xStride, yStride, 1, 1, 0.0));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
  } else if (!hasChroma) {
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice(Imf::FLOAT, base, xStride, yStride, 1, 1, 0.0));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    for (size_t i = 0; i < pixels; ++i) src[i * 3 + 1] = src[i * 3 + 2] = src[i * 3];
  } else {
    Imf::RgbaInputFile rgbaFile(path.c_str());
    std::vector<Imf::Rgba> rgba(pixels);
    rgbaFile.setFrameBuffer(rgba.data() - int64_t{dw.min.y} * dataW - dw.min.x, 1, static_cast<size_t>(dataW));
    rgbaFile.readPixels(dw.min.y, dw.max.y);
    for (size_t i = 0; i < pixels; ++i) {
      src[i * 3] = rgba[i].r;
      src[i * 3 + 1] = rgba[i].g;
      src[i * 3 + 2] = rgba[i].b;
    }
  }
  return true;
}

}  // namespace

bool writeExr(const std::string& path, const std::vector<float>& rgb, int width, int height, std::string& error) {
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<size_t>(width) * height * 3)
    return error = path + ": image size mismatch", false;
  try {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(const_cast<float*>(rgb.data()));
    const size_t xStride = 3 * sizeof(float), yStride = static_cast<size_t>(width) * xStride;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
      header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xStride, yStride));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(height);
  } catch (const std::exception& e) {
    return error = path + ": cannot write EXR (" + e.what() + ")", false;
  }
  return true;
}

bool readExr(const std::string& path, std::vector<float>& rgb, int& width, int& height, std::string& error) {
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const Imath::Box2i disp = file.header().displayWindow();
    const int64_t dataW = int64_t{dw.max.x} - dw.min.x + 1, dataH = int64_t{dw.max.y} - dw.min.y + 1;
    const int64_t dispW = int64_t{disp.max.x} - disp.min.x + 1, dispH = int64_t{disp.max.y} - disp.min.y + 1;
    if (dataW <= 0 || dataH <= 0 || dispW <= 0 || dispH <= 0)
      return error = path + ": EXR has an empty data or display window", false;
    if (dataW * dataH > kMaxExrPixels || dispW * dispH > kMaxExrPixels)
      return error = path + ": EXR is too large", false;
    std::vector<float> src;
    if (!readDataWindow(path, file, dw, static_cast<size_t>(dataW * dataH), src, error)) return false;
    if (dw == disp) {
      rgb = std::move(src);
    } else {
      rgb.assign(static_cast<size_t>(dispW * dispH) * 3, 0.0f);
      cropToDisplayWindow(dw, disp, src, rgb);
    }
    width = static_cast<int>(dispW);
    height = static_cast<int>(dispH);
  } catch (const std::exception& e) {
    return error = path + ": cannot read EXR (" + e.what() + ")", false;
  }
  return true;
}

bool readHdr(const std::string& path, std::vector<float>& rgb, int& width, int& height, std::string& error) {
  int channels = 0;
  float* data = stbi_loadf(path.c_str(), &width, &height, &channels, 3);
  if (!data) {
    error = path + ": cannot read Radiance HDR (" + (stbi_failure_reason() ? stbi_failure_reason() : "unknown") + ")";
    return false;
  }
  rgb.assign(data, data + static_cast<size_t>(width) * height * 3);
  stbi_image_free(data);
  return true;
}

bool parseToneMap(const std::string& name, ToneMap& out) {
  if (name == "filmic") out = ToneMap::Filmic;
  else if (name == "gamma") out = ToneMap::Gamma;
  else return false;
  return true;
}

namespace {
uint8_t toneMapped(float x, float exposure, ToneMap toneMap) {
  float v = std::isfinite(x) ? std::max(0.0f, x * exposure) : 0.0f;
  if (toneMap == ToneMap::Filmic) v = v * (2.51f * v + 0.03f) / (v * (2.43f * v + 0.59f) + 0.14f);
  return static_cast<uint8_t>(std::lround(255.0f * std::min(1.0f, std::pow(v, 1.0f / 2.2f))));
}
}  // namespace

std::vector<unsigned char> toneMapRgba8(const std::vector<float>& rgb, float exposure, ToneMap toneMap) {
  std::vector<unsigned char> out(rgb.size() / 3 * 4, 255);
  for (size_t p = 0; p < rgb.size() / 3; ++p)
    for (size_t c = 0; c < 3; ++c) out[p * 4 + c] = toneMapped(rgb[p * 3 + c], exposure, toneMap);
  return out;
}

bool writePngRgba(const std::string& path, const std::vector<unsigned char>& rgba, int width, int height,
                  std::string& error) {
  if (rgba.size() != static_cast<size_t>(width) * static_cast<size_t>(height) * 4)
    return error = path + ": RGBA image of the wrong size", false;
  std::vector<uint8_t> rgb(rgba.size() / 4 * 3);
  for (size_t p = 0; p < rgba.size() / 4; ++p)
    for (size_t c = 0; c < 3; ++c) rgb[p * 3 + c] = rgba[p * 4 + c];
  if (!stbi_write_png(path.c_str(), width, height, 3, rgb.data(), width * 3))
    return error = path + ": cannot write PNG", false;
  return true;
}

bool writePngPreview(const std::string& path, const std::vector<float>& rgb, int width, int height, float exposure,
                     std::string& error, ToneMap toneMap) {
  std::vector<uint8_t> bytes(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) bytes[i] = toneMapped(rgb[i], exposure, toneMap);
  if (!stbi_write_png(path.c_str(), width, height, 3, bytes.data(), width * 3))
    return error = path + ": cannot write PNG", false;
  return true;
}

}  // namespace probecast::imaging
