// Representation names as users type them (--repr), parsed in one place with one message.
#pragma once

#include <string>

#include "probecast/codec/record.h"

namespace probecast::session {

// "" when `name` is a representation (or "float" where allowed: probes as traced); otherwise
// the message every command gives, e.g. "unknown representation 'l3' (l1, zh3h, zh3, l2, fp16)".
std::string checkRepresentation(const std::string& name, bool allowFloat = false);
// The representation called `name`; throws std::runtime_error with checkRepresentation's message.
Representation parseRepresentationOrThrow(const std::string& name);

}  // namespace probecast::session
