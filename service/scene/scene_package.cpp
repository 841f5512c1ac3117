#include "probecast/service/scene_package.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <set>

#include <nlohmann/json.hpp>
#include <openssl/evp.h>

namespace probecast::service {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Sha256 {
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  Sha256() { EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr); }
  ~Sha256() { EVP_MD_CTX_free(ctx); }
  void add(const void* data, size_t n) { EVP_DigestUpdate(ctx, data, n); }
  SceneHash done() {
    SceneHash h{};
    unsigned int n = 0;
    EVP_DigestFinal_ex(ctx, h.data(), &n);
    return h;
  }
};

bool readFile(const fs::path& path, std::string& out, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return error = path.string() + ": cannot open", false;
  out.assign(std::istreambuf_iterator<char>(in), {});
  if (in.bad()) return error = path.string() + ": cannot read", false;
  return true;
}

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// glTF URIs are percent-encoded (RFC 3986).
bool percentDecode(std::string_view uri, std::string& out) {
  out.clear();
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] != '%') {
      out += uri[i];
      continue;
    }
    if (i + 2 >= uri.size()) return false;
    const int hi = hexDigit(uri[i + 1]), lo = hexDigit(uri[i + 2]);
    if (hi < 0 || lo < 0) return false;
    out += static_cast<char>(hi * 16 + lo);
    i += 2;
  }
  return true;
}

// The JSON of a .gltf file, or the JSON chunk of a .glb.
bool gltfJson(const fs::path& path, const std::string& bytes, json& out, std::string& error) {
  std::string_view text = bytes;
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) {
    uint32_t chunkBytes = 0, chunkType = 0;
    if (bytes.size() < 20) return error = path.string() + ": a .glb shorter than its headers", false;
    std::memcpy(&chunkBytes, bytes.data() + 12, 4);
    std::memcpy(&chunkType, bytes.data() + 16, 4);
    if (chunkType != 0x4E4F534Au || chunkBytes > bytes.size() - 20)
      return error = path.string() + ": a .glb whose first chunk is not its JSON", false;
    text = std::string_view(bytes).substr(20, chunkBytes);
  }
  out = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (out.is_discarded() || !out.is_object()) return error = path.string() + ": not glTF JSON", false;
  return true;
}

