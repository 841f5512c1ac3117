// Scene loading: the Cornell glTF (tests/data), built-in scenes, and broken files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "gltf_test_files.h"
#include "probecast/scene/scene.h"

namespace probecast::scene {
namespace {

const std::string kCornell = std::string(PROBECAST_TEST_DATA) + "/scenes/cornell-box/CornellBox-Original.gltf";

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = std::string(PROBECAST_TEST_TMP) + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(Scene, CornellGltfLoadsTrianglesMaterialsEmission) {
  Scene s;
  std::string error;
  ASSERT_TRUE(loadGltf(kCornell, s, error)) << error;
  // 8 meshes: floor, ceiling, back, right, left (2 triangles each), two boxes (10 each: 5 faces),
  // light (2) = 36 triangles, counted from the file's index accessors.
  EXPECT_EQ(s.triangleCount(), 36u);
  EXPECT_EQ(s.positions.size(), s.normals.size());
  int emissive = 0;
  for (uint32_t t = 0; t < s.triangleCount(); ++t) {
    const Material& m = s.materials[s.triangleMaterial[t]];
    if (m.emission.r > 0) {
      ++emissive;
      // emissiveFactor (1, 0.706, 0.235) × KHR_materials_emissive_strength 17.
      EXPECT_NEAR(m.emission.r, 17.0f, 1e-4f);
      EXPECT_NEAR(m.emission.g, 17.0f * 0.70588235f, 1e-3f);
      EXPECT_NEAR(m.emission.b, 17.0f * 0.23529412f, 1e-3f);
    }
    if (m.name == "leftWall") {
      EXPECT_NEAR(m.baseColor.r, 0.63f, 1e-6f);
    }
  }
  EXPECT_EQ(emissive, 2);
  // Interior x[-1, 1] y[0, 1.99] z[-1.04, 0.99] (CREDITS.md).
  EXPECT_NEAR(s.boundsMin.x, -1.0f, 0.05f);
  EXPECT_NEAR(s.boundsMax.y, 1.99f, 0.05f);
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_NEAR(s.cameras[0].position.z, 3.9f, 1e-4f);
  EXPECT_NEAR(s.cameras[0].forward.z, -1.0f, 1e-4f);
}

TEST(Scene, BuiltinCornellMovesItsLightWithT) {
  Scene a, b;
  std::string error;
  ASSERT_TRUE(makeBuiltinScene("cornell", 0.0f, a, error)) << error;
  ASSERT_TRUE(makeBuiltinScene("cornell", 0.25f, b, error)) << error;
  EXPECT_GT(a.triangleCount(), 20u);
  ASSERT_EQ(a.lights.size(), 1u);
  EXPECT_GT(glm::distance(a.lights[0].position, b.lights[0].position), 0.5f);
  EXPECT_EQ(a.positions, b.positions);  // only the light moves
  bool emissive = false;
  for (const Material& m : a.materials) emissive = emissive || m.emission.r > 0;
  EXPECT_TRUE(emissive);
  EXPECT_FALSE(makeBuiltinScene("atlantis", 0.0f, a, error));
  EXPECT_NE(error.find("atlantis"), std::string::npos);
}

TEST(Scene, TrianglesAreSpatiallySorted) {
  // After finalizeScene, consecutive triangles are near each other: the mean centroid step is
  // much smaller than for the order they were generated in.
  Scene s;
  std::string error;
  ASSERT_TRUE(makeBuiltinScene("cornell", 0.0f, s, error));
  auto centroid = [&](uint32_t t) {
    return (s.positions[s.indices[3 * t]] + s.positions[s.indices[3 * t + 1]] + s.positions[s.indices[3 * t + 2]]) / 3.0f;
  };
  float sorted = 0;
  for (uint32_t t = 1; t < s.triangleCount(); ++t) sorted += glm::distance(centroid(t), centroid(t - 1));
  std::vector<uint32_t> idx = s.indices;
  // Reverse pairs of halves: interleave the two halves to make a deliberately scattered order.
  const uint32_t n = s.triangleCount(), half = n / 2;
  for (uint32_t k = 0; k < half; ++k)
    for (int j = 0; j < 3; ++j) {
      s.indices[3 * (2 * k) + j] = idx[3 * k + j];
      s.indices[3 * (2 * k + 1) + j] = idx[3 * (half + k) + j];
    }
  float scattered = 0;
  for (uint32_t t = 1; t < 2 * half; ++t) scattered += glm::distance(centroid(t), centroid(t - 1));
  EXPECT_LT(sorted, scattered * 0.8f);
}

TEST(Scene, BrokenFilesFailWithClearMessages) {
  Scene s;
  std::string error;
  EXPECT_FALSE(loadScene("/nonexistent/scene.gltf", 0.0f, s, error));
  EXPECT_NE(error.find("/nonexistent/scene.gltf"), std::string::npos);

  const std::string junk = writeTemp("junk.gltf", "{ this is not json");
  EXPECT_FALSE(loadGltf(junk, s, error));
  EXPECT_NE(error.find("junk.gltf"), std::string::npos);

  const std::string empty = writeTemp("empty.gltf", R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0})");
  EXPECT_FALSE(loadGltf(empty, s, error));
  EXPECT_NE(error.find("no triangles"), std::string::npos) << error;

