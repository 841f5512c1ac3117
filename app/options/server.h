// The listening side of a service: address, TLS and token, and how its banner states them.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "commands.h"
#include "options/token.h"
#include "probecast/service/server.h"

namespace probecast::app {

// The listening side of a service: --listen, TLS (--tls-cert, --tls-key) or an explicit
// --plaintext, a bearer token (--token, --token-file) or an explicit --no-auth. Shared by the
// commands that serve.
struct ServerOptions {
  std::string listen = "127.0.0.1:50051", tlsCert, tlsKey, token, tokenFile;
  bool plaintext = false, noAuth = false;
  std::string linkPacing = "on";
  void add(CLI::App* cmd) {
    cmd->add_option("--listen", listen, "address to listen on (host:port)");
    cmd->add_option("--tls-cert", tlsCert, "PEM certificate file")->check(CLI::ExistingFile);
    cmd->add_option("--tls-key", tlsKey, "PEM private key file")->check(CLI::ExistingFile);
    cmd->add_flag("--plaintext", plaintext, "serve without TLS (trusted networks only)");
    CLI::Option* t = cmd->add_option("--token", token, "bearer token every call must present");
    CLI::Option* f =
        cmd->add_option("--token-file", tokenFile, "file holding the bearer token")->check(CLI::ExistingFile);
    CLI::Option* n =
        cmd->add_flag("--no-auth", noAuth, "serve without a token: anyone who reaches the port may subscribe");
    t->excludes(f);
    n->excludes(t)->excludes(f);
    cmd->add_option("--link-pacing", linkPacing,
                    "on: keep each subscriber that acks every frame (every probecast client) within what its link "
                    "delivers, measured from its acks; off: send as fast as the transport takes frames")
        ->check(CLI::IsMember({"on", "off"}));
  }
  // The checked configuration: TLS or --plaintext, a non-empty token or --no-auth.
  service::ServerConfig config() const {
    service::ServerConfig sc;
    sc.listen = listen;
    sc.token = tokenFrom(token, tokenFile);
    sc.noAuth = noAuth;
    sc.plaintext = plaintext;
    sc.linkPacing = linkPacing == "on";
    if (!tlsCert.empty() || !tlsKey.empty()) {
      if (tlsCert.empty() || tlsKey.empty()) throw std::runtime_error("--tls-cert and --tls-key go together");
      sc.tlsCertPem = readTextFile(tlsCert);
      sc.tlsKeyPem = readTextFile(tlsKey);
    }
    if (sc.tlsCertPem.empty() && !sc.plaintext)
      throw std::runtime_error("give --tls-cert and --tls-key, or --plaintext to serve without TLS");
    if (sc.noAuth && !sc.token.empty()) throw std::runtime_error("--no-auth and a token contradict each other");
    if (!sc.noAuth && sc.token.empty())
      throw std::runtime_error(
          "give --token or --token-file, or --no-auth to let anyone who reaches the port subscribe");
    return sc;
  }
};

// How a started server is secured, for its banner: "TLS, token", "plaintext, token", or, loudly,
// that anyone may subscribe. A server without authentication also says so on stderr, once.
inline std::string describeSecurity(const service::ServerConfig& sc, const std::string& who, int port) {
  const std::string transport = sc.tlsCertPem.empty() ? "plaintext" : "TLS";
  if (!sc.noAuth) return transport + ", token";
  fmt::print(stderr,
             "{}: WARNING: no authentication (--no-auth): anyone who can reach port {} may subscribe; give --token "
             "or --token-file on any network you do not trust\n",
             who, port);
  std::fflush(stderr);
  return transport + ", NO AUTHENTICATION: anyone may subscribe";
}

}  // namespace probecast::app