// The external files a glTF names (buffers and images, data: URIs left out), decoded, in order.
bool gltfUris(const fs::path& path, const json& gltf, std::vector<std::string>& uris, std::string& error) {
  for (const char* kind : {"buffers", "images"}) {
    const auto it = gltf.find(kind);
    if (it == gltf.end()) continue;
    if (!it->is_array()) return error = path.string() + ": '" + kind + "' is not an array", false;
    for (const json& entry : *it) {
      if (!entry.is_object() || !entry.contains("uri")) continue;
      if (!entry["uri"].is_string()) return error = path.string() + ": a " + kind + " uri is not a string", false;
      const std::string uri = entry["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) continue;
      std::string decoded;
      if (!percentDecode(uri, decoded)) return error = path.string() + ": malformed uri '" + uri + "'", false;
      if (decoded.substr(0, decoded.find('/')).find(':') != std::string::npos)
        return error = path.string() + ": uri '" + uri + "' names a URI scheme; a scene that is delivered keeps its "
                                        "files beside it", false;
      if (!isSafePackagePath(decoded))
        return error = path.string() + ": uri '" + uri + "' leaves the glTF's folder (or is absolute); a scene "
                                        "that is delivered keeps its files beside it", false;
      uris.push_back(decoded);
    }
  }
  return true;
}

bool addFile(ScenePackage& p, const std::string& inside, const fs::path& source, std::string& error) {
  for (const PackageFile& f : p.files)
    if (f.path == inside) return true;  // named twice
  PackageFile f;
  f.path = inside;
  f.source = source;
  if (!sha256File(source, f.sha256, f.bytes, error)) return false;
  p.files.push_back(std::move(f));
  return true;
}

json lightingJson(const SceneLighting& l) {
  json j = json::object();
  if (l.kind == SceneLighting::Kind::Environment)
    j["environment"] = {{"file", l.file}, {"intensity", l.intensity}, {"rotation_deg", l.rotationDeg}};
  else if (l.kind == SceneLighting::Kind::Sky)
    j["sky"] = {l.sky[0], l.sky[1], l.sky[2]};
  return j;
}

json sceneJson(const ScenePackage& p) {
  return p.builtin() ? json{{"builtin", p.scene.substr(8)}} : json{{"gltf", p.scene}};
}

json filesJson(const std::vector<PackageFile>& files) {
  json a = json::array();
  for (const PackageFile& f : files) a.push_back({{"bytes", f.bytes}, {"path", f.path}, {"sha256", hexOf(f.sha256)}});
  return a;
}

void seal(ScenePackage& p) {
  const json m = {{"files", filesJson(p.files)},
                  {"format", kSceneManifestFormat},
                  {"lighting", lightingJson(p.lighting)},
                  {"scene", sceneJson(p)}};
  p.manifest = m.dump();
  p.hash = sha256(p.manifest);
}

bool finiteFloat(const json& v, float& out) {
  if (!v.is_number()) return false;
  const double d = v.get<double>();
  if (!std::isfinite(d) || std::fabs(d) > 3.0e38) return false;
  out = static_cast<float>(d);
  return true;
}

bool parseLighting(const json& l, ScenePackage& p, std::string& error) {
  if (!l.is_object() || l.size() > 1) return error = "manifest lighting is not {} or one kind", false;
  SceneLighting& out = p.lighting;
  if (l.contains("environment")) {
    const json& e = l["environment"];
    if (!e.is_object() || e.size() != 3 || !e.contains("file") || !e["file"].is_string() ||
        !e.contains("intensity") || !finiteFloat(e["intensity"], out.intensity) || out.intensity < 0.0f ||
        !e.contains("rotation_deg") || !finiteFloat(e["rotation_deg"], out.rotationDeg))
      return error = "manifest environment needs file, intensity >= 0 and rotation_deg", false;
    out.kind = SceneLighting::Kind::Environment;
    out.file = e["file"].get<std::string>();
    bool listed = false;
    for (const PackageFile& f : p.files) listed |= f.path == out.file;
    if (!listed) return error = "manifest environment file '" + printableText(out.file) + "' is not among its files", false;
  } else if (l.contains("sky")) {
    const json& s = l["sky"];
    if (!s.is_array() || s.size() != 3) return error = "manifest sky is not 3 numbers", false;
    for (int c = 0; c < 3; ++c)
      if (!finiteFloat(s[c], out.sky[c]) || out.sky[c] < 0.0f) return error = "manifest sky is not 3 numbers >= 0", false;
    out.kind = SceneLighting::Kind::Sky;
  } else if (!l.empty()) {
    return error = "manifest lighting of an unknown kind", false;
  }
  return true;
}

bool parseFiles(const json& files, ScenePackage& p, std::string& error) {
  if (!files.is_array() || files.size() > kMaxPackageFiles)
    return error = "manifest files is not an array of at most " + std::to_string(kMaxPackageFiles), false;
  std::set<std::string> seen;
  uint64_t total = 0;  // each file at most kMaxPackageBytes, so the sum of 4096 cannot wrap
  for (const json& f : files) {
    if (!f.is_object() || f.size() != 3 || !f.contains("path") || !f["path"].is_string() || !f.contains("bytes") ||
        !f["bytes"].is_number_unsigned() || !f.contains("sha256") || !f["sha256"].is_string())
      return error = "manifest file entry without path, bytes and sha256", false;
    PackageFile pf;
    pf.path = f["path"].get<std::string>();
    pf.bytes = f["bytes"].get<uint64_t>();
    if (!isSafePackagePath(pf.path))
      return error = "manifest names an unsafe path '" + printableText(pf.path) + "'", false;
    if (pf.bytes > kMaxPackageBytes || kMaxPackageBytes - pf.bytes < total)
      return error = "manifest files add up to more than " + std::to_string(kMaxPackageBytes) + " bytes", false;
    total += pf.bytes;
    if (!seen.insert(pf.path).second) return error = "manifest names '" + printableText(pf.path) + "' twice", false;
    if (!parseHex(f["sha256"].get<std::string>(), pf.sha256)) return error = "manifest sha256 of '" + printableText(pf.path) + "' is not 64 hex digits", false;
    p.files.push_back(std::move(pf));
  }
  return true;
}

// Whether `inside` below `root` is a regular file reached without a symbolic link.
bool isPlainFileBelow(const fs::path& root, const std::string& inside) {
  std::error_code ec;
  fs::path at = root;
  for (const fs::path& part : fs::path(inside)) {
    at /= part;
    if (fs::is_symlink(fs::symlink_status(at, ec))) return false;
  }
  return fs::is_regular_file(fs::symlink_status(at, ec));
}

}  // namespace

std::string hexOf(const SceneHash& hash) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  for (uint8_t b : hash) {
    s += digits[b >> 4];
    s += digits[b & 15];
  }
  return s;
}

std::string shortHex(const SceneHash& hash) { return hexOf(hash).substr(0, 12); }

