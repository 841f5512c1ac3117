// Bearer tokens given inline or in a file.
#pragma once

#include <stdexcept>
#include <string>

#include "commands.h"

namespace probecast::app {

// A bearer token given inline or in a file, surrounding whitespace dropped. A token that is empty
// after trimming is an error, never "no token": an empty file must not open a server to everyone.
inline std::string tokenFrom(const std::string& token, const std::string& file,
                             const std::string& fileOption = "--token-file") {
  const bool fromFile = !file.empty();
  const std::string raw = fromFile ? readTextFile(file) : token;
  const size_t first = raw.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) {
    if (!fromFile && token.empty()) return {};  // none given
    throw std::runtime_error(fromFile ? fileOption + " " + file + " holds no token (empty or only whitespace)"
                                      : std::string("--token is empty or only whitespace"));
  }
  const std::string t = raw.substr(first, raw.find_last_not_of(" \t\r\n") + 1 - first);
  for (char c : t)  // it travels as an HTTP/2 header value
    if (c < 0x20 || c > 0x7e)
      throw std::runtime_error(std::string(fromFile ? fileOption + " " + file : "--token") +
                               ": the token must be printable ASCII on one line");
  return t;
}

}  // namespace probecast::app
