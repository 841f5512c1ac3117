// EXR through OpenEXR: every compression written by OpenEXR itself reads back through readExr
// (exact for the lossless ones, within a stated tolerance for the lossy ones), channel layouts,
// data windows, and corrupt or truncated files give an error naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfRgbaFile.h>
#include <ImfTileDescription.h>
#include <ImfTiledOutputFile.h>

#include "exr_test_files.h"
#include "probecast/imaging/image_io.h"

namespace probecast::imaging {
namespace {

using probecast::testing::ExrCompressionCase;
using probecast::testing::exrCompressionCases;
using probecast::testing::exrTestImage;
using probecast::testing::roundToHalf;
using probecast::testing::writeTestExr;

std::string tmpPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("probecast_image_io_" + name)).string();
}

// Largest |a − b| / max(1, |b|).
float maxRelError(const std::vector<float>& a, const std::vector<float>& b) {
  float worst = 0.0f;
  for (size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, std::fabs(a[i] - b[i]) / std::max(1.0f, std::fabs(b[i])));
  return worst;
}

std::vector<char> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const std::string& path, const std::vector<char>& bytes, size_t count) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(count));
}

TEST(ImageIo, EveryCompressionReadsBack) {
  const int w = 37, h = 19;  // not a multiple of any block size (B44 4×4, DWA 8×8, PIZ 32 lines)
  const std::vector<float> image = exrTestImage(w, h);
  for (const ExrCompressionCase& c : exrCompressionCases()) {
    SCOPED_TRACE(c.name);
    const std::string path = tmpPath(std::string(c.name) + ".exr");
    writeTestExr(path, image, w, h, c.compression, c.half);
    std::vector<float> rgb;
    int rw = 0, rh = 0;
    std::string error;
    ASSERT_TRUE(readExr(path, rgb, rw, rh, error)) << error;
    ASSERT_EQ(rw, w);
    ASSERT_EQ(rh, h);
    const std::vector<float> stored = c.half ? roundToHalf(image) : image;
    if (c.tolerance == 0.0f)
      EXPECT_EQ(rgb, stored);
    else
      EXPECT_LE(maxRelError(rgb, stored), c.tolerance);
    std::filesystem::remove(path);
  }
}

TEST(ImageIo, WriteReadRoundTripIsExactAndZipCompressed) {
  const int w = 40, h = 20;
  std::vector<float> image = exrTestImage(w, h);
  image[5] = 1e-30f;  // float, not half: values half cannot hold survive
  image[6] = 70000.0f;
  const std::string path = tmpPath("roundtrip.exr");
  std::string error;
  ASSERT_TRUE(writeExr(path, image, w, h, error)) << error;
  std::vector<float> rgb;
  int rw = 0, rh = 0;
  ASSERT_TRUE(readExr(path, rgb, rw, rh, error)) << error;
  EXPECT_EQ(rw, w);
  EXPECT_EQ(rh, h);
  EXPECT_EQ(rgb, image);
  // ZIP: the smooth image takes well under its raw 40·20·12 = 9600 bytes.
  EXPECT_LT(std::filesystem::file_size(path), 9600u);
  std::filesystem::remove(path);
}

TEST(ImageIo, TiledFilesRead) {
  // A tiled (one level, 16×16 tiles), PIZ-compressed float file: same pixels as written.
  const int w = 37, h = 19;
  const std::vector<float> image = exrTestImage(w, h);
  const std::string path = tmpPath("tiled.exr");
  Imf::Header header(w, h);
  header.compression() = Imf::PIZ_COMPRESSION;
  header.setTileDescription(Imf::TileDescription(16, 16, Imf::ONE_LEVEL));
  Imf::FrameBuffer fb;
  const char* names[3] = {"R", "G", "B"};
  char* base = reinterpret_cast<char*>(const_cast<float*>(image.data()));
  for (int c = 0; c < 3; ++c) {
    header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 3 * sizeof(float), 3 * sizeof(float) * w));
  }
  {
    Imf::TiledOutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writeTiles(0, file.numXTiles() - 1, 0, file.numYTiles() - 1);
  }
  std::vector<float> rgb;
  int rw = 0, rh = 0;
  std::string error;
  ASSERT_TRUE(readExr(path, rgb, rw, rh, error)) << error;
  EXPECT_EQ(rw, w);
  EXPECT_EQ(rh, h);
  EXPECT_EQ(rgb, image);
  std::filesystem::remove(path);
}

TEST(ImageIo, LuminanceOnlyReadsAsGrey) {
  const int w = 16, h = 8;
  const std::vector<float> image = exrTestImage(w, h);
  const std::string path = tmpPath("y.exr");
  writeTestExr(path, image, w, h, Imf::ZIP_COMPRESSION, false, /*luminanceOnly=*/true);
  std::vector<float> rgb;
  int rw = 0, rh = 0;
  std::string error;
  ASSERT_TRUE(readExr(path, rgb, rw, rh, error)) << error;
  ASSERT_EQ(rgb.size(), image.size());
  for (size_t i = 0; i < rgb.size() / 3; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(rgb[i * 3 + c], image[i * 3]) << i;  // Y was written from R
  std::filesystem::remove(path);
}

TEST(ImageIo, LuminanceChromaReadsAsRgb) {
  // Y/RY/BY (chroma subsampled 2×2, half): a grey ramp comes back grey, within half precision and
  // the YC round trip (1 %).
  const int w = 16, h = 8;
  std::vector<Imf::Rgba> pixels(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float v = 0.1f + 0.2f * static_cast<float>(x + y);
      pixels[static_cast<size_t>(y) * w + x] = Imf::Rgba(v, v, v, 1.0f);
    }
  const std::string path = tmpPath("yc.exr");
  {
    Imf::RgbaOutputFile file(path.c_str(), w, h, Imf::WRITE_YC);
    file.setFrameBuffer(pixels.data(), 1, static_cast<size_t>(w));
    file.writePixels(h);
  }
  std::vector<float> rgb;
  int rw = 0, rh = 0;
  std::string error;
  ASSERT_TRUE(readExr(path, rgb, rw, rh, error)) << error;
  ASSERT_EQ(rgb.size(), pixels.size() * 3);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const float v = static_cast<float>(pixels[i].r);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[i * 3 + c], v, 0.01f * v) << i;
  }
  std::filesystem::remove(path);
}