  const std::string required = writeTemp(
      "required.gltf", R"({"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_draco_mesh_compression"],
                           "extensionsRequired": ["KHR_draco_mesh_compression"]})");
  EXPECT_FALSE(loadGltf(required, s, error));
  EXPECT_NE(error.find("KHR_draco_mesh_compression"), std::string::npos) << error;

  // A triangle whose buffer is too short for its accessor.
  const std::string shortBuffer = writeTemp("short.gltf", R"({"asset": {"version": "2.0"},
      "buffers": [{"byteLength": 12, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAA"}],
      "bufferViews": [{"buffer": 0, "byteLength": 12}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
      "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})");
  EXPECT_FALSE(loadGltf(shortBuffer, s, error));
  EXPECT_FALSE(error.empty());
}

// A one-triangle glTF in `dir` whose buffer is `bufferUri` (36 bytes) and, when given, whose base
// colour texture is `imageUri`.
std::string triangleGltf(const std::filesystem::path& dir, const std::string& bufferUri, const std::string& imageUri = "") {
  std::filesystem::create_directories(dir);
  std::string json = R"({"asset":{"version":"2.0"},"buffers":[{"uri":")" + bufferUri + R"(","byteLength":36}],)"
                     R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
                     R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",)"
                     R"("min":[0,0,0],"max":[1,1,0]}],"materials":[{"pbrMetallicRoughness":{)";
  if (!imageUri.empty()) json += R"("baseColorTexture":{"index":0})";
  json += R"(}}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],)";
  if (!imageUri.empty()) json += R"("images":[{"uri":")" + imageUri + R"("}],"textures":[{"source":0}],)";
  json += R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
  const std::string path = (dir / "scene.gltf").string();
  test::writeFile(path, json);
  return path;
}

std::string triangleBytes() {
  const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  return std::string(reinterpret_cast<const char*>(p), sizeof p);
}

TEST(Scene, AGltfReadsOnlyInsideItsFolderAndAPackagedOneOnlyItsListedFiles) {
  namespace fs = std::filesystem;
  const fs::path root = fs::path(PROBECAST_TEST_TMP) / "gltf_files";
  fs::remove_all(root);
  fs::create_directories(root / "pkg");
  test::writeFile((root / "outside.bin").string(), triangleBytes());
  test::writeFile((root / "pkg" / "tri.bin").string(), triangleBytes());
  test::writeFile((root / "pkg" / "pixel.png").string(), test::pngFile(1, 1, 3, 8, {255, 0, 255}));
  Scene s;
  std::string error;
  const auto refused = [&](const std::string& gltf, const PackagedFiles* packaged = nullptr) {
    error.clear();
    EXPECT_FALSE(loadGltf(gltf, s, error, 0.0, packaged)) << gltf;
    return error;
  };
  // Outside the folder, however spelled: each refused by name, the file never read.
  EXPECT_NE(refused(triangleGltf(root / "pkg", "../outside.bin")).find("leaves the glTF's folder"), std::string::npos) << error;
  EXPECT_NE(refused(triangleGltf(root / "pkg", "%2E%2E/outside.bin")).find("leaves the glTF's folder"), std::string::npos) << error;
  EXPECT_NE(refused(triangleGltf(root / "pkg", (root / "outside.bin").string())).find("refused to read"), std::string::npos) << error;
  EXPECT_NE(refused(triangleGltf(root / "pkg", "file://" + (root / "outside.bin").string())).find("URI scheme"), std::string::npos) << error;
  EXPECT_NE(refused(triangleGltf(root / "pkg", "tri.bin", "../../pixel.png")).find("leaves the glTF's folder"), std::string::npos) << error;
  // Not in the folder: not looked for in the working folder either.
  const fs::path cwd = fs::current_path();
  fs::current_path(root);
  EXPECT_NE(refused(triangleGltf(root / "pkg", "outside.bin")).find("File not found"), std::string::npos) << error;
  fs::current_path(cwd);
  // Inside: loads, and a package's listed files load.
  const std::string inside = triangleGltf(root / "pkg", "tri.bin", "pixel.png");
  ASSERT_TRUE(loadGltf(inside, s, error)) << error;
  PackagedFiles listed{{"tri.bin", "pixel.png"}};
  ASSERT_TRUE(loadGltf(inside, s, error, 0.0, &listed)) << error;
  PackagedFiles bufferOnly{{"tri.bin"}};
  EXPECT_NE(refused(inside, &bufferOnly).find("'" + (root / "pkg" / "pixel.png").string() + "' is not a file of the scene's package"),
            std::string::npos) << error;
  // A listed file that is a link out of the package.
  fs::remove(root / "pkg" / "tri.bin");
  fs::create_symlink(root / "outside.bin", root / "pkg" / "tri.bin");
  EXPECT_NE(refused(inside, &listed).find("is a symbolic link"), std::string::npos) << error;
  EXPECT_TRUE(loadGltf(inside, s, error)) << error;  // a local scene's own link is its owner's choice
}

TEST(Scene, NanPositionsAreRejected) {
  // One triangle whose first x is NaN (bytes 00 00 c0 7f).
  Scene s;
  std::string error;
  const std::string nan = writeTemp("nan.gltf", R"({"asset": {"version": "2.0"},
      "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AADAfwAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
      "bufferViews": [{"buffer": 0, "byteLength": 36}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
      "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})");
  EXPECT_FALSE(loadGltf(nan, s, error));
  EXPECT_NE(error.find("NaN"), std::string::npos) << error;
}

}  // namespace
}  // namespace probecast::scene

namespace probecast::scene {
namespace {

TEST(Scene, TexturedGltfLoadsTexturesUvsAndNormals) {
  Scene s;
  std::string error;
  ASSERT_TRUE(loadGltf(std::string(PROBECAST_TEST_DATA) + "/scenes/cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf", s,
                       error))
      << error;
  EXPECT_EQ(s.textures.size(), 2u);  // checkerBJS.png and checker-meter.png
  ASSERT_EQ(s.texcoords.size(), s.positions.size());
  ASSERT_EQ(s.normals.size(), s.positions.size());
  int textured = 0;
  for (const Material& m : s.materials) textured += m.baseColorTexture >= 0 ? 1 : 0;
  EXPECT_EQ(textured, 2);  // bloc and cornellBox.ground
  for (const Texture& t : s.textures) {
    EXPECT_GT(t.width, 0u);
    EXPECT_EQ(t.rgba.size(), static_cast<size_t>(t.width) * t.height * 4);
  }
  for (const glm::vec3& n : s.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-3f);
  // Suzanne is smooth-shaded: some vertex normals differ from their triangle's face normal.
  int smooth = 0;
  for (uint32_t t = 0; t < s.triangleCount(); ++t) {
    const glm::vec3 a = s.positions[s.indices[3 * t]], b = s.positions[s.indices[3 * t + 1]],
                    c = s.positions[s.indices[3 * t + 2]];
    const glm::vec3 fn = glm::normalize(glm::cross(b - a, c - a));
    if (glm::dot(fn, s.normals[s.indices[3 * t]]) < 0.99f) ++smooth;
  }
  EXPECT_GT(smooth, 100);
}

// Three quads: Mask with cutoff 0.3 and a transformed texture read through TEXCOORD_1, Blend with
// alpha 0.4, and an opaque material with KHR_materials_transmission 0.8 — all extensions required.
TEST(Scene, AlphaModesTransmissionAndTextureTransformsAreLoaded) {
  const std::string dir = PROBECAST_TEST_TMP;
  test::writeFile(dir + "/mat_tex.png", test::pngFile(2, 2, 4, 8, std::vector<uint16_t>(16, 200)));
  std::vector<test::GltfQuad> quads(3);
  for (int q = 0; q < 3; ++q) {
    const float z = -static_cast<float>(q);
    quads[q].corners[0] = {0, 0, z}, quads[q].corners[1] = {1, 0, z}, quads[q].corners[2] = {1, 1, z};
    quads[q].corners[3] = {0, 1, z};
    quads[q].material = q;
  }
  const std::string materials =
      R"({"name":"mask","alphaMode":"MASK","alphaCutoff":0.3,"pbrMetallicRoughness":{"baseColorFactor":[1,1,1,0.9],)"
      R"("baseColorTexture":{"index":0,"extensions":{"KHR_texture_transform":)"
      R"({"offset":[0.25,0.5],"rotation":1.5707963,)"
      R"("scale":[2,3],"texCoord":1}}}}},)"
      R"({"name":"glass","alphaMode":"BLEND","pbrMetallicRoughness":{"baseColorFactor":[1,0,0,0.4]}},)"
      R"({"name":"thin","extensions":{"KHR_materials_transmission":{"transmissionFactor":0.8}}})";
  const std::string top =
      R"("extensionsUsed":["KHR_texture_transform","KHR_materials_transmission"],)"
      R"("extensionsRequired":["KHR_texture_transform","KHR_materials_transmission"],)";
  const std::string path = test::writeQuadGltf(dir, "materials", quads, materials, R"({"source":0})",
                                               R"({"uri":"mat_tex.png"})", top);
  Scene s;
  std::string error;
  ASSERT_TRUE(loadGltf(path, s, error)) << error;
  ASSERT_GE(s.materials.size(), 3u);
  const Material &mask = s.materials[0], &glass = s.materials[1], &thin = s.materials[2];
  EXPECT_EQ(mask.alphaMode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(mask.alphaCutoff, 0.3f);
  EXPECT_FLOAT_EQ(mask.alpha, 0.9f);
  EXPECT_GE(mask.baseColorTexture, 0);
  // translation(0.25, 0.5) × rotation(π/2) × scale(2, 3): rows (cos·2, sin·3, 0.25), (−sin·2, cos·3, 0.5).
  EXPECT_EQ(mask.baseColorTransform.texCoord, 1u);
  EXPECT_NEAR(mask.baseColorTransform.row0.x, 0.0f, 1e-6f);
  EXPECT_NEAR(mask.baseColorTransform.row0.y, 3.0f, 1e-6f);
  EXPECT_NEAR(mask.baseColorTransform.row0.z, 0.25f, 1e-6f);
  EXPECT_NEAR(mask.baseColorTransform.row1.x, -2.0f, 1e-6f);
  EXPECT_NEAR(mask.baseColorTransform.row1.y, 0.0f, 1e-6f);
  EXPECT_NEAR(mask.baseColorTransform.row1.z, 0.5f, 1e-6f);
  EXPECT_EQ(glass.alphaMode, AlphaMode::Blend);
  EXPECT_FLOAT_EQ(glass.alpha, 0.4f);
  EXPECT_TRUE(glass.transmissive());
  EXPECT_EQ(thin.alphaMode, AlphaMode::Opaque);
  EXPECT_FLOAT_EQ(thin.transmission, 0.8f);
  EXPECT_TRUE(thin.transmissive());
  ASSERT_EQ(s.texcoords1.size(), s.positions.size());
  // finalizeScene's order: the cut-out quad before the two transmissive ones, each one run.
  ASSERT_EQ(s.triangleCount(), 6u);
  EXPECT_EQ(leadingTrianglesBelowClass(s, 1), 0u);
  EXPECT_EQ(leadingTrianglesBelowClass(s, 2), 2u);
  for (uint32_t t = 2; t < 6; ++t) EXPECT_EQ(triangleClass(s, t), 2u);
}

TEST(Scene, MetallicRoughnessAndOcclusionTexturesAreReadWithTheirTransformsAndStrength) {
  const std::string dir = PROBECAST_TEST_TMP;
  test::writeFile(dir + "/mr.png", test::pngFile(1, 1, 3, 8, {255, 128, 0}));
  std::vector<test::GltfQuad> quads(1);
  quads[0].corners[0] = {0, 0, 0}, quads[0].corners[1] = {1, 0, 0}, quads[0].corners[2] = {1, 1, 0};
  quads[0].corners[3] = {0, 1, 0};
  const std::string path = test::writeQuadGltf(
      dir, "mr", quads,
      R"({"pbrMetallicRoughness":{"metallicFactor":0.5,"roughnessFactor":0.25,)"
      R"("metallicRoughnessTexture":{"index":0,"texCoord":1}},"occlusionTexture":{"index":0,"strength":0.7,)"
      R"("extensions":{"KHR_texture_transform":{"offset":[0.5,0]}}}})",
      R"({"source":0})", R"({"uri":"mr.png"})", R"("extensionsUsed":["KHR_texture_transform"],)");
  Scene s;
  std::string error;
  ASSERT_TRUE(loadGltf(path, s, error)) << error;
  const Material& m = s.materials[0];
  EXPECT_FLOAT_EQ(m.metallic, 0.5f);
  EXPECT_FLOAT_EQ(m.roughness, 0.25f);
  ASSERT_GE(m.metallicRoughnessTexture, 0);
  EXPECT_EQ(m.metallicRoughnessTransform.texCoord, 1u);
  EXPECT_EQ(m.occlusionTexture, m.metallicRoughnessTexture);  // one image, converted once
  EXPECT_FLOAT_EQ(m.occlusionStrength, 0.7f);
  EXPECT_FLOAT_EQ(m.occlusionTransform.row0.z, 0.5f);
  const Texture& t = s.textures[m.metallicRoughnessTexture];
  EXPECT_EQ(std::vector<uint8_t>(t.rgba.begin(), t.rgba.end()), (std::vector<uint8_t>{255, 128, 0, 255}));
}

TEST(Scene, SixteenBitPngIsReadAsItsTopEightBitsRounded) {
  // RGBA16 texels: 0x8080 → 128, 0xffff → 255, 0x4000 → round(16384 · 255 / 65535) = 64, 0 → 0;
  // a 16-bit grey + alpha image expands grey to RGB.
  const std::string dir = PROBECAST_TEST_TMP;
  test::writeFile(dir + "/rgba16.png", test::pngFile(2, 1, 4, 16, {0x8080, 0xffff, 0x4000, 0xffff,  //
                                                                  0, 0x4000, 0xffff, 0x8080}));
  test::writeFile(dir + "/ga16.png", test::pngFile(1, 1, 2, 16, {0x4000, 0xffff}));
  std::vector<test::GltfQuad> quads(1);
  quads[0].corners[0] = {0, 0, 0}, quads[0].corners[1] = {1, 0, 0}, quads[0].corners[2] = {1, 1, 0};
  quads[0].corners[3] = {0, 1, 0};
  const std::string path = test::writeQuadGltf(
      dir, "png16", quads,
      R"({"pbrMetallicRoughness":{"baseColorTexture":{"index":0}},)"
      R"("emissiveTexture":{"index":1},"emissiveFactor":[1,1,1]})",
      R"({"source":0},{"source":1})", R"({"uri":"rgba16.png"},{"uri":"ga16.png"})");
  Scene s;
  std::string error;
  ASSERT_TRUE(loadGltf(path, s, error)) << error;
  ASSERT_GE(s.materials[0].baseColorTexture, 0) << "16-bit PNG not loaded";
  ASSERT_GE(s.materials[0].emissiveTexture, 0);
  const Texture& rgba = s.textures[s.materials[0].baseColorTexture];
  ASSERT_EQ(rgba.width, 2u);
  const std::vector<uint8_t> expected = {128, 255, 64, 255, 0, 64, 255, 128};
  EXPECT_EQ(rgba.rgba, expected);
  const Texture& ga = s.textures[s.materials[0].emissiveTexture];
  EXPECT_EQ(ga.rgba, (std::vector<uint8_t>{64, 64, 64, 255}));
}

TEST(Scene, UnknownRequiredExtensionIsStillRefused) {
  std::vector<test::GltfQuad> quads(1);
  quads[0].corners[0] = {0, 0, 0}, quads[0].corners[1] = {1, 0, 0}, quads[0].corners[2] = {1, 1, 0};
  quads[0].corners[3] = {0, 1, 0};
  const std::string path = test::writeQuadGltf(PROBECAST_TEST_TMP, "required", quads, "{}", "", "",
                                               R"("extensionsUsed":["KHR_materials_volume"],)"
                                               R"("extensionsRequired":["KHR_materials_volume"],)");
  Scene s;
  std::string error;
  EXPECT_FALSE(loadGltf(path, s, error));
  EXPECT_NE(error.find("KHR_materials_volume"), std::string::npos) << error;
}

}  // namespace
}  // namespace probecast::scene
