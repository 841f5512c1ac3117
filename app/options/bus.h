// The link to the probe bus (NATS): credentials and TLS, never open by accident.
#pragma once

#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "probecast/service/bus_nats.h"
#include "options/token.h"

namespace probecast::app {

// The link to the probe bus, never open by accident: a token (--nats-token-file) or NATS
// credentials (--nats-creds), or an explicit --nats-no-auth; TLS (--nats-tls, --nats-ca) or an
// explicit --nats-plaintext. Shared by serve --publish and edge; `needs` (optional) is the option
// without which these mean nothing.
struct BusOptions {
  std::string tokenFile, credsFile, caFile;
  bool noAuth = false, tls = false, plaintext = false;
  void add(CLI::App* cmd, CLI::Option* needs = nullptr) {
    CLI::Option* options[] = {
        cmd->add_option("--nats-token-file", tokenFile, "file holding the NATS server's authorization token")
            ->check(CLI::ExistingFile),
        cmd->add_option("--nats-creds", credsFile, "NATS credentials file (user JWT and NKey seed)")
            ->check(CLI::ExistingFile),
        cmd->add_flag("--nats-no-auth", noAuth, "connect to NATS without credentials (a trusted network only)"),
        cmd->add_flag("--nats-tls", tls, "connect to NATS over TLS (the system's roots unless --nats-ca)"),
        cmd->add_option("--nats-ca", caFile, "PEM file of the roots NATS's certificate must chain to (implies --nats-tls)")
            ->check(CLI::ExistingFile),
        cmd->add_flag("--nats-plaintext", plaintext, "connect to NATS without TLS (a trusted network only)")};
    options[0]->excludes(options[1]);
    options[2]->excludes(options[0])->excludes(options[1]);
    options[5]->excludes(options[3])->excludes(options[4]);
    if (needs)
      for (CLI::Option* o : options) o->needs(needs);
  }
  // Into `bus`, then checked (service::checkBusConfig): std::runtime_error naming the options.
  void apply(service::BusConfig& bus) const {
    std::string why;
    service::BusConfig where = bus;  // the URL and stream first, whatever the credentials
    where.noAuth = where.plaintext = true;
    if (!service::checkBusConfig(where, why)) throw std::runtime_error("--nats/--publish/--stream: " + why);
    bus.token = tokenFrom("", tokenFile, "--nats-token-file");
    bus.credsFile = credsFile;
    bus.noAuth = noAuth;
    bus.tls = tls || !caFile.empty();
    bus.caFile = caFile;
    bus.plaintext = plaintext;
    if (!bus.token.empty() && bus.token.find(' ') != std::string::npos)
      throw std::runtime_error("--nats-token-file " + tokenFile + ": the token must have no spaces");
    if (bus.token.empty() && bus.credsFile.empty() && !bus.noAuth)
      throw std::runtime_error("give --nats-token-file or --nats-creds, or --nats-no-auth to use a bus anyone who "
                               "reaches it may write to");
    if (!bus.tls && !bus.plaintext)
      throw std::runtime_error("give --nats-tls (or --nats-ca), or --nats-plaintext to use the bus without TLS");
    if (!service::checkBusConfig(bus, why)) throw std::runtime_error("--nats/--publish: " + why);
  }
};

}  // namespace probecast::app
