// Scene identity and delivery. A scene package is what a viewer needs to draw the world a probe
// stream was traced in: the scene (a built-in's name, or a glTF file with every buffer and image it
// uses) and the distant light around it (an environment map with its intensity and rotation, or a
// uniform sky). Its manifest is canonical JSON naming each file with its size and SHA-256; the
// package's hash is the SHA-256 of the manifest, so one changed byte anywhere changes it.
//
// Manifest (format 1), keys sorted, no whitespace:
//   {"files":[{"bytes":N,"path":"P","sha256":"HEX"},...],"format":1,
//    "lighting":{} | {"environment":{"file":"P","intensity":K,"rotation_deg":R}} | {"sky":[R,G,B]},
//    "scene":{"builtin":"NAME"} | {"gltf":"P"}}
// Paths are relative, '/'-separated, without empty, '.' or '..' parts: a package never names a
// file outside its own folder. The glTF's files keep their places relative to it; an environment
// map goes under environment/.
//
// Packages are cached on disk under their hash (defaultSceneCache()), written to a temporary
// folder, checked and renamed into place, so a cached package is always whole.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace probecast::service {

// Trailing metadata of an UNAVAILABLE GetScene: the server names the scene in its stream but is
// still getting its files (an edge just started); ask again after this many milliseconds.
inline constexpr const char* kSceneRetryMetadata = "probecast-scene-retry-ms";

using SceneHash = std::array<uint8_t, 32>;

constexpr uint32_t kSceneManifestFormat = 1;
constexpr size_t kMaxManifestBytes = 256 * 1024;
constexpr size_t kMaxPackageFiles = 4096;
// The most bytes a package's files may add up to (1 TiB): sizes are checked against it one by one,
// so no sum of a manifest's sizes can wrap around.
constexpr uint64_t kMaxPackageBytes = uint64_t{1} << 40;

std::string hexOf(const SceneHash& hash);
// The first 12 hex digits, for messages.
std::string shortHex(const SceneHash& hash);
bool parseHex(std::string_view text, SceneHash& out);
SceneHash sha256(std::string_view bytes);
// SHA-256 of a file's bytes; false with `error` when it cannot be read.
bool sha256File(const std::filesystem::path& path, SceneHash& out, uint64_t& bytes, std::string& error);

struct PackageFile {
  std::string path;              // inside the package
  uint64_t bytes = 0;
  SceneHash sha256{};
  std::filesystem::path source;  // where it is on this machine (empty until known)
};

// What lights the scene besides its own emitters and lights.
struct SceneLighting {
  enum class Kind { None, Environment, Sky };
  Kind kind = Kind::None;
  std::string file;  // Environment: the map's path inside the package
  float intensity = 1.0f, rotationDeg = 0.0f;  // Environment
  std::array<float, 3> sky{0.0f, 0.0f, 0.0f};  // Sky: uniform radiance
  bool operator==(const SceneLighting&) const = default;
};

// How a command was asked to light the scene: an environment map on this machine, or a sky.
struct LightingRequest {
  std::filesystem::path environmentFile;
  float intensity = 1.0f, rotationDeg = 0.0f;
  std::vector<float> sky;  // empty or 3 values
};

struct ScenePackage {
  std::string scene;      // "builtin:NAME", or the glTF file's path inside the package
  SceneLighting lighting;
  std::vector<PackageFile> files;  // the glTF and what it uses, then the environment map
  std::string manifest;   // canonical JSON of the above
  SceneHash hash{};       // SHA-256 of the manifest

  bool builtin() const { return scene.rfind("builtin:", 0) == 0; }
  uint64_t totalBytes() const;
  // The hash of the scene alone, its lighting left out (what a viewer with a copy of the scene
  // compares when the lighting comes from the stream).
  SceneHash sceneHash() const;
  // A spec for loadScene on this machine: "builtin:NAME", or the glTF's source path (files known).
  std::string localSceneSpec() const;
  // The environment map's source path on this machine (empty without one or before it is known).
  std::filesystem::path localEnvironmentFile() const;
  // "builtin:cornell" or "Sponza.gltf (73 files, 61.2 MB)", then the lighting and the short hash.
  std::string describe() const;
};

// The package of `spec` (builtin:NAME, or a .gltf/.glb file: the files it names are found by
// reading its JSON, data: URIs stay inside it) lit as asked. False with `error` naming the file and
// the problem (missing, unreadable, a URI outside the glTF's folder, a malformed glTF).
bool makeScenePackage(const std::string& spec, const LightingRequest& lighting, ScenePackage& out, std::string& error);
// Checks a manifest as received (size, canonical JSON, format, every field, path and size, the
// sizes' sum at most kMaxPackageBytes) and fills `out` from it (sources empty, hash computed).
bool parseManifest(std::string_view text, ScenePackage& out, std::string& error);
// Whether `path` may name a file inside a package (see the header comment).
bool isSafePackagePath(std::string_view path);

// Text from the wire (a server's message, a name in a manifest) as it may be printed on a terminal:
// control characters (C0, DEL and C1, so no escape sequence) and bytes that are not UTF-8 become
// \xNN; anything beyond `limit` bytes is cut and marked.
std::string printableText(std::string_view text, size_t limit = 512);

// $PROBECAST_SCENE_CACHE, else $XDG_CACHE_HOME/probecast/scenes, else $HOME/.cache/probecast/scenes.
std::filesystem::path defaultSceneCache();
// The package of `hash` held whole in `cache` (its manifest and every file of its size, each a
// regular file reached without a symbolic link), sources set; false when it is not there.
bool findCachedPackage(const std::filesystem::path& cache, const SceneHash& hash, ScenePackage& out);

// Writes a package into a cache as its bytes arrive: files in any order, each in pieces in order.
// finish() checks every file's size and SHA-256 and moves the package into place; a writer
// destroyed unfinished removes what it wrote.
class PackageWriter {
 public:
  // `package` from parseManifest.
  PackageWriter(std::filesystem::path cache, ScenePackage package);
  ~PackageWriter();
  PackageWriter(const PackageWriter&) = delete;
  PackageWriter& operator=(const PackageWriter&) = delete;
  bool begin(std::string& error);
  // The next piece of `path` at `offset` (which must follow the previous piece of that file).
  bool write(std::string_view path, uint64_t offset, std::string_view data, std::string& error);
  // On success `out` is the package with its sources in the cache.
  bool finish(ScenePackage& out, std::string& error);

 private:
  std::filesystem::path cache_, staging_;
  ScenePackage package_;
  std::vector<uint64_t> written_;
  bool finished_ = false;
};

}  // namespace probecast::service
