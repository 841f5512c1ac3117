// Subcommands of the probecast binary: each registers its options and its action.
#pragma once

#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

namespace probecast::app {

void addBenchCommands(CLI::App& app);
void addDemoCommand(CLI::App& app);
void addBakeCommand(CLI::App& app);
void addReferenceCommand(CLI::App& app);
void addServeCommand(CLI::App& app);
void addSubscribeCommand(CLI::App& app);
void addEdgeCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addViewCommand(CLI::App& app);

// The one error channel of the commands: an exception, which main prints and exits 1 with.
// For the calls that report failure through an error string.
inline void orThrow(bool ok, const std::string& error) {
  if (!ok) throw std::runtime_error(error);
}

// The contents of a text file; throws std::runtime_error with the path when it cannot be read.
std::string readTextFile(const std::string& path);
// Writes text to a file, creating parent folders; throws std::runtime_error with the path on failure.
void writeTextFile(const std::string& path, const std::string& text);
// Prints a benchmark's table, writes its JSON and (when a path is given) its SVG chart.
void writeBenchOutputs(const std::string& table, const std::string& json, const std::string& jsonPath,
                       const std::string& svg, const std::string& chartPath);
// The command line as typed, for provenance in outputs.
const std::string& commandLine();
void setCommandLine(int argc, char** argv);

}  // namespace probecast::app