bool parseHex(std::string_view text, SceneHash& out) {
  if (text.size() != 64) return false;
  for (size_t i = 0; i < 32; ++i) {
    const int hi = hexDigit(text[2 * i]), lo = hexDigit(text[2 * i + 1]);
    if (hi < 0 || lo < 0) return false;
    out[i] = static_cast<uint8_t>(hi * 16 + lo);
  }
  return true;
}

SceneHash sha256(std::string_view bytes) {
  Sha256 h;
  h.add(bytes.data(), bytes.size());
  return h.done();
}

bool sha256File(const fs::path& path, SceneHash& out, uint64_t& bytes, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return error = path.string() + ": cannot open", false;
  Sha256 h;
  std::vector<char> buffer(1 << 20);
  bytes = 0;
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto n = static_cast<size_t>(in.gcount());
    h.add(buffer.data(), n);
    bytes += n;
  }
  if (in.bad()) return error = path.string() + ": cannot read", false;
  out = h.done();
  return true;
}

bool isSafePackagePath(std::string_view path) {
  if (path.empty() || path.size() > 1024 || path.front() == '/') return false;
  size_t start = 0;
  while (start <= path.size()) {
    const size_t end = std::min(path.find('/', start), path.size());
    const std::string_view part = path.substr(start, end - start);
    if (part.empty() || part == "." || part == "..") return false;
    for (char c : part)
      if (c == '\\' || c == '\0' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return false;
    start = end + 1;
  }
  return true;
}

namespace {

// The length of the UTF-8 sequence at `s` (1 to 4), or 0 when it is not one (overlong, surrogate,
// beyond U+10FFFF, cut short).
size_t utf8Length(std::string_view s) {
  const auto b = [&](size_t i) { return static_cast<unsigned char>(s[i]); };
  const size_t n = b(0) < 0x80 ? 1 : b(0) >= 0xC2 && b(0) <= 0xDF ? 2 : b(0) >= 0xE0 && b(0) <= 0xEF ? 3
                                 : b(0) >= 0xF0 && b(0) <= 0xF4 ? 4 : 0;
  if (n == 0 || n > s.size()) return 0;
  for (size_t i = 1; i < n; ++i)
    if ((b(i) & 0xC0) != 0x80) return 0;
  if (n == 3 && ((b(0) == 0xE0 && b(1) < 0xA0) || (b(0) == 0xED && b(1) >= 0xA0))) return 0;
  if (n == 4 && ((b(0) == 0xF0 && b(1) < 0x90) || (b(0) == 0xF4 && b(1) >= 0x90))) return 0;
  return n;
}

}  // namespace

std::string printableText(std::string_view text, size_t limit) {
  std::string out;
  size_t i = 0;
  while (i < text.size() && out.size() < limit) {
    const size_t n = utf8Length(text.substr(i));
    const auto c = static_cast<unsigned char>(text[i]);
    const bool control = n == 1 ? (c < 0x20 || c == 0x7F) : n == 2 && c == 0xC2 && static_cast<unsigned char>(text[i + 1]) < 0xA0;
    if (n == 0 || control) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
      i += 1;
      continue;
    }
    out.append(text.substr(i, n));
    i += n;
  }
  if (i < text.size()) out += "... (cut)";
  return out;
}

uint64_t ScenePackage::totalBytes() const {
  uint64_t n = 0;
  for (const PackageFile& f : files) n = f.bytes > UINT64_MAX - n ? UINT64_MAX : n + f.bytes;  // saturates
  return n;
}

SceneHash ScenePackage::sceneHash() const {
  std::vector<PackageFile> sceneFiles;
  for (const PackageFile& f : files)
    if (!(lighting.kind == SceneLighting::Kind::Environment && f.path == lighting.file)) sceneFiles.push_back(f);
  return sha256(json{{"files", filesJson(sceneFiles)}, {"scene", sceneJson(*this)}}.dump());
}

std::string ScenePackage::localSceneSpec() const {
  if (builtin()) return scene;
  for (const PackageFile& f : files)
    if (f.path == scene) return f.source.string();
  return {};
}

fs::path ScenePackage::localEnvironmentFile() const {
  if (lighting.kind != SceneLighting::Kind::Environment) return {};
  for (const PackageFile& f : files)
    if (f.path == lighting.file) return f.source;
  return {};
}

