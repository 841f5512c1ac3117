// probecast: one binary, one subcommand per job (see README.md).
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "commands.h"

int main(int argc, char** argv) {
  probecast::app::setCommandLine(argc, argv);
  CLI::App app{"probecast: streaming light-probe codec and service for real-time global illumination"};
  app.require_subcommand(1);
  int exitCode = 0;
  probecast::app::addDemoCommand(app, exitCode);
  probecast::app::addBenchCommands(app, exitCode);
  probecast::app::addBakeCommand(app, exitCode);
  probecast::app::addReferenceCommand(app, exitCode);
  probecast::app::addServeCommands(app, exitCode);
  probecast::app::addCompareCommand(app, exitCode);
  probecast::app::addViewCommand(app, exitCode);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "probecast: error: %s\n", e.what());
    return 1;
  }
  return exitCode;
}
