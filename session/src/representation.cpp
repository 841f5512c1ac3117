#include "probecast/session/representation.h"

#include <stdexcept>

namespace probecast::session {

std::string checkRepresentation(const std::string& name, bool allowFloat) {
  if (parseRepresentation(name) || (allowFloat && name == "float")) return "";
  return "unknown representation '" + name + "' (" + (allowFloat ? "float, " : "") + "l1, zh3h, zh3, l2, fp16)";
}

Representation parseRepresentationOrThrow(const std::string& name) {
  const auto r = parseRepresentation(name);
  if (!r) throw std::runtime_error(checkRepresentation(name));
  return *r;
}

}  // namespace probecast::session
