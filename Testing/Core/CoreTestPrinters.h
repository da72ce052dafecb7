// SDFCage — Testing: readable GoogleTest output for Core types (found by argument-dependent
// lookup, so failures print "verification failed" rather than raw bytes).
#pragma once

#include "Envelope/Envelope.h"

#include <ostream>

namespace sdfcage
{

inline void PrintTo(Status status, std::ostream* os)
{
  *os << statusName(status);
}

} // namespace sdfcage