std::string ScenePackage::describe() const {
  std::string s = printableText(scene);
  if (!files.empty()) {
    char size[64];
    std::snprintf(size, sizeof size, " (%zu files, %.1f MB)", files.size(), static_cast<double>(totalBytes()) / 1e6);
    s += size;
  }
  if (lighting.kind == SceneLighting::Kind::Environment) s += ", environment " + printableText(lighting.file);
  if (lighting.kind == SceneLighting::Kind::Sky) s += ", uniform sky";
  return s + ", scene " + shortHex(hash);
}

bool makeScenePackage(const std::string& spec, const LightingRequest& lighting, ScenePackage& out, std::string& error) {
  ScenePackage p;
  if (spec.rfind("builtin:", 0) == 0) {
    p.scene = spec;
  } else {
    const fs::path path(spec);
    std::string bytes;
    json gltf;
    std::vector<std::string> uris;
    if (!readFile(path, bytes, error) || !gltfJson(path, bytes, gltf, error) || !gltfUris(path, gltf, uris, error))
      return false;
    p.scene = path.filename().string();
    if (!isSafePackagePath(p.scene)) return error = path.string() + ": not a file name a package can hold", false;
    if (!addFile(p, p.scene, path, error)) return false;
    for (const std::string& uri : uris)
      if (!addFile(p, uri, path.parent_path() / uri, error)) return false;
  }
  if (!lighting.environmentFile.empty()) {
    p.lighting.kind = SceneLighting::Kind::Environment;
    p.lighting.file = "environment/" + lighting.environmentFile.filename().string();
    p.lighting.intensity = lighting.intensity;
    p.lighting.rotationDeg = lighting.rotationDeg;
    for (const PackageFile& f : p.files)
      if (f.path == p.lighting.file)
        return error = "the scene itself has a file " + f.path + "; the environment map cannot go there", false;
    if (!addFile(p, p.lighting.file, lighting.environmentFile, error)) return false;
  } else if (lighting.sky.size() == 3) {
    p.lighting.kind = SceneLighting::Kind::Sky;
    for (int c = 0; c < 3; ++c) p.lighting.sky[c] = lighting.sky[c];
  }
  if (p.files.size() > kMaxPackageFiles)
    return error = spec + " uses " + std::to_string(p.files.size()) + " files, more than a package holds (" +
                   std::to_string(kMaxPackageFiles) + ")", false;
  seal(p);
  if (p.manifest.size() > kMaxManifestBytes) return error = spec + ": its manifest is too large to send", false;
  out = std::move(p);
  return true;
}

bool parseManifest(std::string_view text, ScenePackage& out, std::string& error) {
  if (text.size() > kMaxManifestBytes)
    return error = "scene manifest of " + std::to_string(text.size()) + " bytes (at most " +
                   std::to_string(kMaxManifestBytes) + ")", false;
  const json m = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (m.is_discarded() || !m.is_object()) return error = "scene manifest is not a JSON object (in UTF-8)", false;
  // One package, one text: a manifest is hashed as it is, so it must be the canonical one (keys
  // sorted, once each, no whitespace), or two texts would name one package under two hashes.
  if (m.dump() != text) return error = "scene manifest is not canonical JSON (keys sorted and once each, no whitespace)", false;
  if (!m.contains("format") || m["format"] != kSceneManifestFormat)
    return error = "scene manifest format is not " + std::to_string(kSceneManifestFormat), false;
  if (m.size() != 4 || !m.contains("files") || !m.contains("lighting") || !m.contains("scene"))
    return error = "scene manifest needs exactly files, format, lighting and scene", false;
  ScenePackage p;
  if (!parseFiles(m["files"], p, error)) return false;
  const json& s = m["scene"];
  if (s.is_object() && s.size() == 1 && s.contains("builtin") && s["builtin"].is_string()) {
    p.scene = "builtin:" + s["builtin"].get<std::string>();
    const std::string name = p.scene.substr(8);
    if (name.empty() || name.size() > 64 ||
        name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos)
      return error = "manifest builtin scene '" + printableText(name) + "' is not a name (a-z, 0-9, - and _)", false;
  } else if (s.is_object() && s.size() == 1 && s.contains("gltf") && s["gltf"].is_string()) {
    p.scene = s["gltf"].get<std::string>();
    bool listed = false;
    for (const PackageFile& f : p.files) listed |= f.path == p.scene;
    if (!listed) return error = "manifest scene '" + printableText(p.scene) + "' is not among its files", false;
  } else {
    return error = "manifest scene is neither {\"builtin\": NAME} nor {\"gltf\": PATH}", false;
  }
  if (!parseLighting(m["lighting"], p, error)) return false;
  p.manifest = std::string(text);
  p.hash = sha256(text);
  out = std::move(p);
  return true;
}