TEST(ImageIo, AlphaIsIgnored) {
  const int w = 16, h = 8;
  const std::vector<float> image = exrTestImage(w, h);
  const std::string path = tmpPath("rgba.exr");
  writeTestExr(path, image, w, h, Imf::PIZ_COMPRESSION, true, false, /*withAlpha=*/true);
  std::vector<float> rgb;
  int rw = 0, rh = 0;
  std::string error;
  ASSERT_TRUE(readExr(path, rgb, rw, rh, error)) << error;
  EXPECT_EQ(rgb, roundToHalf(image));
  std::filesystem::remove(path);
}

TEST(ImageIo, DataWindowIsPlacedInTheDisplayWindow) {
  // Data window shifted by (3, 2) inside an equally sized display window: the first 3 columns
  // and 2 rows are black, the data's last columns and rows fall outside and are dropped.
  const int w = 12, h = 6, dx = 3, dy = 2;
  const std::vector<float> image = exrTestImage(w, h);
  const std::string path = tmpPath("window.exr");
  writeTestExr(path, image, w, h, Imf::ZIP_COMPRESSION, false, false, false, dx, dy);
  std::vector<float> rgb;
  int rw = 0, rh = 0;
  std::string error;
  ASSERT_TRUE(readExr(path, rgb, rw, rh, error)) << error;
  ASSERT_EQ(rw, w);
  ASSERT_EQ(rh, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        const float expected = (x < dx || y < dy) ? 0.0f : image[(static_cast<size_t>(y - dy) * w + (x - dx)) * 3 + c];
        EXPECT_EQ(rgb[(static_cast<size_t>(y) * w + x) * 3 + c], expected) << x << "," << y;
      }
  std::filesystem::remove(path);
}

TEST(ImageIo, MissingNotExrAndTruncatedFilesFailNamingTheFile) {
  std::vector<float> rgb;
  int w = 0, h = 0;
  std::string error;
  EXPECT_FALSE(readExr("/nonexistent/x.exr", rgb, w, h, error));
  EXPECT_NE(error.find("/nonexistent/x.exr"), std::string::npos) << error;

  const std::string bad = tmpPath("not_an.exr");
  writeBytes(bad, std::vector<char>(64, 'x'), 64);
  error.clear();
  EXPECT_FALSE(readExr(bad, rgb, w, h, error));
  EXPECT_NE(error.find(bad), std::string::npos) << error;
  std::filesystem::remove(bad);

  // Every compression, truncated at many lengths: false with the file's name, never a crash.
  const std::vector<float> image = exrTestImage(24, 12);
  for (const ExrCompressionCase& c : exrCompressionCases()) {
    SCOPED_TRACE(c.name);
    const std::string path = tmpPath(std::string("trunc_") + c.name + ".exr");
    writeTestExr(path, image, 24, 12, c.compression, c.half);
    const std::vector<char> bytes = readBytes(path);
    const std::string cut = tmpPath(std::string("cut_") + c.name + ".exr");
    for (size_t n = 0; n < bytes.size(); n += 1 + bytes.size() / 41) {
      writeBytes(cut, bytes, n);
      error.clear();
      EXPECT_FALSE(readExr(cut, rgb, w, h, error)) << n;
      EXPECT_NE(error.find(cut), std::string::npos) << error;
    }
    std::filesystem::remove(cut);
    std::filesystem::remove(path);
  }
}

TEST(ImageIo, CorruptBytesNeverCrash) {
  // Single-byte corruptions anywhere in a ZIP and a PIZ file: either an error naming the file or
  // an image of the header's size.
  const std::vector<float> image = exrTestImage(24, 12);
  for (int compression : {int{Imf::ZIP_COMPRESSION}, int{Imf::PIZ_COMPRESSION}}) {
    const std::string path = tmpPath("corrupt_src.exr");
    writeTestExr(path, image, 24, 12, compression, false);
    const std::vector<char> bytes = readBytes(path);
    const std::string bad = tmpPath("corrupt.exr");
    for (size_t i = 0; i < bytes.size(); i += 5) {
      std::vector<char> copy = bytes;
      copy[i] = static_cast<char>(copy[i] ^ 0x5a);
      writeBytes(bad, copy, copy.size());
      std::vector<float> rgb;
      int w = 0, h = 0;
      std::string error;
      if (readExr(bad, rgb, w, h, error))
        EXPECT_EQ(rgb.size(), static_cast<size_t>(w) * h * 3);
      else
        EXPECT_NE(error.find(bad), std::string::npos) << error;
    }
    std::filesystem::remove(bad);
    std::filesystem::remove(path);
  }
}

TEST(ImageIo, WriteRefusesSizeMismatch) {
  std::string error;
  EXPECT_FALSE(writeExr(tmpPath("mismatch.exr"), std::vector<float>(5), 2, 2, error));
  EXPECT_NE(error.find("mismatch.exr"), std::string::npos);
}

}  // namespace
}  // namespace probecast::imaging
