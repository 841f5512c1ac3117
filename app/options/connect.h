// A client's connection to a server: --connect, --token, --tls-ca, --tls-name.
#pragma once

#include <algorithm>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "options/token.h"
#include "probecast/service/client.h"

namespace probecast::app {

// A client's connection to a server: --connect, --token (and --token-file), --tls-ca, --tls-name.
struct ConnectOptions {
  std::string connect, token, tokenFile, tlsCa, tlsName;
  uint64_t maxProbes = uint64_t{1} << 21;  // a 128³ volume: 226 MB as floats
  // --max-probes, for commands that hold and write what a server describes.
  void addLimits(CLI::App* cmd) {
    cmd->add_option("--max-probes", maxProbes,
                    "the largest probe volume accepted from a server (a description of more is refused before "
                    "anything is set aside for it)")
        ->check(CLI::Range(uint64_t{1}, uint64_t{kMaxProbes}))
        ->capture_default_str();
  }
  void add(CLI::App* cmd, const std::string& what, bool required, bool withTokenFile) {
    CLI::Option* c = cmd->add_option("--connect", connect, what);
    if (required) c->required();
    cmd->add_option("--token", token, "bearer token");
    if (withTokenFile) cmd->add_option("--token-file", tokenFile, "file holding the bearer token")->check(CLI::ExistingFile);
    cmd->add_option("--tls-ca", tlsCa, "PEM root certificate to trust (enables TLS)")->check(CLI::ExistingFile);
    cmd->add_option("--tls-name", tlsName, "server name to check in its certificate");
  }
  // --connect may name several servers (edges), comma-separated: the client fails over between them.
  service::ClientConfig client(const std::string& name) const {
    service::ClientConfig cc;
    size_t start = 0;
    while (start <= connect.size()) {
      const size_t end = std::min(connect.find(',', start), connect.size());
      const std::string one = connect.substr(start, end - start);
      if (one.empty()) throw std::runtime_error("--connect '" + connect + "': an empty address in the list");
      cc.addresses.push_back(one);
      start = end + 1;
    }
    cc.address = cc.addresses.front();
    cc.token = tokenFrom(token, tokenFile);
    cc.name = name;
    cc.maxProbes = maxProbes;
    if (!tlsCa.empty()) {
      cc.tls = true;
      cc.rootCertPem = readTextFile(tlsCa);
      cc.tlsServerName = tlsName;
    }
    return cc;
  }
};

}  // namespace probecast::app
