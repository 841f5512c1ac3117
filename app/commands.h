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

// Writes text to a file, creating parent folders; throws std::runtime_error with the path on failure.
void writeTextFile(const std::string& path, const std::string& text);
// The command line as typed, for provenance in outputs.
const std::string& commandLine();
void setCommandLine(int argc, char** argv);

}  // namespace probecast::app