fs::path defaultSceneCache() {
  if (const char* c = std::getenv("PROBECAST_SCENE_CACHE"); c && *c) return c;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return fs::path(x) / "probecast" / "scenes";
  if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".cache" / "probecast" / "scenes";
  return fs::temp_directory_path() / "probecast-scenes";
}

bool findCachedPackage(const fs::path& cache, const SceneHash& hash, ScenePackage& out) {
  const fs::path dir = cache / hexOf(hash);
  std::string text, error;
  std::error_code ec;
  if (!fs::is_regular_file(dir / "manifest.json", ec) || !readFile(dir / "manifest.json", text, error)) return false;
  ScenePackage p;
  if (!parseManifest(text, p, error) || p.hash != hash) return false;
  if (fs::is_symlink(fs::symlink_status(dir, ec)) || fs::is_symlink(fs::symlink_status(dir / "files", ec))) return false;
  for (PackageFile& f : p.files) {
    f.source = dir / "files" / f.path;
    if (!isPlainFileBelow(dir / "files", f.path) || fs::file_size(f.source, ec) != f.bytes || ec) return false;
  }
  out = std::move(p);
  return true;
}

PackageWriter::PackageWriter(fs::path cache, ScenePackage package)
    : cache_(std::move(cache)), package_(std::move(package)), written_(package_.files.size(), 0) {}

PackageWriter::~PackageWriter() {
  std::error_code ec;
  if (!finished_ && !staging_.empty()) fs::remove_all(staging_, ec);
}

bool PackageWriter::begin(std::string& error) {
  std::error_code ec;
  fs::create_directories(cache_, ec);
  if (ec) return error = cache_.string() + ": cannot create the scene cache (" + ec.message() + ")", false;
  std::random_device rd;
  staging_ = cache_ / (".partial-" + shortHex(package_.hash) + "-" + std::to_string(rd()));
  fs::create_directories(staging_ / "files", ec);
  if (ec) return error = staging_.string() + ": " + ec.message(), false;
  std::ofstream(staging_ / "manifest.json", std::ios::binary) << package_.manifest;
  for (const PackageFile& f : package_.files) {
    const fs::path target = staging_ / "files" / f.path;
    fs::create_directories(target.parent_path(), ec);
    std::ofstream create(target, std::ios::binary);
    if (!create) return error = target.string() + ": cannot create", false;
  }
  return true;
}

bool PackageWriter::write(std::string_view path, uint64_t offset, std::string_view data, std::string& error) {
  for (size_t i = 0; i < package_.files.size(); ++i) {
    const PackageFile& f = package_.files[i];
    if (f.path != path) continue;
    if (offset != written_[i] || data.size() > f.bytes - written_[i])
      return error = "scene file " + printableText(f.path) + ": a piece at " + std::to_string(offset) + " of " +
                     std::to_string(data.size()) + " bytes does not follow the " + std::to_string(written_[i]) +
                     " bytes held (the file has " + std::to_string(f.bytes) + ")", false;
    std::ofstream out(staging_ / "files" / f.path, std::ios::binary | std::ios::app);
    out.write(data.data(), static_cast<std::streamsize>(data.size()));
    if (!out) return error = "scene cache: cannot write " + printableText(f.path), false;
    written_[i] += data.size();
    return true;
  }
  return error = "the server sent a file the manifest does not name: " + printableText(path), false;
}

bool PackageWriter::finish(ScenePackage& out, std::string& error) {
  for (size_t i = 0; i < package_.files.size(); ++i) {
    PackageFile& f = package_.files[i];
    f.source = staging_ / "files" / f.path;
    SceneHash h{};
    uint64_t bytes = 0;
    if (!sha256File(f.source, h, bytes, error)) return false;
    if (bytes != f.bytes || h != f.sha256)
      return error = "scene file " + printableText(f.path) + " arrived as " + std::to_string(bytes) + " bytes with another SHA-256 "
                     "than its manifest's (" + std::to_string(f.bytes) + " bytes)", false;
  }
  const fs::path dir = cache_ / hexOf(package_.hash);
  std::error_code ec;
  fs::rename(staging_, dir, ec);
  if (ec) {  // another viewer cached it first: use theirs when whole
    if (findCachedPackage(cache_, package_.hash, out)) {
      fs::remove_all(staging_, ec);
      finished_ = true;
      return true;
    }
    return error = dir.string() + ": cannot move the scene into the cache (" + ec.message() + ")", false;
  }
  finished_ = true;
  for (PackageFile& f : package_.files) f.source = dir / "files" / f.path;
  out = package_;
  return true;
}

}  // namespace probecast::service
