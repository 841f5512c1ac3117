// Subcommands of the probecast binary: each registers its options and its action.
#pragma once

#include <CLI/CLI.hpp>

namespace probecast::app {

void addBenchCommands(CLI::App& app, int& exitCode);
void addDemoCommand(CLI::App& app, int& exitCode);
void addBakeCommand(CLI::App& app, int& exitCode);
void addReferenceCommand(CLI::App& app, int& exitCode);
void addServeCommands(CLI::App& app, int& exitCode);
void addCompareCommand(CLI::App& app, int& exitCode);
void addViewCommand(CLI::App& app, int& exitCode);

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
