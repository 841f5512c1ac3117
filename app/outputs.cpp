// What every command shares: the command line for provenance, text files in and out, a
// benchmark's outputs.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "commands.h"

namespace probecast::app {
namespace {

std::string gCommandLine;

}  // namespace

void setCommandLine(int argc, char** argv) {
  gCommandLine = "probecast";
  for (int i = 1; i < argc; ++i) gCommandLine += std::string(" ") + argv[i];
}
const std::string& commandLine() { return gCommandLine; }

std::string readTextFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void writeTextFile(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  std::error_code ec;
  if (p.has_parent_path()) fs::create_directories(p.parent_path(), ec);
  std::ofstream out(p, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error(path + ": cannot write");
}

void writeBenchOutputs(const std::string& table, const std::string& json, const std::string& jsonPath,
                       const std::string& svg, const std::string& chartPath) {
  fmt::print("{}", table);
  writeTextFile(jsonPath, json);
  fmt::print("wrote {}\n", jsonPath);
  if (!chartPath.empty()) {
    writeTextFile(chartPath, svg);
    fmt::print("wrote {}\n", chartPath);
  }
}

}  // namespace probecast::app
