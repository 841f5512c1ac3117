// Tiny glTF files written by tests: quads with two UV sets in one .bin, materials/textures/images
// given as JSON text, and PNG images (8 or 16 bits per sample, stored deflate) written beside them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace probecast::test {

inline uint32_t pngCrc(const std::string& bytes, size_t begin) {
  uint32_t c = 0xffffffffu;
  for (size_t i = begin; i < bytes.size(); ++i) {
    c ^= static_cast<uint8_t>(bytes[i]);
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

inline void putBigEndian(std::string& out, uint32_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

// A PNG of `channels` (1 grey, 2 grey + alpha, 3 RGB, 4 RGBA) samples of `bits` (8 or 16) per
// pixel, rows top first; the zlib stream holds stored (uncompressed) deflate blocks.
inline std::string pngFile(uint32_t width, uint32_t height, int channels, int bits,
                           const std::vector<uint16_t>& samples) {
  std::string raw;
  for (uint32_t y = 0; y < height; ++y) {
    raw.push_back(0);  // filter: none
    for (uint32_t i = 0; i < width * static_cast<uint32_t>(channels); ++i)
      putBigEndian(raw, samples[static_cast<size_t>(y) * width * channels + i], bits / 8);
  }
  std::string z = {0x78, 0x01};
  for (size_t at = 0; at < raw.size() || at == 0; at += 65535) {
    const size_t n = std::min<size_t>(65535, raw.size() - at);
    z.push_back(at + n >= raw.size() ? 1 : 0);
    z.push_back(static_cast<char>(n & 0xff));
    z.push_back(static_cast<char>(n >> 8));
    z.push_back(static_cast<char>(~n & 0xff));
    z.push_back(static_cast<char>((~n >> 8) & 0xff));
    z.append(raw, at, n);
    if (raw.empty()) break;
  }
  uint32_t a = 1, b = 0;
  for (char c : raw) {
    a = (a + static_cast<uint8_t>(c)) % 65521u;
    b = (b + a) % 65521u;
  }
  putBigEndian(z, (b << 16) | a, 4);
  std::string png = "\x89PNG\r\n\x1a\n";
  const auto chunk = [&](const char* type, const std::string& data) {
    putBigEndian(png, static_cast<uint32_t>(data.size()), 4);
    const size_t begin = png.size();
    png += type;
    png += data;
    putBigEndian(png, pngCrc(png, begin), 4);
  };
  std::string ihdr;
  putBigEndian(ihdr, width, 4);
  putBigEndian(ihdr, height, 4);
  const int colorType[5] = {0, 0, 4, 2, 6};
  ihdr += {static_cast<char>(bits), static_cast<char>(colorType[channels]), 0, 0, 0};
  chunk("IHDR", ihdr);
  chunk("IDAT", z);
  chunk("IEND", "");
  return png;
}

inline void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

struct GltfQuad {
  glm::vec3 corners[4];  // counter-clockwise seen from the front
  glm::vec2 uv0[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  glm::vec2 uv1[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  int material = 0;
};

// Writes `dir/name.gltf` + `dir/name.bin`: one mesh node per quad (POSITION, TEXCOORD_0,
// TEXCOORD_1, indices). `materials`, `textures`, `images`: JSON array bodies (without brackets);
// `top`: extra top-level members, e.g. "\"extensionsRequired\": [...],". Returns the .gltf path.
inline std::string writeQuadGltf(const std::string& dir, const std::string& name, const std::vector<GltfQuad>& quads,
                                 const std::string& materials, const std::string& textures = "",
                                 const std::string& images = "", const std::string& top = "") {
  std::string bin;
  const auto putFloat = [&](float f) { bin.append(reinterpret_cast<const char*>(&f), 4); };
  std::string accessors, meshes, nodes, views;
  int view = 0;
  for (size_t q = 0; q < quads.size(); ++q) {
    const GltfQuad& quad = quads[q];
    const size_t pos = bin.size();
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const glm::vec3& c : quad.corners) {
      for (int k = 0; k < 3; ++k) putFloat(c[k]);
      lo = glm::min(lo, c);
      hi = glm::max(hi, c);
    }
    const size_t uv0 = bin.size();
    for (const glm::vec2& t : quad.uv0) putFloat(t.x), putFloat(t.y);
    const size_t uv1 = bin.size();
    for (const glm::vec2& t : quad.uv1) putFloat(t.x), putFloat(t.y);
    const size_t idx = bin.size();
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) bin.append(reinterpret_cast<const char*>(&i), 4);
    const auto addView = [&](size_t offset, size_t length) {
      views += (view ? "," : "") + std::string("{\"buffer\":0,\"byteOffset\":") + std::to_string(offset) +
               ",\"byteLength\":" + std::to_string(length) + "}";
      return view++;
    };
    const int a0 = static_cast<int>(q) * 4;
    accessors += (q ? "," : "") + std::string("{\"bufferView\":") + std::to_string(addView(pos, 48)) +
                 ",\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[" + std::to_string(lo.x) + "," +
                 std::to_string(lo.y) + "," + std::to_string(lo.z) + "],\"max\":[" + std::to_string(hi.x) + "," +
                 std::to_string(hi.y) + "," + std::to_string(hi.z) + "]}";
    accessors += ",{\"bufferView\":" + std::to_string(addView(uv0, 32)) +
                 ",\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"}";
    accessors += ",{\"bufferView\":" + std::to_string(addView(uv1, 32)) +
                 ",\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"}";
    accessors += ",{\"bufferView\":" + std::to_string(addView(idx, 24)) +
                 ",\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"}";
    meshes += (q ? "," : "") + std::string("{\"primitives\":[{\"attributes\":{\"POSITION\":") + std::to_string(a0) +
              ",\"TEXCOORD_0\":" + std::to_string(a0 + 1) + ",\"TEXCOORD_1\":" + std::to_string(a0 + 2) +
              "},\"indices\":" + std::to_string(a0 + 3) + ",\"material\":" + std::to_string(quad.material) + "}]}";
    nodes += (q ? "," : "") + std::string("{\"mesh\":") + std::to_string(q) + "}";
  }
  std::string sceneNodes;
  for (size_t q = 0; q < quads.size(); ++q) sceneNodes += (q ? "," : "") + std::to_string(q);
  std::string json = "{\"asset\":{\"version\":\"2.0\"}," + top + "\"scene\":0,\"scenes\":[{\"nodes\":[" + sceneNodes +
                     "]}],\"nodes\":[" + nodes + "],\"meshes\":[" + meshes + "],\"materials\":[" + materials + "]," +
                     (textures.empty() ? "" : "\"textures\":[" + textures + "],") +
                     (images.empty() ? "" : "\"images\":[" + images + "],") + "\"accessors\":[" + accessors +
                     "],\"bufferViews\":[" + views + "],\"buffers\":[{\"uri\":\"" + name +
                     ".bin\",\"byteLength\":" + std::to_string(bin.size()) + "}]}";
  writeFile(dir + "/" + name + ".bin", bin);
  writeFile(dir + "/" + name + ".gltf", json);
  return dir + "/" + name + ".gltf";
}

}  // namespace probecast::test
